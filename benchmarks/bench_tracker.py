"""The paper's 2D tracker on a coloured body rendered from real motion (CMU walk), with ground-truth 2D.

Run: .venv/bin/python benchmarks/bench_tracker.py [--frames N]
Prints mean 2D error (px) over found joints, the lost-track rate and frames per second.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from kinect_retarget.core.skeletons import KINECT_V1  # noqa: E402
from kinect_retarget.lift.video_camera import Camera, view_points  # noqa: E402
from kinect_retarget.sim.body_imagery import background, render  # noqa: E402
from kinect_retarget.lift.joint_tracker import JointTracker, TrackerSettings  # noqa: E402
from kinect_retarget.takes import bvh  # noqa: E402

from _common import shared_data_or_skip  # noqa: E402

DATA = shared_data_or_skip(__file__)

TRACKED = ("HipCenter", "ShoulderCenter", "Head", "ShoulderLeft", "ElbowLeft", "WristLeft", "ShoulderRight",
           "ElbowRight", "WristRight", "HipLeft", "KneeLeft", "AnkleLeft", "HipRight", "KneeRight", "AnkleRight")


def rendered_sequence(frames: int, azimuth: float, size=(480, 360), seed: int = 5):
    take = bvh.read(DATA / "mocap_bvh" / "131_02.bvh")
    step = int(round(take.rate / 30))
    pos = take.positions[::step][135:135 + frames]  # from 4.5 s: the walking part of "start, walk, stop"
    pos = view_points(pos, azimuth, 5.0, 4.0, pos[:, 0].mean(axis=0))
    cam = Camera.for_image(*size, 420.0)
    rng = np.random.default_rng(seed)
    bg = background(*size, rng)
    images = [render(p, cam, *size, bg, rng) for p in pos]
    return images, cam.project(pos)


def run(frames: int, azimuth: float) -> dict:
    images, uv = rendered_sequence(frames, azimuth)
    idx = [KINECT_V1.index(n) for n in TRACKED]
    init = {n: tuple(uv[0, j]) for n, j in zip(TRACKED, idx)}
    t0 = time.perf_counter()
    tr = JointTracker(images[0], init, TrackerSettings(seed=1))
    res = [tr.initial()] + [tr.step(im) for im in images[1:]]
    dt = time.perf_counter() - t0
    est = np.stack([r.uv for r in res])
    found = np.stack([r.found for r in res])
    err = np.linalg.norm(est - uv[:, idx], axis=-1)
    return {"err": float(err[found].mean()), "err_all": float(err.mean()), "lost": float(1 - found.mean()),
            "fps": len(images) / dt, "worst": TRACKED[int(np.argmax(err.mean(axis=0)))]}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--frames", type=int, default=90)
    args = ap.parse_args()
    print(f"paper-004 tracker on a rendered coloured body (CMU 131_02 walking from 4.5 s, 480x360, body about "
          f"180 px tall, {args.frames} frames)")
    for az in (0.0, 45.0, 90.0):
        r = run(args.frames, az)
        print(f"  view {az:4.0f} deg: mean 2D error {r['err']:.1f} px on found joints ({r['err_all']:.1f} px "
              f"all), lost-track rate {r['lost']:.3f}, {r['fps']:.1f} frames/s (worst joint {r['worst']})")


if __name__ == "__main__":
    main()
