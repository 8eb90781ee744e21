"""Lifting accuracy on real optical mocap (CMU BVH) seen by known cameras, and on Kinectron's 2D/3D pairs.

Run: .venv/bin/python benchmarks/bench_lift.py [--quick]
Prints, per take and viewpoint: MPJPE after Procrustes (rigid + scale), root-relative MPJPE, absolute MPJPE,
and the fraction of frames with a depth-sign flip on any limb, for our lifter and for the paper's method
alone (`LiftSettings(method="paper")`, lift/paper_lift.py: eq. 3 scale, orthographic, plain depth with
continuity signs, no smoothing); the paper's row uses none of our steps.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from _common import shared_data_or_skip  # noqa: E402

from kinect_retarget.core.skeletons import KINECT_V1, KINECT_V2, V1_FROM_V2  # noqa: E402
from kinect_retarget.core.take import Take  # noqa: E402
from kinect_retarget.lift.bones import lengths_from_take, standing_height  # noqa: E402
from kinect_retarget.lift.lifter import LiftSettings, lift  # noqa: E402
from kinect_retarget.lift.tracks2d import Tracks2D  # noqa: E402
from kinect_retarget.lift.video_camera import Camera, view_points  # noqa: E402
from kinect_retarget.sim.lift_scoring import (  # noqa: E402
    mpjpe,
    procrustes_align,
    root_relative,
    sign_flip_fraction,
    tracks_from_take,
)
from kinect_retarget.takes import bvh, kinectron_json  # noqa: E402

DATA = shared_data_or_skip(__file__)

IMAGE = (1280, 720)
FOCAL = 1000.0
VIEWS = ((0, 5), (45, 5), (90, 5), (135, 10), (180, 5), (-60, 20))  # azimuth, elevation (deg)
LIMB_BONES = np.array([KINECT_V1.index(n) for n in (
    "ElbowLeft", "WristLeft", "ElbowRight", "WristRight", "KneeLeft", "AnkleLeft", "KneeRight", "AnkleRight")])

METHODS = {
    "ours (viterbi, persp.)": dict(signs="viterbi", scale="envelope", focal=True),
    "ours, focal unknown": dict(signs="viterbi", scale="envelope", focal=False),
    "ours, causal (greedy)": dict(signs="greedy", scale="envelope", focal=True),
    "paper as published": dict(method="paper", signs="continuity", scale="paper", focal=False),
}


def mocap_take(path: Path, rate: float = 30.0, max_s: float | None = None) -> Take:
    """A CMU take resampled to video rate (every k-th frame)."""
    take = bvh.read(path)
    step = max(1, int(round(take.rate / rate)))
    frames = np.arange(0, take.frame_count, step)
    if max_s is not None:
        frames = frames[take.times[frames] <= max_s]
    return take.slice(frames)


def evaluate(truth: np.ndarray, tracks: Tracks2D, size: dict, method: dict) -> dict:
    """size: LiftSettings' dict(lengths=calibrated (J,) metres) or dict(height_m=...) (anthropometric)."""
    st = LiftSettings(**size, focal_px=FOCAL if method["focal"] else None,
                      signs=method["signs"], scale=method["scale"], method=method.get("method", "ours"))
    t0 = time.perf_counter()
    res = lift(tracks, st)
    dt = time.perf_counter() - t0
    pred = res.take.positions
    return {"pa": 1000 * mpjpe(procrustes_align(pred, truth), truth),
            "rel": 1000 * mpjpe(root_relative(pred), root_relative(truth)),
            "abs": 1000 * mpjpe(pred, truth),
            "flip": sign_flip_fraction(pred, truth, KINECT_V1.parent_array, LIMB_BONES),
            "fps": tracks.frame_count / dt}


