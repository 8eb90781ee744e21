"""Bake speed on rigs whose FK controls hang from constraint-driven parents (issue 15): per-frame cost of an
end-to-end bake of 3,000 frames (retarget, probe, constrained solve, bulk keys) on the generated Kinect rig,
a bare Rigify rig (generated from Blender's human metarig) and the same Rigify rig with a 50k-vertex body
bound to it with armature deform, side by side in one run.

    .venv/bin/python benchmarks/bench_constrained_bake.py [--frames 3000] [--repeat 5]

Goals: <= 1 ms a frame on Rigify, and the body changes the time by <= 10 %. (Before issue 15 Rigify cost
20-22 ms a frame: Blender evaluated the rig, with its meshes, several times per frame.)
"""
from __future__ import annotations

import argparse
import os
import tempfile
import time

import numpy as np
from bench_speed import long_take

from kinect_retarget.core.pipeline import RetargetSettings
from kinect_retarget.takes import krtake, load_take

BODY_VERTICES = 50_000


def rigify_file(path: str, body: bool) -> None:
    import bpy  # noqa: I001 (addon_utils needs bpy first)
    import addon_utils
    bpy.ops.wm.read_factory_settings(use_empty=True)
    addon_utils.enable("rigify", default_set=True)
    bpy.ops.object.armature_human_metarig_add()
    bpy.ops.pose.rigify_generate()
    bpy.data.objects.remove(bpy.data.objects["metarig"])
    if body:
        bind_body(bpy, bpy.data.objects["rig"])
    bpy.ops.wm.save_as_mainfile(filepath=path)


def bind_body(bpy, rig) -> None:
    """A 50k-vertex closed surface wrapped around the rig, each vertex weighted to its nearest DEF bone,
    deformed by an Armature modifier (what a skinned character does)."""
    bpy.ops.mesh.primitive_uv_sphere_add(segments=250, ring_count=201)
    body = bpy.context.object
    mesh = body.data
    n = len(mesh.vertices)
    co = np.empty(n * 3, dtype=np.float32)
    mesh.vertices.foreach_get("co", co)
    co = co.reshape(n, 3)
    bones = [b for b in rig.data.bones if b.name.startswith("DEF-")]
    heads = np.array([b.head_local for b in bones])
    tails = np.array([b.tail_local for b in bones])
    lo, hi = np.minimum(heads, tails).min(0), np.maximum(heads, tails).max(0)
    co = (lo + hi) / 2 + co * (hi - lo) / 2 * 1.05   # stretch the sphere over the rig's extent
    mesh.vertices.foreach_set("co", co.ravel())
    seg = tails - heads
    t = np.clip(np.einsum("vbk,bk->vb", co[:, None] - heads, seg) / np.maximum((seg * seg).sum(1), 1e-9), 0, 1)
    nearest = np.argmin(np.linalg.norm(co[:, None] - (heads + t[..., None] * seg), axis=-1), axis=1)
    for k, b in enumerate(bones):
        idx = np.flatnonzero(nearest == k)
        if idx.size:
            body.vertex_groups.new(name=b.name).add(idx.tolist(), 1.0, "REPLACE")
    body.parent = rig
    body.modifiers.new("Armature", "ARMATURE").object = rig
    print(f"body: {n} vertices bound to {len(bones)} DEF bones")


def bake_once(path: str | None, take_path: str) -> tuple[float, float, str]:
    """Wall and CPU seconds of one bake (the file is open already; the take is read inside the timing)."""
    import bpy  # noqa: I001 (addon_utils needs bpy first)
    import addon_utils
    from kinect_retarget.blender.bake_take import bake_take, new_generated_rig
    if path is None:
        bpy.ops.wm.read_factory_settings(use_empty=True)
    else:
        addon_utils.enable("rigify", default_set=True)  # its load handlers expect its properties
        bpy.ops.wm.open_mainfile(filepath=path)
    notes = []
    t0, c0 = time.perf_counter(), time.process_time()
    take = load_take(take_path)
    if path is None:
        obj, preset = new_generated_rig(bpy.context.scene, take), "kinect"
    else:
        obj, preset = bpy.data.objects["rig"], "rigify"
    bake_take(obj, take, preset=preset, settings=RetargetSettings(filter="default"),
              report=lambda level, msg: notes.append(msg))
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    return wall, cpu, next((m for m in notes if m.startswith("Constrained")), "no constrained parents")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--frames", type=int, default=3000)
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    tmp = tempfile.mkdtemp()
    take_path = os.path.join(tmp, "long.krtake")
    krtake.write(take_path, long_take(args.frames))
    bare, bodied = os.path.join(tmp, "rigify.blend"), os.path.join(tmp, "rigify_body.blend")
    rigify_file(bare, body=False)
    rigify_file(bodied, body=True)
    rigs = (("generated Kinect rig", None), ("Rigify, bare", bare), ("Rigify + 50k-vertex body", bodied))
    runs = {label: [] for label, _ in rigs}
    for _ in range(args.repeat):  # interleaved, so a burst of load on the shared machine hits every rig
        for label, path in rigs:
            runs[label].append(bake_once(path, take_path))
    rows = {}
    for label, _ in rigs:
        wall, cpu = min(r[0] for r in runs[label]), min(r[1] for r in runs[label])
        rows[label] = (wall, cpu)
        print(f"{label:26s} {args.frames} frames: {wall:6.3f} s wall, {cpu:6.3f} s CPU -> "
              f"{wall / args.frames * 1000:.3f} ms/frame wall, {cpu / args.frames * 1000:.3f} ms/frame CPU "
              f"(best of {args.repeat}) | {runs[label][0][2]}")
    b, w = rows["Rigify, bare"], rows["Rigify + 50k-vertex body"]
    print(f"Rigify per frame: {b[1] / args.frames * 1000:.3f} ms CPU (goal <= 1 ms; before issue 15: 20-22 ms); "
          f"body changes the time by {100 * (w[1] / b[1] - 1):+.1f} % CPU, {100 * (w[0] / b[0] - 1):+.1f} % wall "
          f"(goal within 10 %)")


if __name__ == "__main__":
    main()
