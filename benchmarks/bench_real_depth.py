"""Depth -> skeleton tracking on real Kinect v1 depth, measured against the Kinect SDK's own skeleton.

    .venv/bin/python benchmarks/bench_real_depth.py [--subjects 1,2] [--trials 1] [--actions 1,5] [--limit N]
                                                    [--save DIR] [--load DIR] [--raw-output] [--live-smoothing]

Reads ../shared/data/utd_mhad_dev/ in place (UTD-MHAD, research use only: nothing from it, or computed from
it, goes into the repository; see its README) and skips with a message when the folder is absent. Each
sequence is unmirrored, upsampled to 640x480 (each pixel doubled) and tracked with f = 571.26 px, as
`python -m kinect_retarget track ... --focal 571.26` would: the live tracker, then the recorded take's cleanup
with its future frames (take_smoothing.py); the live tracker's own output is scored too (its summary last).
The output for depth frame k is scored against the SDK skeleton of frames k-L for the lag L in 0..3 that fits
that sequence best (the depth lags the skeleton), over frames k >= 3, all 20 joints whatever their reported
state. Figures (issue 14's table):
mean joint error, hands and wrists, directions of the 8 limb segments (mean, and the worst action's mean),
joint samples reported tracked (and their error), frames with a skeleton, joints within 10 cm; per subject,
per action and for subjects 1-2 (where settings are chosen) and 3-4 (not tuned on).
"""
from __future__ import annotations

import argparse
import os
import re
import time
from pathlib import Path

import numpy as np

from _common import SHARED_DATA

from kinect_retarget.core.skeletons import KINECT_V1, NOT_TRACKED, TRACKED
from kinect_retarget.depth.depth_camera import DepthCamera
from kinect_retarget.depth.skeleton_tracker import SkeletonTracker, TrackerSettings
from kinect_retarget.depth.take_smoothing import smooth_recorded_joints

DATA = SHARED_DATA / "utd_mhad_dev"
FOCAL_640 = 571.26
MAX_LAG = 3
# the dataset's joint order -> Kinect v1 SDK order (KINECT_V1)
_ORDER = ("Head", "ShoulderCenter", "Spine", "HipCenter", "ShoulderLeft", "ElbowLeft", "WristLeft", "HandLeft",
          "ShoulderRight", "ElbowRight", "WristRight", "HandRight", "HipLeft", "KneeLeft", "AnkleLeft", "FootLeft",
          "HipRight", "KneeRight", "AnkleRight", "FootRight")
TO_SDK = np.array([_ORDER.index(n) for n in KINECT_V1.joints])
J = KINECT_V1.index
HANDS_WRISTS = [J(f"{p}{s}") for p in ("Hand", "Wrist") for s in ("Left", "Right")]
SEGMENTS = [(J(f"{a}{s}"), J(f"{b}{s}")) for s in ("Left", "Right")
            for a, b in (("Shoulder", "Elbow"), ("Elbow", "Wrist"), ("Hip", "Knee"), ("Knee", "Ankle"))]
ACTIONS = {1: "right arm swipe left", 2: "right arm swipe right", 3: "right hand wave", 4: "two hand front clap",
           5: "right arm throw", 6: "cross arms in the chest", 7: "basketball shoot", 8: "right hand draw x",
           9: "draw circle (cw)", 10: "draw circle (ccw)", 11: "draw triangle", 12: "bowling", 13: "front boxing",
           14: "baseball swing", 15: "tennis forehand", 16: "arm curl", 17: "tennis serve", 18: "two hand push",
           19: "knock on door", 20: "catch an object", 21: "pick up and throw", 22: "jogging in place",
           23: "walking in place", 24: "sit to stand", 25: "stand to sit", 26: "forward lunge", 27: "squat"}


def sequences(subjects, trials, actions):
    out = []
    for p in DATA.glob("a*_s*_t*.npz"):
        a, s, t = map(int, re.match(r"a(\d+)_s(\d+)_t(\d+)", p.stem).groups())
        if s in subjects and t in trials and a in actions:
            out.append((a, s, t, p))
    return sorted(out)


def load(path: Path):
    """(depth mm (F, 480, 640) camera view, SDK skeleton (F, 20, 3) in KINECT_V1 order)."""
    with np.load(path) as d:
        depth, skel = d["depth"], d["skeleton"]
    depth = depth[:, :, ::-1].repeat(2, axis=1).repeat(2, axis=2)   # unmirrored, 640x480
    return np.ascontiguousarray(depth), skel[:, TO_SDK].astype(np.float64)


