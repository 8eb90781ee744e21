"""Several performers on the command line, the same for `bake` and `live`: `--armature NAME --body N` once
per rig (paired in order), or `--body all` (bake: every body of the take); bake also takes `--rig FILE` once
per body, each performer's rig in its own file. Not a command group."""
from __future__ import annotations


def body_arg(text: str) -> int | str:
    if text == "all":
        return text
    if not text.isdigit():
        raise ValueError(f"--body takes a body number from 0 or 'all', not {text!r}")
    return int(text)


def add_performer_args(p, rig_help: str) -> None:
    p.add_argument("--rig", action="append", help=rig_help)
    p.add_argument("--armature", action="append",
                   help="armature object name in --rig (default: the only armature); repeat it with --body to "
                        "drive each performer's own rig, paired in order")
    p.add_argument("--body", action="append", type=body_arg,
                   help="which performer of a source with several (NTU, Kinectron, NI mate's numbered users; "
                        "from 0; default 0); repeat it (one per --armature) or give 'all' for every body of a take")


def performers(args, available: int | None, where: str) -> list[tuple[int, str | None]]:
    """(body, armature name or None) for each rig, from --body and --armature; `available`: how many bodies
    the source holds (None: not known before it runs, as for OSC)."""
    bodies = args.body or [0]
    names = args.armature or []
    rigs = args.rig or []
    if "all" in bodies:
        if len(bodies) > 1:
            raise ValueError("--body all takes every body: give it alone")
        if available is None:
            raise ValueError(f"{where}: --body all needs a take (how many people OSC will send is not known)")
        bodies = list(range(available))
    if len(set(bodies)) != len(bodies):
        raise ValueError(f"--body repeats a body ({', '.join(map(str, bodies))})")
    for b in bodies:
        if available is not None and b >= available:
            raise ValueError(f"{where}: no body {b} (the take holds {available}, numbered from 0)")
    if not args.rig and names:  # (one body too: the generated rig would ignore the name)
        raise ValueError("--armature names armatures in --rig; without --rig each body gets a generated rig")
    if len(rigs) > 1:  # each performer's rig in its own file, paired in order
        if len(rigs) != len(bodies):
            raise ValueError(f"{len(rigs)} --rig files need as many --body (one rig file per performer, paired in "
                             f"order; or one --rig file and an --armature per body)")
        if names and len(names) != len(rigs):
            raise ValueError("with several --rig files give an --armature for each, or none (each file's only "
                             "armature)")
        return list(zip(bodies, names or [None] * len(bodies)))
    if len(bodies) == 1:
        if len(names) > 1:
            raise ValueError("several --armature need as many --body (one rig per performer)")
        return [(bodies[0], names[0] if names else None)]
    if args.rig and len(names) != len(bodies):
        raise ValueError(f"{len(bodies)} bodies need {len(bodies)} --armature names in --rig, paired in order "
                         f"(got {len(names)})")
    return list(zip(bodies, names or [None] * len(bodies)))


def rig_files(args, count: int) -> list[str | None]:
    """The rig file of each of `count` performers: one --rig for all, one per performer, or none (None)."""
    rigs = args.rig or []
    return rigs if len(rigs) > 1 else [rigs[0] if rigs else None] * count


def single_rig(args, where: str) -> str | None:
    """The one --rig file a command that drives every performer from one file takes."""
    rigs = args.rig or []
    if len(rigs) > 1:
        raise ValueError(f"{where}: one --rig file; name each performer's armature in it with --armature")
    return rigs[0] if rigs else None
