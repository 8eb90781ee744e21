"""Measure the Kinect SDK's joint conventions on its own skeletons (redistributable Kinect v2 recordings).

    .venv/bin/python tools/measure_sdk_proportions.py [FILE.csv ...]

The depth tracker's body is MakeHuman's; the Kinect SDK puts some joints elsewhere. Kinect v2 shares the
v1 limb joints (Shoulder/Elbow/Wrist/Hand, Hip/Knee/Ankle/Foot). On the LabanotationSuite recordings
(`shared/data/kinect_v2`, MIT) this prints, as fractions of standing height (the head joint to the feet's
joints is 0.937 of it on MakeHuman's body), the hand joint's distance beyond the wrist and the ankle's place
relative to the foot joint in the body's frame: the constants SDK_HAND and SDK_ANKLE_* of depth/part_fit.py.
The spine's joints differ between v1 and v2 (SpineBase is not HipCenter) and are not measured here.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
DATA = REPO.parent / "shared" / "data" / "kinect_v2"

from kinect_retarget.core.skeletons import KINECT_V2  # noqa: E402
from kinect_retarget.takes import kinect_v2_csv  # noqa: E402

N = KINECT_V2.index
HEAD_TO_FEET = 0.937   # MakeHuman: head joint 0.951 of standing height, foot joints 0.014


def measure(positions: np.ndarray) -> dict[str, float]:
    """Per-recording medians over frames and sides, fractions of standing height."""
    p = positions
    up = p[:, N("SpineShoulder")] - p[:, N("SpineBase")]
    up /= np.linalg.norm(up, axis=-1, keepdims=True)
    lat = p[:, N("ShoulderLeft")] - p[:, N("ShoulderRight")] + p[:, N("HipLeft")] - p[:, N("HipRight")]
    lat -= np.sum(lat * up, -1, keepdims=True) * up
    lat /= np.linalg.norm(lat, axis=-1, keepdims=True)
    fwd = np.cross(lat, up)
    feet = (p[:, N("FootLeft")] + p[:, N("FootRight")]) / 2
    height = float(np.median(np.sum((p[:, N("Head")] - feet) * up, -1))) / HEAD_TO_FEET
    out: dict[str, list] = {"hand": [], "ankle_above_foot": [], "ankle_behind_foot": []}
    for s in ("Left", "Right"):
        d = p[:, N(f"Ankle{s}")] - p[:, N(f"Foot{s}")]
        out["hand"].append(np.linalg.norm(p[:, N(f"Hand{s}")] - p[:, N(f"Wrist{s}")], axis=-1))
        out["ankle_above_foot"].append(np.sum(d * up, -1))
        out["ankle_behind_foot"].append(-np.sum(d * fwd, -1))
    return {k: float(np.median(np.concatenate(v))) / height for k, v in out.items()}


def main() -> None:
    files = [Path(f) for f in sys.argv[1:]] or sorted(DATA.glob("Ges*.csv"))
    if not files:
        sys.exit(f"no Kinect v2 recordings: {DATA} is absent")
    rows = []
    for f in files:
        m = measure(kinect_v2_csv.read(str(f)).positions)
        rows.append(m)
        print(f"{f.name:26s} " + ", ".join(f"{k} {v:.3f}" for k, v in m.items()))
    print("median of the recordings: " + ", ".join(f"{k} {np.median([r[k] for r in rows]):.3f}" for k in rows[0]))


if __name__ == "__main__":
    main()
