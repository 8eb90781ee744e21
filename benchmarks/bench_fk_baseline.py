"""Paper 000's experiment, reproducible: our retargeting against the forward-kinematics baseline it compares
with (Boboc et al.: joint coordinates by forward kinematics, then smoothed, then the model adjusted to them),
on every real take in sample_takes/. Pure numpy (no Blender). Prints figures.

    .venv/bin/python benchmarks/bench_fk_baseline.py

The character has fixed bone lengths (the take's median lengths), so a method's joints are forward
kinematics of its bone directions. Paper 000's error (eq. 14-15) is printed in two readings:
* as printed: per frame, m_d = the largest joint error of that frame and avg_error = mean over the joints
  of error / m_d, then the mean over frames. It is a ratio of mean to maximum error: never below 1/n (5 %
  for 20 joints), and 100 % when one joint carries all the error; it says how evenly the error is spread,
  not how large it is, so the paper's 4.2 % cannot come from it;
* ours: m_d = the body's extent in that frame (the largest distance between two of the performer's
  joints), so the figure is the mean joint error as a fraction of body size.
With no filter our joints depend only on bone directions and lengths, exactly as plain FK's do, so the two
are equal on this metric; they differ where this prints the other columns: jitter (mean joint
acceleration), lag behind the raw joints (frames), and joint orientation: the roll the baseline gives the
forearms and shins (carried along by the smallest turn, as positions-only FK must) against ours (about the
elbow's or knee's hinge axis), in degrees.
"""
from __future__ import annotations

import os

import numpy as np
from _common import SAMPLE_TAKES

from kinect_retarget.core.filters import DoubleExponentialFilter, jitter, lag_frames, make_filter
from kinect_retarget.core.joint_frames import frame_from_y_hint, resolver, rotate_minimal, segment_hint
from kinect_retarget.core.skeletons import topological_order
from kinect_retarget.takes import load_take

ROLL_JOINTS = ("WristLeft", "WristRight", "AnkleLeft", "AnkleRight")  # forearms and shins (by their tail)


def fk(positions: np.ndarray, parents: np.ndarray, lengths: np.ndarray, order) -> np.ndarray:
    """Joints placed from the root along each bone's direction in `positions`, at fixed lengths."""
    out = np.empty_like(positions)
    root = order[0]
    out[:, root] = positions[:, root]
    for j in order[1:]:
        d = positions[:, j] - positions[:, parents[j]]
        out[:, j] = out[:, parents[j]] + lengths[j] * d / np.maximum(np.linalg.norm(d, axis=-1, keepdims=True),
                                                                       1e-9)
    return out


def paper_errors(truth: np.ndarray, computed: np.ndarray, root: int) -> tuple[float, float]:
    """Eq. 14-15 (%, mean over frames): (as printed: m_d = the frame's largest joint error; ours: m_d = the
    body's extent), both skeletons placed at their root."""
    t = truth - truth[:, root:root + 1]
    c = computed - computed[:, root:root + 1]
    err = np.linalg.norm(t - c, axis=-1)
    printed = np.mean(err / np.maximum(err.max(axis=1, keepdims=True), 1e-12), axis=1)
    extent = np.max(np.linalg.norm(t[:, :, None] - t[:, None], axis=-1), axis=(1, 2))
    ours = np.mean(err / extent[:, None], axis=1)
    return 100 * float(printed.mean()), 100 * float(ours.mean())


def roll_difference(positions: np.ndarray, skeleton) -> float:
    """Mean angle (deg) between our X axis of the forearms and shins (the hinge) and the one positions-only
    FK carries along by the smallest turn from the first frame (the baseline has no other source of roll)."""
    names = skeleton.joints
    get = resolver(names, positions)
    lateral, up = np.array([1.0, 0, 0]), np.array([0.0, 1, 0])
    diffs = []
    for tail in ROLL_JOINTS:
        if tail not in names:
            continue
        j = names.index(tail)
        y = positions[:, j] - positions[:, skeleton.parent_array[j]]
        y /= np.maximum(np.linalg.norm(y, axis=-1, keepdims=True), 1e-9)
        ours = frame_from_y_hint(y, np.nan_to_num(segment_hint(get, tail, y, lateral, up)))[..., 0]
        carried = np.empty_like(ours)
        carried[0] = ours[0]
        for i in range(1, len(y)):
            x = rotate_minimal(carried[i - 1], y[i - 1], y[i])
            carried[i] = x / np.linalg.norm(x)
        diffs.append(np.degrees(np.arccos(np.clip(np.sum(ours * carried, axis=-1), -1, 1))))
    return float(np.mean(diffs))


def main() -> None:
    takes = sorted(f for f in os.listdir(SAMPLE_TAKES) if f.endswith(".krtake"))
    print("paper 000 eq. 14-15 (%): 'printed' = mean/max joint error per frame as the paper prints it; "
          "'extent' = mean error / body extent (ours)\n")
    head = (f"{'take':44s} {'frames':>6s} | {'method':24s} {'printed':>7s} {'extent':>7s} "
            f"{'jitter mm/f2':>12s} {'lag f':>6s}")
    print(head)
    summary: dict[str, list] = {}
    for name in takes:
        take = load_take(SAMPLE_TAKES / name)
        sk = take.skeleton
        parents = sk.parent_array
        order = topological_order(sk)
        ok = (take.states > 0).all(axis=1)
        raw = take.positions[ok]
        if len(raw) < 10:
            continue
        lengths = np.zeros(len(sk))
        for j in order[1:]:
            lengths[j] = np.median(np.linalg.norm(raw[:, j] - raw[:, parents[j]], axis=-1))
        states = take.states[ok]
        methods = {
            "ours, filter none": fk(raw, parents, lengths, order),
            "ours, default filter": fk(make_filter("default", take.rate).run(raw, states, take.times[ok]),
                                       parents, lengths, order),
            "FK baseline (Boboc)": DoubleExponentialFilter().run(fk(raw, parents, lengths, order), states,
                                                               take.times[ok]),
        }
        for k, (label, joints) in enumerate(methods.items()):
            printed, extent = paper_errors(raw, joints, sk.root)
            row = (printed, extent, 1000 * jitter(joints), lag_frames(raw, joints))
            summary.setdefault(label, []).append((len(raw),) + row)
            print(f"{name if k == 0 else '':44s} {len(raw) if k == 0 else '':>6} | {label:24s} {row[0]:7.2f} "
                  f"{row[1]:7.2f} {row[2]:12.2f} {row[3]:6.2f}")
        print(f"{'':44s} {'':6s} | raw joints: jitter {1000 * jitter(raw):.2f} mm/frame²; forearm/shin roll, "
              f"ours vs positions-only FK: mean {roll_difference(raw, sk):.1f} deg")
    print("\nall takes (frame-weighted):")
    for label, rows in summary.items():
        r = np.array(rows)
        w = r[:, 0]
        print(f"  {label:24s} printed {np.average(r[:, 1], weights=w):6.2f} %  extent "
              f"{np.average(r[:, 2], weights=w):5.2f} %  jitter {np.average(r[:, 3], weights=w):6.2f} mm/frame²  "
              f"lag {np.average(r[:, 4], weights=w):4.2f} frames")
    print("  (paper 000 reports 4.2 % for its method and 7.4 % for the FK baseline)")


if __name__ == "__main__":
    main()
