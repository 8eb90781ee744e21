"""`info` and `bake`: inspect a take, bake it onto a rig and save a .blend."""
from __future__ import annotations

import argparse
import json
import os

import numpy as np

from ..core.bake_options import HAND_MODES, RANGE_UNITS, BakeOptions
from ..core.filters import FILTERS
from ..core.foot_lock import FEET_MODES
from ..core.presets import PRESET_NAMES
from ..core.retarget import ROOT_MODES
from ..takes import body_count, load_take
from .performer_args import add_performer_args, performers, rig_files


def add_parsers(sub) -> None:
    p = sub.add_parser("info", help="print format, skeleton, frames, duration, rate, tracked fraction of a take; "
                                    "with --rig, the bone mapping of a rig")
    p.add_argument("take", nargs="?")
    p.add_argument("--rig", help=".blend: print which bone drives which Kinect joint (preset, or found by structure)")
    p.add_argument("--armature", help="armature object name in --rig (default: the only armature)")
    p.add_argument("--preset", choices=PRESET_NAMES, default="auto", help="with --rig: the preset to show")
    p.add_argument("--json", action="store_true", help="one JSON object instead of text")
    p.set_defaults(handler=run_info)

    p = sub.add_parser("bake", help="bake a take onto a rig and save a .blend, or export .fbx/.glb/.bvh")
    p.add_argument("take")
    p.add_argument("--out", required=True,
                   help="output .blend, or .fbx / .glb / .gltf / .bvh exported with game-engine settings")
    add_performer_args(p, ".blend holding the target armature(s) (default: a generated Kinect rig per body); "
                          "repeat it with --body for each performer's rig in its own file")
    p.add_argument("--preset", choices=PRESET_NAMES, default="auto")
    p.add_argument("--mapping", help="JSON {bone: joint} overriding the preset per bone")
    p.add_argument("--filter", choices=FILTERS, default="default")
    p.add_argument("--root", choices=ROOT_MODES, default="xyz")
    p.add_argument("--fps", type=float, help="key rate (default: the rig file's scene rate; the take's own "
                                            "rate in the new scene made without --rig)")
    p.add_argument("--frame-start", type=int, default=1, help="scene frame of the take's (range's) start")
    p.add_argument("--mirror", action="store_true", help="swap the performer's left and right")
    p.add_argument("--root-scale", type=_root_scale, default=None, metavar="N|auto",
                   help="paper 000 eq. 13: the factor from the performer's root travel (metres) to the rig's "
                        "(rig units); 'auto' (default): the rig's leg length over the performer's (1 on a "
                        "generated rig)")
    p.add_argument("--scale", type=float, help="BVH only: metres per file unit (default: guessed from the "
                                               "figure's standing height)")
    add_bake_option_args(p)
    p.set_defaults(handler=run_bake)


def add_bake_option_args(p) -> None:
    g = p.add_argument_group("bake options (see docs/bake.md)")
    g.add_argument("--take-start", type=float, help="bake from here in the take (--range-unit; default: start)")
    g.add_argument("--take-end", type=float, help="bake up to here in the take, inclusive (default: end)")
    g.add_argument("--range-unit", choices=RANGE_UNITS, default="seconds",
                   help="unit of --take-start/--take-end: seconds from the take's start or take frames from 0")
    g.add_argument("--step", type=int, default=1, help="key every N scene frames")
    g.add_argument("--reduce", action="store_true", help="remove keys linear interpolation reproduces within "
                                                         "--tolerance-deg / --tolerance-mm")
    g.add_argument("--tolerance-deg", type=float, default=0.5, help="key reduction: rotation tolerance, degrees")
    g.add_argument("--tolerance-mm", type=float, default=1.0, help="key reduction: root tolerance, millimetres")
    g.add_argument("--into-current", action="store_true",
                   help="key into the rig's current Action (its keys in the baked range are replaced)")
    g.add_argument("--nla", action="store_true", help="push the new Action to the NLA as a strip named after the take")
    g.add_argument("--hands", choices=HAND_MODES, default="auto",
                   help="Kinect v2 hands (thumb roll, hand-tip bend, hand-state curls) on rigs with finger bones; "
                        "auto: on for v2 takes")
    g.add_argument("--feet", choices=FEET_MODES, default="lock",
                   help="lock: planted feet pinned where they land (two-bone IK) and kept above the floor; "
                        "floor: only kept above the floor; off")
    g.add_argument("--root-motion", action="store_true",
                   help="put the performer's horizontal travel on the rig's root bone, the hips relative to it "
                        "(game engines; the pose in the world is unchanged)")
    g.add_argument("--root-motion-facing", action="store_true", help="with --root-motion: the heading too")
    g.add_argument("--root-bone", help="with --root-motion: the bone to carry it (default: the top ancestor "
                                       "of the hips bone, e.g. 'root')")
    g.add_argument("--set-scene-fps", action="store_true", help="set the rig file's scene to the key rate")
    g.add_argument("--extend-range", action="store_true",
                   help="grow the rig file's scene range to hold the keys (never shortens it)")


