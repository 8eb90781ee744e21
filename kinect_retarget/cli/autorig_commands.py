"""`python -m kinect_retarget autorig MESH --out OUT.blend [--take TAKE] [--render DIR]`: rig a humanoid mesh
file (OBJ, PLY, GLB) and save it as a .blend; with a take, bake it onto the new rig; with --render, write
Workbench PNG frames. Everything that can fail on bad input is checked before Blender starts."""
from __future__ import annotations

import json
import os


def add_parsers(sub) -> None:
    p = sub.add_parser("autorig", help="auto-rig a humanoid mesh (OBJ/PLY/GLB) into a .blend, optionally "
                                       "baking a take onto it and rendering frames")
    p.add_argument("mesh", help="mesh file: .obj, .ply or .glb (detected from the content)")
    p.add_argument("--out", required=True, help="output .blend")
    p.add_argument("--take", help="take to bake onto the new rig (any format the project reads)")
    p.add_argument("--render", metavar="DIR", help="write Workbench PNG frames into DIR")
    p.add_argument("--frames", type=int, default=6, help="frames to render with --render (default 6)")
    p.add_argument("--group", help="OBJ group or object to rig (e.g. 'body' for MakeHuman's base.obj)")
    p.add_argument("--weights", choices=("projection", "heat"), default="projection",
                   help="skin weights: the paper's bone projection (default) or Blender's bone heat")
    p.add_argument("--joints", choices=("fractions", "paper"), default="fractions",
                   help="joint rule: rings at fixed geodesic fractions (default, the more accurate) or the "
                        "paper's skeleton points with its shoulder/ankle adjustment (docs/autorig.md)")
    p.add_argument("--levels", type=int, default=None, choices=range(2, 8), metavar="K",
                   help="topological levels of the paper's skeleton points (2-7, default 4); they move the "
                        "joints with --joints paper and shape --paper-skeleton")
    p.add_argument("--normalize", choices=("segment", "global"), default=None,
                   help="eq. 6's normalization of the geodesic distance: per segment (default) or over all "
                        "vertices as printed; acts where --levels does")
    p.add_argument("--paper-skeleton", action="store_true",
                   help="also build the paper's skeleton points and tree as an armature beside the rig")
    p.add_argument("--keep-transform", action="store_true",
                   help="keep the file's axes and units (default: stand the mesh Z-up, facing -Y, in metres)")
    p.set_defaults(handler=run_autorig)


def run_autorig(args) -> int:
    import numpy as np

    from ..autorig import Mesh, autorig, load_mesh
    from ..autorig.orient import upright_transform

    if not args.out.lower().endswith(".blend"):
        raise ValueError(f"--out {args.out}: the output must be a .blend file")
    if args.joints == "fractions" and not args.paper_skeleton:
        unused = [o for o, v in (("--levels", args.levels), ("--normalize", args.normalize)) if v is not None]
        if unused:  # an option that changes nothing is refused rather than silently ignored
            raise ValueError(f"{' and '.join(unused)} change(s) only the paper's skeleton points: use them with "
                             f"--joints paper or --paper-skeleton")
    args.levels = 4 if args.levels is None else args.levels
    args.normalize = args.normalize or "segment"
    mesh = load_mesh(args.mesh, group=args.group)
    take = None
    if args.take:
        from ..takes import load_take
        take = load_take(args.take)
        take.metadata.setdefault("name", os.path.splitext(os.path.basename(args.take))[0])
    rig = autorig(mesh, levels=args.levels, joints=args.joints, normalization=args.normalize)  # not a human: a clear MeshError now, before Blender starts
    vertices = mesh.vertices
    if not args.keep_transform:
        m = upright_transform(mesh.vertices, np.asarray(rig.features.up), np.asarray(rig.features.front),
                              rig.height, rig.joints[0])
        vertices = mesh.vertices @ m[:3, :3].T + m[:3, 3]
    name = os.path.splitext(os.path.basename(args.mesh))[0] + (f"_{args.group}" if args.group else "")
    from ..blender.mesh_autorig import autorig_to_file

    summary = autorig_to_file(Mesh(vertices, mesh.faces, name), args.out, take=take, render_dir=args.render,
                              frames=args.frames, weights=args.weights.upper(),
                              levels=args.levels, joints=args.joints, normalization=args.normalize,
                              paper_skeleton=args.paper_skeleton)
    print(json.dumps(summary))
    return 0
