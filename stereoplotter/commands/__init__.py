"""Command modules of the CLI: each defines ``add_arguments(sub)`` and ``run…(args) -> int``."""