def bench_mocap(files: list[str], noise_px: float, max_s: float | None, anthropometric: bool) -> None:
    rng = np.random.default_rng(7)
    cam = Camera.for_image(*IMAGE, FOCAL)
    rows: dict[str, list[dict]] = {m: [] for m in METHODS}
    for name in files:
        take = mocap_take(DATA / "mocap_bvh" / name, max_s=max_s)
        lengths = lengths_from_take(take)
        # anthropometric: only the performer's height is known
        size = dict(height_m=standing_height(lengths)) if anthropometric else dict(lengths=lengths)
        pivot = take.positions[:, 0].mean(axis=0)
        for az, el in VIEWS:
            truth = view_points(take.positions, az, el, 4.5, pivot)
            vt = Take(KINECT_V1, truth, take.states, take.times, take.rate)
            tracks = tracks_from_take(vt, cam, IMAGE, noise_px, rng)
            line = []
            for m, spec in METHODS.items():
                r = evaluate(truth, tracks, size, spec)
                rows[m].append(r)
                line.append(f"{r['pa']:5.0f}/{r['flip']:.2f}")
            print(f"  {name:10s} az {az:4d} el {el:2d}: " + "  ".join(line))
    print(f"  (columns: {' | '.join(METHODS)}; each 'PA-MPJPE mm / flip fraction')")
    for m, rs in rows.items():
        mean = {k: float(np.mean([r[k] for r in rs])) for k in rs[0]}
        print(f"  {m:24s} PA-MPJPE {mean['pa']:5.1f} mm | root-rel {mean['rel']:5.1f} mm | "
              f"absolute {mean['abs']:6.1f} mm | limb sign-flip frames {mean['flip']:.3f} | "
              f"{mean['fps']:.0f} frames/s")


def bench_kinectron(noise_px: float = 0.0) -> None:
    """Kinect v2's own colour-pixel 2D lifted, compared with its 3D (fitted focal ~1062 px, data/README)."""
    take, two_d = kinectron_json.read_with_2d(DATA / "kinect_v2" / "recorded_skeleton.json")
    idx = [KINECT_V2.index(V1_FROM_V2[n]) for n in KINECT_V1.joints]
    truth = take.positions[:, idx]
    uv = two_d["color_px"][:, idx].copy()
    # Kinect v2 colour frames are mirrored: a fit of u to X/Z gives u = +1059 X/Z + 995 (ours is cx - f X/Z).
    uv[..., 0] = kinectron_json.COLOR_SIZE[0] - uv[..., 0]
    principal = (kinectron_json.COLOR_SIZE[0] - 995.4, 540.8)
    ok = take.states[:, idx] > 0
    tracks = Tracks2D(uv, ok.astype(float), take.times, kinectron_json.COLOR_SIZE, source="kinectron")
    v1 = Take(KINECT_V1, truth, take.states[:, idx], take.times, take.rate)
    for label, size in (("calibrated lengths", dict(lengths=lengths_from_take(v1))),
                        ("height 1.70 m (anthropometric)", dict(height_m=1.70))):
        for focal, method in ((1062.0, "ours"), (None, "ours"), (None, "paper")):
            res = lift(tracks, LiftSettings(**size, focal_px=focal, principal_point=principal, method=method))
            pred = res.take.positions
            m = ok.all(axis=1)
            print(f"  kinectron, {method}, {label}, focal {'1062 px' if focal else 'unknown'}: PA-MPJPE "
                  f"{1000 * mpjpe(procrustes_align(pred[m], truth[m]), truth[m]):.0f} mm, root-rel "
                  f"{1000 * mpjpe(root_relative(pred[m]), root_relative(truth[m])):.0f} mm, absolute "
                  f"{1000 * mpjpe(pred[m], truth[m]):.0f} mm, limb sign-flip frames "
                  f"{sign_flip_fraction(pred[m], truth[m], KINECT_V1.parent_array, LIMB_BONES):.3f}")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="one take, first 10 s")
    ap.add_argument("--noise", type=float, default=2.0, help="2D noise, pixels (std)")
    args = ap.parse_args()
    files = ["131_02.bvh"] if args.quick else ["01_01.bvh", "131_01.bvh", "131_02.bvh", "131_03.bvh"]
    max_s = 10.0 if args.quick else None
    print(f"CMU mocap -> {IMAGE[0]}x{IMAGE[1]} camera, f {FOCAL:.0f} px, 4.5 m, noise {args.noise} px, 30 fps")
    print(" bone lengths calibrated from the take:")
    bench_mocap(files, args.noise, max_s, anthropometric=False)
    print(" bone lengths from the height only (anthropometric ratios):")
    bench_mocap(files, args.noise, max_s, anthropometric=True)
    print("Kinectron real 2D/3D pairs:")
    bench_kinectron()


if __name__ == "__main__":
    main()
