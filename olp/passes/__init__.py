"""Compiler passes: resolve (targets to joints), check, timing. Each is a plain function."""
