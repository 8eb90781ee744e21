"""Learn the offset from each body part's centre (the forest's joint proposal) to its joint.

    .venv/bin/python tools/learn_joint_offsets.py [--forest PATH] [--out PATH]

Renders MakeHuman in CMU motion (sim.synthetic_depth, redistributable assets only) on stretches of the clips
that the synthetic depth benchmark does not score (its walk, hop and jumps use each clip's first 600 BVH
frames and its walk with turns all of 131_01), at several distances, sensor tilts and turns, tracks them with
the shipped tracker and collects, for every confident proposal (part_fit.USE_CONFIDENCE) within 15 cm of its
ground-truth joint, the ground truth minus the proposal in the body frame the tracker fitted (outward, up,
forward). The per-joint median, left and right pooled, is written to kinect_retarget/assets/
part_joint_offsets.npz with this recipe. Seeded, about 2 minutes on one core.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
DATA = REPO.parent / "shared" / "data"

from kinect_retarget.core.skeletons import KINECT_V1  # noqa: E402
from kinect_retarget.depth import part_fit  # noqa: E402
from kinect_retarget.depth.part_forest import MODEL_PATH  # noqa: E402
from kinect_retarget.depth.skeleton_tracker import SkeletonTracker, TrackerSettings  # noqa: E402
from kinect_retarget.sim.synthetic_depth import Scenario, render_sequence  # noqa: E402

# (clip, first BVH frame at 120 fps, frames at 30 fps, scenario): none of it scored by bench_depth_tracking
STRETCHES = (
    ("131_02", 640, 60, Scenario(distance=2.0, seed=11)),
    ("131_02", 880, 60, Scenario(distance=3.0, tilt_deg=10.0, turn_deg=25.0, seed=12)),
    ("131_03", 640, 60, Scenario(distance=2.4, turn_deg=-25.0, seed=13)),
    ("01_01", 800, 60, Scenario(distance=2.8, tilt_deg=8.0, seed=14)),
    ("01_01", 1400, 60, Scenario(distance=2.2, turn_deg=20.0, seed=15)),
    ("01_01", 2000, 60, Scenario(distance=3.2, seed=16)),
)
MAX_ERROR = 0.15    # m: a proposal farther from its joint is another part mistaken, not an offset
SKIP = 6            # frames after acquisition (the fit settles; its body frame is a first guess)


def collect(forest: str) -> tuple[np.ndarray, np.ndarray]:
    """(samples (N, 20, 3) of ground truth minus proposal in the body frame, outward-signed; valid (N, 20))."""
    rows, valid = [], []
    outward = np.stack([np.where(part_fit.OUTWARD == 0, 1.0, part_fit.OUTWARD), np.ones(20), np.ones(20)], 1)
    for clip, start, frames, scen in STRETCHES:
        t = time.perf_counter()
        seq = render_sequence(str(DATA / "mocap_bvh" / f"{clip}.bvh"), str(DATA / "meshes" / "makehuman"), scen,
                              start=start, frames=frames)
        tracker = SkeletonTracker(gravity=seq.gravity, settings=TrackerSettings(part_forest=forest))
        for i in range(len(seq.mm)):
            tracker.update(seq.mm[i], seq.times[i])
            fit, props = tracker.last_good, tracker.last_proposals
            if i < SKIP or fit is None or props is None or fit.axis is None or not seq.present[i]:
                continue
            frame = part_fit.body_frame(fit.lateral, fit.axis)
            d = (seq.joints[i] - props.positions) @ frame.T * outward
            ok = (props.confidence >= part_fit.USE_CONFIDENCE) & (np.linalg.norm(d, axis=1) < MAX_ERROR)
            rows.append(d)
            valid.append(ok)
        print(f"  {clip} from {start}: {frames} frames in {time.perf_counter() - t:.0f} s", flush=True)
    return np.array(rows), np.array(valid)


def offsets_from(samples: np.ndarray, valid: np.ndarray, min_samples: int = 30) -> tuple[np.ndarray, np.ndarray]:
    """Per-joint median offset, each side's joint pooled with its mirror (the body is symmetric); joints with
    fewer than `min_samples` confident proposals get 0. Returns (offsets (20, 3), sample counts (20,))."""
    names = KINECT_V1.joints
    off, count = np.zeros((20, 3)), np.zeros(20, np.int64)
    for j, n in enumerate(names):
        mates = [j] + ([names.index(n.replace("Left", "Right"))] if "Left" in n else
                       [names.index(n.replace("Right", "Left"))] if "Right" in n else [])
        pooled = np.concatenate([samples[valid[:, k], k] for k in mates])
        count[j] = len(pooled)
        if len(pooled) >= min_samples:
            off[j] = np.median(pooled, axis=0)
    return off, count


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--forest", default=MODEL_PATH)
    ap.add_argument("--out", default=part_fit.OFFSETS_PATH)
    args = ap.parse_args()
    if not (DATA / "mocap_bvh").is_dir():
        sys.exit(f"{DATA} is absent: the offsets are learned on renders of its CMU clips and MakeHuman mesh")
    part_fit.load_offsets.cache_clear()
    saved = part_fit.load_offsets
    part_fit.load_offsets = lambda path=None: np.zeros((20, 3))   # the tracker's own proposals, raw
    try:
        samples, valid = collect(args.forest)
    finally:
        part_fit.load_offsets = saved
    off, count = offsets_from(samples, valid)
    for n, o, c in zip(KINECT_V1.joints, off, count):
        print(f"  {n:15s} outward {o[0] * 100:5.1f} cm, up {o[1] * 100:5.1f}, forward {o[2] * 100:5.1f} ({c} samples)")
    recipe = {"stretches": [(c, s, f, vars(sc)) for c, s, f, sc in STRETCHES], "forest": Path(args.forest).name,
              "frames": int(len(samples)), "max_error_m": MAX_ERROR}
    np.savez(args.out, offsets=off.astype(np.float32), samples=count, recipe=np.array(repr(recipe)))
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