def bake_options_from_args(args) -> BakeOptions:
    return BakeOptions(range_start=args.take_start, range_end=args.take_end, range_unit=args.range_unit,
                       step=args.step, reduce=args.reduce, tolerance_deg=args.tolerance_deg,
                       tolerance_mm=args.tolerance_mm, into_current=args.into_current, push_nla=args.nla,
                       set_scene_fps=args.set_scene_fps, extend_scene_range=args.extend_range, hands=args.hands, feet=args.feet,
                       root_motion=args.root_motion or args.root_motion_facing,
                       root_motion_facing=args.root_motion_facing, root_bone=args.root_bone)


BVH_FIELDS = {"bvh_unit": "unit", "bvh_standing_height_m": "standing_height_m", "bvh_up_axis": "up_axis",
              "bvh_up": "up", "bvh_position_channels": "position_channels", "bvh_mapping_notes": "mapping_notes",
              "bvh_mapping": "mapping"}


def take_summary(path: str) -> dict:
    take = load_take(path)
    meta = take.metadata
    bvh = {short: meta[key] for key, short in BVH_FIELDS.items() if key in meta}
    return {"file": os.path.basename(path), "format": take.source_format, "skeleton": take.skeleton.name,
            "joints": len(take.skeleton), "frames": take.frame_count, "duration_s": round(take.duration, 3),
            "rate_fps": take.rate, "time_unit": meta.get("time_unit", "s"),
            "tracked_fraction": round(take.tracked_fraction, 4),
            "frames_with_body": int(np.count_nonzero(take.any_tracked)), "bodies": body_count(take),
            **dropped_summary(meta), **bvh,
            **({"warnings": meta["warnings"]} if meta.get("warnings") else {})}


def dropped_summary(meta: dict) -> dict:
    """How many joint samples the reader dropped as unusable (NaN, inf, absurd) and where the first was."""
    if not meta.get("dropped_joint_samples"):
        return {}
    first = next((f"{k[len('first_dropped_'):]} {v}" for k, v in meta.items() if k.startswith("first_dropped_")),
                 "")
    return {"dropped_joint_samples": meta["dropped_joint_samples"], "first_dropped": first}


def run_info(args) -> int:
    if not args.take and not args.rig:
        raise ValueError("info needs a take, or --rig RIG.blend")
    if args.rig:
        from ..blender.io.rig_mapping_report import rig_mapping_summary
        info = rig_mapping_summary(args.rig, args.armature, args.preset)
    else:
        info = take_summary(args.take)
    if args.json:
        print(json.dumps(info))
    else:
        width = max(len(k) for k in info)
        for k, v in info.items():
            if isinstance(v, dict):  # the BVH mapping, joint by joint
                print(k)
                for joint, how in v.items():
                    print(f"  {joint:<{width - 2}}  {how}")
            else:
                if isinstance(v, list):  # notes joined by "; ", a vector (the BVH up) by spaces
                    v = ("; " if all(isinstance(x, str) for x in v) else " ").join(map(str, v))
                print(f"{k:<{width}}  {v}")
    return 0


def _root_scale(text: str) -> float | None:
    """'auto' -> None (the leg-length ratio), else a positive number."""
    if text.strip().lower() == "auto":
        return None
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: expected a positive number or 'auto'") from None
    if not (value > 0 and value < float("inf")):
        raise argparse.ArgumentTypeError(f"{text!r}: the root scale must be a positive number")
    return value


def run_bake(args) -> int:
    from ..core.pipeline import RetargetSettings
    from ..core.presets import load_mapping_file

    take = load_take(args.take, scale=args.scale)  # bad input fails here, before Blender starts
    pairs = performers(args, body_count(take), args.take)
    takes = [take if body == 0 else load_take(args.take, body=body) for body, _ in pairs]
    name = os.path.splitext(os.path.basename(args.take))[0]
    for (body, _), t in zip(pairs, takes):
        t.metadata.setdefault("name", name if len(pairs) == 1 else f"{name}_body{body}")
    settings = RetargetSettings(filter=args.filter, root_mode=args.root, fps=args.fps,
                                frame_start=args.frame_start, mirror=args.mirror, root_scale=args.root_scale)
    options = bake_options_from_args(args)  # bad options fail here too
    overrides = load_mapping_file(args.mapping) if args.mapping else None
    from ..blender.headless import bake_bodies_to_file, bake_to_file

    rigs = rig_files(args, len(pairs))
    if len(pairs) == 1:
        result = bake_to_file(takes[0], args.out, rig_path=rigs[0], armature=pairs[0][1], preset=args.preset,
                              overrides=overrides, settings=settings, options=options)
    else:
        result = bake_bodies_to_file(takes, args.out, rig_path=rigs[0], armatures=[a for _, a in pairs],
                                     preset=args.preset, overrides=overrides, settings=settings, options=options,
                                     rig_paths=rigs if len(set(rigs)) > 1 else None)
    print(json.dumps(result))
    return 0
