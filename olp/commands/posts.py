"""``olp posts``: list the post-processors (bundled, entry points)."""

from __future__ import annotations

import argparse

from olp.commands.common import EXIT_OK

NAME = "posts"
HELP = "list the available post-processors"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    del parser


def run(args: argparse.Namespace) -> int:
    from olp.posts import available_posts
    from olp.posts.manifest import load_manifest

    for name, folder in available_posts().items():
        print(f"{name:12} {load_manifest(folder).description}")
    return EXIT_OK
