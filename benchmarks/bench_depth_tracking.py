"""Depth -> skeleton tracking: accuracy on rendered real motions, speed, latency and robustness.

    .venv/bin/python benchmarks/bench_depth_tracking.py [--only walk,hop,speed,...] [--save DIR] [--forest PATH|none]
                                                        [--raw-output]

Renders CMU mocap (walks 131_02 and 131_01, hop 131_03, forward jumps 01_01) on the MakeHuman body as Kinect v1 depth
(cached in $KR_DEPTH_CACHE, default /tmp/kinect_retarget_depth_cache), tracks it, prints the figures.
The issue motions are also scored as `track` writes them from a recording (cleaned with their future frames,
take_smoothing.py). Goals (issue 5): mean error <= 8 cm, no left/right swap > 3 frames, every joint within
15 cm or flagged, >= 30 frames/s on one core at 640x480 input, latency <= 33 ms, robustness scenarios never
NaN and recover within 1 s. Also prints the fraction of joint samples flagged (inferred/untracked), and the figures of
the development half (each motion's first half; the only one looked at while tuning) and the held-out half.
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

from kinect_retarget.core.skeletons import KINECT_V1, NOT_TRACKED  # noqa: E402
from kinect_retarget.sim.depth_scoring import facing_angle, score  # noqa: E402
from kinect_retarget.sim.synthetic_depth import Scenario, render_sequence  # noqa: E402
from kinect_retarget.depth.sdk_joints import to_sdk_joints  # noqa: E402
from kinect_retarget.depth.skeleton_tracker import SkeletonTracker, TrackerSettings  # noqa: E402
from kinect_retarget.depth.take_smoothing import smooth_recorded_joints  # noqa: E402

from _common import shared_data_or_skip  # noqa: E402

DATA = shared_data_or_skip(__file__)

# name: (clip, first BVH frame at 120 fps, frames at 30 fps, scenario)
MOTIONS = {
    "walk": ("131_02", 0, 150, Scenario(seed=5)),
    "walk+turns": ("131_01", 0, 240, Scenario()),
    "hop": ("131_03", 0, 150, Scenario(seed=6)),
    "jumps": ("01_01", 0, 150, Scenario(seed=7)),
}
SCENARIOS = {
    "bystander+furniture": ("131_02", 0, 150, Scenario(second_person=(1.1, 3.4),
                                                       boxes=[((-1.5, -0.9, 2.0), (-0.9, -0.15, 2.6))], seed=3)),
    "enter+leave": ("131_02", 0, 150, Scenario(enter_exit=True, seed=4)),
    "arm occluded (turned 60 deg)": ("131_02", 0, 150, Scenario(turn_deg=60.0, seed=8)),
}
ISSUE_MOTIONS = ("walk", "hop", "jumps")   # the motions issue 5's goals name; the turns are our harder extra
FRONTAL_DEG = 45.0   # the SDK's design range: the performer faces the sensor
# Development subset: the first half of every motion's frames; tuning looks only at these figures. The second
# half is held out (tracked in the same run, since the tracker needs the history, but scored separately).
DEV_FRACTION = 0.5
SETTINGS = TrackerSettings()   # --forest replaces its body-part forest


def cached(name: str, clip: str, frames: int, scenario: Scenario | None = None, start: int = 0):
    name = "".join(ch if ch.isalnum() else "_" for ch in name)
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
    tracker = SkeletonTracker(gravity=data["gravity"], settings=SETTINGS)
    mm, times = np.asarray(data["mm"]), np.asarray(data["times"])  # an NpzFile decompresses on every access
    data = {"mm": mm, "times": times}
    n = len(mm)
    pos, st = np.zeros((n, 20, 3)), np.zeros((n, 20), np.uint8)
    lat = np.zeros(n)
    for i in range(n):
        t = time.perf_counter()
        pos[i], st[i] = tracker.update(data["mm"][i], data["times"][i])
        lat[i] = time.perf_counter() - t
    return pos, st, lat


def speed(frames: int = 90) -> None:
    """Per-frame time on the walk, each frame tracked 3 times by fresh trackers replaying the same history;
    the best of the 3 is the single-core cost with less noise from other processes on a shared machine."""
    clip, start, n, scen = MOTIONS["walk"]
    d = cached("walk", clip, n, scen, start)
    best = np.full(frames, np.inf)
    for _ in range(3):
        _, _, lat = run({k: (d[k][:frames] if k in ("mm", "times") else d[k]) for k in ("mm", "times", "gravity")})
        best = np.minimum(best, lat)
    print(f"speed, best of 3 per frame: {1.0 / best.mean():.1f} frames/s; latency p50 {np.median(best) * 1e3:.1f} ms, "
          f"p95 {np.percentile(best, 95) * 1e3:.1f} ms, max {best.max() * 1e3:.1f} ms", flush=True)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--only", help="comma-separated motion/scenario names to run")
    ap.add_argument("--save", help="directory to write each motion's tracked positions/states (.npz)")
    ap.add_argument("--raw-output", action="store_true", help="score the tracker's joints before its output "
                    "smoothing (TrackerSettings.steady_output = False)")
    ap.add_argument("--forest", help="body-part forest (.npz) to track with instead of the shipped one; 'none': "
                    "track without body parts")
    args = ap.parse_args()
    if args.forest:
        SETTINGS.part_forest = None if args.forest == "none" else args.forest
    SETTINGS.steady_output = not args.raw_output
    only = set(args.only.split(",")) if args.only else None
    print("depth tracking benchmark (640x480 input, one thread; errors in cm)")
    all_lat, errs, frontal_errs, named, as_take = [], [], [], {}, {}
    split = {"dev": [], "held-out": []}
    for name, (clip, start, frames, scen) in MOTIONS.items():
        if only and name not in only:
            continue
        d = cached(name, clip, frames, scen, start)
        pos, st, lat = run(d)
        all_lat.append(lat)
        gt, present = d["gt_joints"], d["gt_present"].astype(bool)
        if args.save:
            Path(args.save).mkdir(parents=True, exist_ok=True)
            np.savez(Path(args.save) / f"{name.replace('+', '_')}.npz", pos=pos, st=st, gt=gt, present=present)
        sc = score(pos, st, gt, present)
        if SETTINGS.steady_output:   # what `track` writes from a recording: cleaned with its future frames too
            as_take[name] = score(smooth_recorded_joints(pos, st, np.asarray(d["times"])), st, gt, present)
        dev = np.arange(len(pos)) < int(DEV_FRACTION * len(pos))
        for part, sel in (("dev", dev), ("held-out", ~dev)):
            split[part].append(score(pos, st, gt, present & sel))
        front = present & (facing_angle(gt) < FRONTAL_DEG)
        scf = score(pos, st, gt, front)
        errs.append(sc.mean_error)
        named[name] = sc
        frontal_errs.append(scf.mean_error)
        worst = np.argsort(sc.per_joint)[::-1][:3]
        print(f"{name:11s} {clip} ({len(pos)} frames, {front.mean() * 100:.0f} % frontal): mean error "
              f"{sc.mean_error * 100:5.1f} | frontal {scf.mean_error * 100:5.1f} | tracked-state joints "
              f"{sc.tracked_error * 100:5.1f} | within 15 cm or flagged {sc.within_or_flagged * 100:5.1f} % "
              f"| flagged {sc.flagged * 100:4.1f} % | swaps >3 frames {sc.swaps_over_3} (longest {sc.longest_swap}) | coverage {sc.coverage * 100:.0f} %"
              f" | NaN frames {sc.nan_frames} | worst: "
              + ", ".join(f"{KINECT_V1.joints[j]} {sc.per_joint[j] * 100:.0f}" for j in worst), flush=True)
    if errs:
        lat = np.concatenate(all_lat)
        issue = [named[n] for n in ISSUE_MOTIONS if n in named]
        if issue:
            print(f"issue 5's motions ({', '.join(n for n in ISSUE_MOTIONS if n in named)}): mean error "
                  f"{np.mean([x.mean_error for x in issue]) * 100:.1f} cm (goal <= 8; each "
                  + " / ".join(f"{x.mean_error * 100:.1f}" for x in issue) + ") | within 15 cm or flagged "
                  + " / ".join(f"{x.within_or_flagged * 100:.1f}" for x in issue) + " % (tracked yet beyond 15 cm: "
                  + " / ".join(str(x.wrong_tracked) for x in issue) + " samples) | swaps >3 frames "
                  + " / ".join(str(x.swaps_over_3) for x in issue), flush=True)
        taken = [as_take[n] for n in ISSUE_MOTIONS if n in as_take]
        if taken:
            print("  as recorded takes (`track`: cleaned with their future frames): mean error "
                  f"{np.mean([x.mean_error for x in taken]) * 100:.1f} cm (each "
                  + " / ".join(f"{x.mean_error * 100:.1f}" for x in taken) + ") | tracked yet beyond 15 cm: "
                  + " / ".join(str(x.wrong_tracked) for x in taken) + " samples | swaps >3 frames "
                  + " / ".join(str(x.swaps_over_3) for x in taken), flush=True)
        print(f"all motions (with the turns): mean error {np.mean(errs) * 100:.1f} cm, frontal frames "
              f"{np.mean(frontal_errs) * 100:.1f} cm")
        for part, scs in split.items():
            print(f"  {part:8s} (each motion's {'first' if part == 'dev' else 'second'} half): mean error "
                  f"{np.mean([x.mean_error for x in scs]) * 100:.1f} cm | within 15 cm or flagged "
                  + " / ".join(f"{x.within_or_flagged * 100:.1f}" for x in scs)
                  + " % | flagged " + " / ".join(f"{x.flagged * 100:.0f}" for x in scs)
                  + " % | swaps >3 frames " + " / ".join(str(x.swaps_over_3) for x in scs), flush=True)
        print(f"speed: {1.0 / lat.mean():.1f} frames/s (goal >= 30); latency p50 {np.median(lat) * 1e3:.1f} ms, "
              f"p95 {np.percentile(lat, 95) * 1e3:.1f} ms, max {lat.max() * 1e3:.1f} ms (goal <= 33); "
              f"machine load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores", flush=True)
    if not only or "speed" in only:
        speed()
    for name, (clip, start, frames, scen) in SCENARIOS.items():
        if only and name not in only:
            continue
        d = cached(name, clip, frames, scen, start)
        pos, st, _ = run(d)
        gt, present = d["gt_joints"], d["gt_present"].astype(bool)
        sc = score(pos, st, gt, present)
        have = np.any(st != NOT_TRACKED, axis=1)
        # recovery: after the performer (re)appears, frames until a skeleton is on them
        late, run_ = [], 0
        for p, h in zip(present, have):
            run_ = run_ + 1 if (p and not h) else 0
            late.append(run_)
        hip_err = np.linalg.norm(pos[:, 0] - to_sdk_joints(gt)[:, 0], axis=-1)   # the output's convention
        on_main = np.mean(hip_err[have & present] < 0.3) if np.any(have & present) else 0.0
        print(f"{name}: mean error {sc.mean_error * 100:.1f} | on the main person {on_main * 100:.0f} % of frames "
              f"| coverage {sc.coverage * 100:.0f} % | longest wait for a skeleton {max(late) / 30:.2f} s "
              f"| NaN frames {sc.nan_frames} | skeletons while the performer is out of view "
              f"{int(np.sum(have & ~present))} | within 15 cm or flagged {sc.within_or_flagged * 100:.0f} %", flush=True)


if __name__ == "__main__":
    main()
