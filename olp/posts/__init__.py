"""Post-processors: the sandboxed template environment and the template view."""
