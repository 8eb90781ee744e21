"""Depth -> skeleton tracking: accuracy on rendered real motions, speed, latency and robustness.

    .venv/bin/python benchmarks/bench_depth_tracking.py [--frames N] [--quick]

Renders CMU mocap (walk 131_01, hop 131_03, forward jumps 01_01) on the MakeHuman body as Kinect v1 depth
(cached in $KR_DEPTH_CACHE, default /tmp/kinect_retarget_depth_cache), tracks it, prints the figures.
Goals (issue 5): mean error <= 8 cm, no left/right swap > 3 frames, every joint within 15 cm or flagged,
>= 30 frames/s on one core at 640x480 input, latency <= 33 ms, robustness scenarios never NaN and
recover within 1 s.
"""
from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
DATA = REPO.parent / "shared" / "data"

from kinect_retarget.core.skeletons import KINECT_V1, NOT_TRACKED  # noqa: E402
from kinect_retarget.depth.evaluation import score  # noqa: E402
from kinect_retarget.depth.synthetic import Scenario, render_sequence  # noqa: E402
from kinect_retarget.depth.tracker import SkeletonTracker  # noqa: E402

MOTIONS = {"walk": ("131_01", 0), "hop": ("131_03", 0), "jumps": ("01_01", 0)}
SCENARIOS = {
    "bystander+furniture": ("131_03", Scenario(second_person=(1.1, 3.4), boxes=[((-1.5, -0.9, 2.0), (-0.9, -0.15, 2.6))], seed=3)),
    "enter+leave": ("131_01", Scenario(enter_exit=True, seed=4)),
}


def cached(name: str, clip: str, frames: int, scenario: Scenario | None = None, start: int = 0):
    cache = Path(os.environ.get("KR_DEPTH_CACHE", "/tmp/kinect_retarget_depth_cache"))
    cache.mkdir(parents=True, exist_ok=True)
    path = cache / f"{name}_{clip}_{start}_{frames}.npz"
    if not path.exists():
        t = time.perf_counter()
        seq = render_sequence(str(DATA / "mocap_bvh" / f"{clip}.bvh"), str(DATA / "meshes" / "makehuman"),
                              scenario, start=start, frames=frames)
        seq.save_npz(str(path))
        print(f"  rendered {name} ({clip}, {frames} frames) in {time.perf_counter() - t:.0f} s", flush=True)
    return np.load(path)


def run(data):
    tracker = SkeletonTracker(gravity=data["gravity"])
    n = len(data["mm"])
    pos, st = np.zeros((n, 20, 3)), np.zeros((n, 20), np.uint8)
    lat = np.zeros(n)
    for i in range(n):
        t = time.perf_counter()
        pos[i], st[i] = tracker.update(data["mm"][i], data["times"][i])
        lat[i] = time.perf_counter() - t
    return pos, st, lat


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--frames", type=int, default=240, help="frames per motion at 30 fps")
    args = ap.parse_args()
    print(f"depth tracking benchmark ({args.frames} frames per motion, 640x480 input, one thread)")
    all_lat, errs = [], []
    for name, (clip, start) in MOTIONS.items():
        d = cached(name, clip, args.frames, start=start)
        pos, st, lat = run(d)
        all_lat.append(lat)
        sc = score(pos, st, d["gt_joints"], d["gt_present"])
        errs.append(sc.mean_error)
        worst = np.argsort(sc.per_joint)[::-1][:3]
        print(f"{name:6s} {clip}: mean error {sc.mean_error * 100:5.1f} cm (tracked joints {sc.tracked_error * 100:5.1f} cm)"
              f" | within 15 cm or flagged {sc.within_or_flagged * 100:5.1f} % | swaps >3 frames {sc.swaps_over_3}"
              f" (longest {sc.longest_swap}) | coverage {sc.coverage * 100:.0f} % | NaN frames {sc.nan_frames}"
              f" | worst: " + ", ".join(f"{KINECT_V1.joints[j]} {sc.per_joint[j] * 100:.0f}" for j in worst))
    lat = np.concatenate(all_lat)
    print(f"overall mean error {np.mean(errs) * 100:.1f} cm (goal <= 8)")
    print(f"speed: {1.0 / lat.mean():.1f} frames/s (goal >= 30); latency p50 {np.median(lat) * 1e3:.1f} ms, "
          f"p95 {np.percentile(lat, 95) * 1e3:.1f} ms, max {lat.max() * 1e3:.1f} ms (goal <= 33)")
    for name, (clip, scen) in SCENARIOS.items():
        d = cached(name.replace("+", "_"), clip, args.frames, scen)
        pos, st, _ = run(d)
        sc = score(pos, st, d["gt_joints"], d["gt_present"])
        have = np.any(st != NOT_TRACKED, axis=1)
        present = d["gt_present"].astype(bool)
        # recovery: longest run of present frames without a skeleton, after the first acquisition
        gaps, run_ = [], 0
        for p, h in zip(present, have):
            run_ = run_ + 1 if (p and not h) else 0
            gaps.append(run_)
        err_main = sc.mean_error
        print(f"{name}: mean error {err_main * 100:.1f} cm on the main person | coverage {sc.coverage * 100:.0f} %"
              f" | longest gap {max(gaps) / 30:.2f} s | NaN frames {sc.nan_frames}"
              f" | skeleton output while absent: {int(np.sum(have & ~present))} frames")


if __name__ == "__main__":
    main()
