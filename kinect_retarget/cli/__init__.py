"""`python -m kinect_retarget <command>`: one module per command group, each with `add_parsers(subparsers)`
setting `handler=run_<command>`. bpy is imported only inside the handlers that need Blender, so `info` and
the device commands run in plain Python."""
from __future__ import annotations

import argparse
import sys

from ..core.take import TakeError
from . import autorig_commands, device_commands, lift_commands, live_commands, take_commands, track_commands

COMMAND_GROUPS = (take_commands, device_commands, live_commands, autorig_commands, lift_commands, track_commands)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="python -m kinect_retarget",
                                     description="Kinect motion onto any humanoid rig in Blender.")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for group in COMMAND_GROUPS:
        group.add_parsers(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    from ..device.errors import BadInputFile, KinectError
    from ..sources.frame_source import SourceError

    try:
        return int(args.handler(args) or 0)
    except (TakeError, ValueError, OSError, BadInputFile) as exc:  # bad input: exit 2
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except (KinectError, SourceError) as exc:  # a device or source that failed while running: exit 1
        print(f"error: {exc}", file=sys.stderr)
        return 1