def track(depth: np.ndarray, settings: TrackerSettings):
    tracker = SkeletonTracker(DepthCamera(f=FOCAL_640), settings=settings)
    n = len(depth)
    pos, st, lat = np.zeros((n, 20, 3)), np.zeros((n, 20), np.uint8), np.zeros(n)
    for i in range(n):
        t = time.perf_counter()
        pos[i], st[i] = tracker.update(depth[i], i / 30.0)
        lat[i] = time.perf_counter() - t
    return pos, st, lat, tracker.calibration.height


def _angle(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    c = np.sum(a * b, -1) / np.maximum(np.linalg.norm(a, axis=-1) * np.linalg.norm(b, axis=-1), 1e-9)
    return np.degrees(np.arccos(np.clip(c, -1.0, 1.0)))


def score(pos: np.ndarray, st: np.ndarray, sdk: np.ndarray) -> dict:
    """Per-sequence sums (so figures pool over joint samples) at the lag that fits best."""
    n = len(pos)
    k = np.arange(MAX_LAG, n)
    has = np.any(st[k] != NOT_TRACKED, axis=1)
    best = None
    for lag in range(MAX_LAG + 1):
        err = np.linalg.norm(pos[k] - sdk[k - lag], axis=-1)[has]
        if best is None or (err.size and err.mean() < best[1].mean()):
            best = (lag, err)
    lag, err = best
    ref, p, s = sdk[k - lag][has], pos[k][has], st[k][has]
    seg = np.stack([_angle(p[:, b] - p[:, a], ref[:, b] - ref[:, a]) for a, b in SEGMENTS], axis=1)
    tracked = s == TRACKED
    return {"frames": len(k), "with_skeleton": int(has.sum()), "lag": lag, "err_sum": float(err.sum()),
            "n": int(err.size), "hw_sum": float(err[:, HANDS_WRISTS].sum()), "hw_n": int(err[:, HANDS_WRISTS].size),
            "seg_sum": float(seg.sum()), "seg_n": int(seg.size), "tracked": int(tracked.sum()),
            "tracked_err_sum": float(err[tracked].sum()), "within10": int(np.sum(err < 0.10)),
            "per_joint_sum": err.sum(axis=0)}


def pool(rows: list[dict]) -> dict:
    tot = {key: sum(r[key] for r in rows) for key in rows[0] if key != "lag"}
    n = max(tot["n"], 1)
    return {"mean": tot["err_sum"] / n * 100, "hw": tot["hw_sum"] / max(tot["hw_n"], 1) * 100,
            "seg": tot["seg_sum"] / max(tot["seg_n"], 1), "tracked": tot["tracked"] / n * 100,
            "tracked_err": tot["tracked_err_sum"] / max(tot["tracked"], 1) * 100,
            "skeleton": tot["with_skeleton"] / max(tot["frames"], 1) * 100, "within10": tot["within10"] / n * 100,
            "per_joint": tot["per_joint_sum"] / max(n / 20, 1) * 100, "count": len(rows)}


HEADER = (f"{'':28s} {'seqs':>4s} {'mean':>6s} {'hands+wr':>8s} {'limb dir':>8s} {'worst act':>9s} "
          f"{'tracked':>7s} {'its err':>7s} {'skeleton':>8s} {'<10 cm':>6s}")


def line(label: str, rows: list[dict]) -> str:
    f = pool(rows)
    by_action = {}
    for r in rows:
        by_action.setdefault(r["action"], []).append(r)
    worst = max(pool(v)["seg"] for v in by_action.values())
    return (f"{label:28s} {f['count']:4d} {f['mean']:5.1f}cm {f['hw']:6.1f}cm {f['seg']:7.1f}d {worst:8.1f}d "
            f"{f['tracked']:6.0f}% {f['tracked_err']:5.1f}cm {f['skeleton']:7.1f}% {f['within10']:5.0f}%")


def report(rows: list[dict]) -> None:
    print("\nGoals (issue 14): mean <= 8 cm, hands+wrists <= 10 cm, limb directions <= 10 deg mean and <= 15 in "
          "every action, >= 75 % tracked (tracked ones <= 7 cm), >= 98 % frames with a skeleton")
    print(HEADER)
    for t in sorted({r["trial"] for r in rows}):
        sel = [r for r in rows if r["trial"] == t]
        print(line(f"trial {t}, all subjects", sel))
        for group, subs in (("subjects 1-2 (tuned on)", (1, 2)), ("subjects 3-4 (not tuned on)", (3, 4))):
            part = [r for r in sel if r["subject"] in subs]
            if part:
                print(line(f"  {group}", part))
    print(line("all", rows))
    print("\nper subject")
    for s in sorted({r["subject"] for r in rows}):
        print(line(f"subject {s}", [r for r in rows if r["subject"] == s]))
    print("\nper action (all subjects and trials run)")
    for a in sorted({r["action"] for r in rows}):
        print(line(f"a{a:02d} {ACTIONS[a][:23]}", [r for r in rows if r["action"] == a]))
    f = pool(rows)
    print("\nper joint (cm): " + ", ".join(f"{n} {e:.1f}" for n, e in zip(KINECT_V1.joints, f["per_joint"])))
    lags = np.bincount([r["lag"] for r in rows], minlength=MAX_LAG + 1)
    print("best lag (frames) 0/1/2/3: " + " / ".join(str(x) for x in lags) + " sequences")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ints = lambda s: {int(x) for x in s.split(",")}
    ap.add_argument("--subjects", type=ints, default={1, 2, 3, 4})
    ap.add_argument("--trials", type=ints, default={1, 2})
    ap.add_argument("--actions", type=ints, default=set(ACTIONS))
    ap.add_argument("--limit", type=int, help="track only the first N frames of each sequence")
    ap.add_argument("--save", help="directory to write each sequence's tracked positions/states (.npz)")
    ap.add_argument("--forest", help="body-part forest (.npz) to track with instead of the shipped one; 'none': "
                    "track without body parts")
    ap.add_argument("--raw-output", action="store_true", help="score the tracker's joints before its output "
                    "smoothing (TrackerSettings.steady_output = False)")
    ap.add_argument("--live-smoothing", action="store_true", help="score the live tracker's output as the take "
                    "(no cleanup with future frames, as `track --live-smoothing` writes)")
    ap.add_argument("--load", help="score positions/states saved by --save instead of tracking")
    args = ap.parse_args()
    if not DATA.is_dir():
        print(f"real-depth benchmark skipped: {DATA} is absent (UTD-MHAD development split, research use only)")
        return
    seqs = sequences(args.subjects, args.trials, args.actions)
    print(f"real-depth benchmark: {len(seqs)} UTD-MHAD sequences (640x480 upsampled, f = {FOCAL_640} px, one "
          f"thread), scored against the Kinect SDK skeleton at the best lag of 0-{MAX_LAG} frames", flush=True)
    settings = TrackerSettings()
    if args.forest:
        settings.part_forest = None if args.forest == "none" else args.forest
    settings.steady_output = not args.raw_output
    cleaned = settings.steady_output and not args.live_smoothing   # as `track` writes a recording
    rows, live_rows, lat_all, t0 = [], [], [], time.perf_counter()
    for a, s, t, path in seqs:
        depth, sdk = load(path)
        if args.limit:
            depth, sdk = depth[:args.limit], sdk[:args.limit]
        if args.load:
            with np.load(Path(args.load) / f"{path.stem}.npz") as d:
                live, st, height = d["live"] if "live" in d else d["pos"], d["st"], float(d["height"])
        else:
            live, st, lat, height = track(depth, settings)
            lat_all.append(lat)
        pos = smooth_recorded_joints(live, st, np.arange(len(live)) / 30.0) if cleaned else live
        if args.save:
            Path(args.save).mkdir(parents=True, exist_ok=True)
            np.savez(Path(args.save) / f"{path.stem}.npz", pos=pos, live=live, st=st, height=height)
        r = score(pos, st, sdk)
        r.update(action=a, subject=s, trial=t)
        rows.append(r)
        if cleaned:   # else the take is the live output, scored above
            live_rows.append(dict(score(live, st, sdk), action=a, subject=s, trial=t))
        f = pool([r])
        print(f"  {path.stem:11s} {len(depth):3d} frames, lag {r['lag']}, height {height:.2f} m: mean {f['mean']:5.1f} cm"
              f", hands+wrists {f['hw']:5.1f}, limbs {f['seg']:5.1f} deg, tracked {f['tracked']:3.0f} %, "
              f"skeleton {f['skeleton']:5.1f} %", flush=True)
    if not rows:
        print("no sequences selected")
        return
    report(rows)
    if cleaned:
        print("\nthe live tracker's own output (what the live puppet gets: no future frames)")
        print(HEADER)
        for t in sorted({r["trial"] for r in live_rows}):
            print(line(f"trial {t}, all subjects", [r for r in live_rows if r["trial"] == t]))
        print(line("all", live_rows))
    if lat_all:
        lat = np.concatenate(lat_all)
        print(f"speed while scoring: {1.0 / lat.mean():.1f} frames/s, p95 {np.percentile(lat, 95) * 1e3:.1f} ms "
              f"(load average {os.getloadavg()[0]:.1f}; {time.perf_counter() - t0:.0f} s in all)")


if __name__ == "__main__":
    main()
