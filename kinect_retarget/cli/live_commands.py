"""`live`: the live pump without a window. Timers do not run while a script blocks, so this loop calls the
same pump the sidebar's timer calls, then bakes the recording into OUT.blend and prints one JSON line."""
from __future__ import annotations

import contextlib
import json
import os
import sys

from ..core.kinect_rig_layout import typical_segment_lengths
from .performer_args import add_performer_args, performers, single_rig


def add_parsers(sub) -> None:
    from ..core.filters import FILTERS
    from ..core.presets import PRESET_NAMES
    from ..core.retarget import ROOT_MODES

    p = sub.add_parser("live", help="drive a rig live from a source without a window; prints JSON statistics")
    p.add_argument("--source", required=True, help="take:FILE, osc:PORT or usb")
    p.add_argument("--seconds", type=float, required=True, help="how long to run")
    add_performer_args(p, ".blend holding the target armature(s) (default: a generated Kinect rig per body)")
    p.add_argument("--preset", default="auto", choices=PRESET_NAMES, help="bone-mapping preset (default: auto)")
    p.add_argument("--mapping", help="JSON bone-mapping overrides")
    p.add_argument("--filter", default="default", choices=FILTERS, help="jitter filter (default: default)")
    p.add_argument("--root", default="xyz", choices=ROOT_MODES, help="root motion")
    p.add_argument("--mirror", action="store_true", help="swap the performer's left and right")
    p.add_argument("--speed", type=float, default=1.0, help="take playback speed (take: sources)")
    p.add_argument("--loop", action="store_true", help="loop take playback")
    p.add_argument("--host", default="127.0.0.1", help="OSC listen address (default: this computer only)")
    p.add_argument("--simulate", action="store_true",
                   help="usb: the emulated Kinect streaming rendered depth of real mocap, through the depth tracker")
    p.add_argument("--record", metavar="TAKE_OUT", help="record every received frame to this .krtake")
    p.add_argument("--out", metavar="OUT.blend", help="save the rig (with the baked recording) here")
    p.set_defaults(handler=run_live)


@contextlib.contextmanager
def stdout_to_stderr():
    """Blender prints status lines on stdout; keep stdout for the one JSON line."""
    sys.stdout.flush()
    saved = os.dup(1)
    os.dup2(2, 1)
    try:
        yield
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
        os.close(saved)


def run_live(args) -> int:
    from ..sources import SourceError, open_source
    from ..takes import body_count

    if not args.seconds > 0:
        raise ValueError("--seconds must be positive")
    try:
        source = open_source(args.source, speed=args.speed, loop=args.loop, host=args.host,
                             simulate=args.simulate)
        take = getattr(source, "take", None)
        pairs = performers(args, None if take is None else body_count(take), args.source)
        if take is not None and [b for b, _ in pairs] != [0]:  # play every body the rigs follow
            source = open_source(args.source, speed=args.speed, loop=args.loop,
                                 bodies=tuple(b for b, _ in pairs))
    except SourceError as exc:  # bad input fails before Blender starts
        raise ValueError(str(exc)) from None
    rig = single_rig(args, "live")
    overrides = None
    if args.mapping:
        from ..core.presets import load_mapping_file
        overrides = load_mapping_file(args.mapping)

    lengths = None
    if not rig:  # bone lengths of the generated rig: the take's, or typical ones for live devices
        take = getattr(source, "take", None)
        if take is not None:
            from ..core.kinect_rig_layout import median_segment_lengths
            lengths = median_segment_lengths(take)
        else:
            lengths = typical_segment_lengths(source.skeleton)
    with stdout_to_stderr():
        from ..blender.live.live_headless import run_headless
        result = run_headless(source, args.seconds, rig_path=rig, performers=pairs,
                              preset=args.preset, filter_name=args.filter, root=args.root, mirror=args.mirror,
                              overrides=overrides, record=args.record, out=args.out, rig_lengths=lengths)
        result = {"source": args.source, **result}
    print(json.dumps(result))
    if result["error"]:
        print(f"error: live stopped: {result['error']}", file=sys.stderr)
        return 1
    return 0
