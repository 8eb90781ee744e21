"""Main-thread cost of one live frame: retarget (process_frame: filter + solve) and apply (pose channels +
depsgraph update), on the generated Kinect rig and on a Rigify rig generated from Blender's human metarig.

    .venv/bin/python benchmarks/bench_live_apply.py [--frames 300] [--no-rigify]

Goals: apply <= 2 ms per frame (issue 3), exact on Rigify (issue 15: the constrained parents' learned
relations, no Blender evaluation in apply). Figures are medians over the frames of a real sample take.
"""
from __future__ import annotations

import argparse
import json
import time

import numpy as np

from _live_bench import live_scene


def measure(obj, take, preset: str, frames: int) -> dict:
    """Through the live controller itself: retarget = the pump's batch step for one frame; apply = what the
    controller does on the main thread (constrained parents solved exactly, pose channels); depsgraph = the
    evaluation the viewport's redraw performs after a pose change."""
    import bpy

    from kinect_retarget.blender.live import live_runtime as live
    from kinect_retarget.sources.frame_source import FrameSource

    class Idle(FrameSource):
        kind = "bench"

        def _run(self):
            while self._sleep(0.05):
                pass

    s = bpy.context.scene.kinect_retarget
    s.initialised, s.armature, s.preset, s.filter = True, obj, preset, "default"
    c = live.start_live(bpy.context, source=Idle(take.skeleton, 30.0), use_timer=False)
    c.update_after_apply = False  # timed separately below
    pipeline = c.session.pipeline
    view_layer = bpy.context.view_layer
    n = min(frames, take.frame_count)
    solve, apply, update = [], [], []
    for i in range(n):
        t0 = time.perf_counter()
        pose = pipeline.process_frames(take.positions[i:i + 1], take.states[i:i + 1], take.times[i:i + 1])
        t1 = time.perf_counter()
        if pose is None:
            continue
        c.apply(pose)
        t2 = time.perf_counter()
        view_layer.update()
        t3 = time.perf_counter()
        solve.append(t1 - t0)
        apply.append(t2 - t1)
        update.append(t3 - t2)
    result = {"preset": preset, "bones_driven": len(pipeline.bone_names), "bones_in_rig": len(obj.pose.bones),
              "frames": len(solve),
              "constrained_parents": "none" if c.model is None else
              f"{len(c.model.follows)} learned relations, {len(c.model.fallback)} fallback bones "
              f"({'exact' if not c.model.fallback or c.exact else 'fallback one frame late'})"}
    live.stop_live(bake=False)
    ms = lambda a: round(float(np.median(a)) * 1000, 3)
    p99 = lambda a: round(float(np.percentile(a, 99)) * 1000, 3)
    return {**result, "retarget_ms_median": ms(solve), "apply_ms_median": ms(apply), "apply_ms_p99": p99(apply),
            "depsgraph_update_ms_median": ms(update),
            "main_thread_total_ms_median": ms(np.add(np.add(apply, update), solve))}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--frames", type=int, default=300)
    ap.add_argument("--no-rigify", action="store_true")
    args = ap.parse_args()
    import bpy

    import kinect_retarget

    take, obj = live_scene(speed=1.0)   # the sample take, a generated rig, the add-on registered
    results = {"generated_rig": measure(obj, take, "kinect", args.frames)}
    if not args.no_rigify:
        bpy.ops.wm.read_factory_settings(use_empty=True)
        import addon_utils
        addon_utils.enable("rigify", default_set=True)
        bpy.ops.object.armature_human_metarig_add()
        bpy.ops.pose.rigify_generate()
        bpy.data.objects.remove(bpy.data.objects["metarig"])  # keep only the rig a user would animate
        rig = bpy.data.objects["rig"]
        results["rigify_rig"] = measure(rig, take, "rigify", args.frames)
    kinect_retarget.unregister()
    for name, r in results.items():
        print(f"{name:14s} apply {r['apply_ms_median']:.3f} ms (p99 {r['apply_ms_p99']:.3f}; goal <= 2 ms) | "
              f"retarget {r['retarget_ms_median']:.2f} ms | depsgraph (viewport) {r['depsgraph_update_ms_median']:.2f}"
              f" ms | main thread total {r['main_thread_total_ms_median']:.2f} ms | {r['bones_driven']} of "
              f"{r['bones_in_rig']} bones driven, constrained parents: {r['constrained_parents']}")
    print(json.dumps(results))


if __name__ == "__main__":
    main()
