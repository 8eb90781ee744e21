"""`python -m kinect_retarget <command>`: each command lives in its own module; bpy is imported only by the
commands that need Blender, so `info` and the device commands run in plain Python."""
from __future__ import annotations

import argparse
import sys
from importlib import import_module

from .core.take import TakeError

# modules contributing subcommands through add_parser(subparsers) / add_parsers(subparsers)
COMMAND_MODULES = ("cli_take", "cli_device", "cli_live", "cli_autorig", "cli_lift", "cli_track")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="python -m kinect_retarget",
                                     description="Kinect motion onto any humanoid rig in Blender.")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name in COMMAND_MODULES:
        try:
            mod = import_module(f".{name}", __package__)
        except ModuleNotFoundError as exc:
            if exc.name != f"{__package__}.{name}":
                raise
            continue
        for hook in ("add_parser", "add_parsers"):
            if hasattr(mod, hook):
                getattr(mod, hook)(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    from .device.errors import BadInputFile, KinectError
    from .sources.base import SourceError

    try:
        return int(args.handler(args) or 0)
    except (TakeError, ValueError, OSError, BadInputFile) as exc:  # bad input: exit 2
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except (KinectError, SourceError) as exc:  # a device or source that failed while running: exit 1
        print(f"error: {exc}", file=sys.stderr)
        return 1
