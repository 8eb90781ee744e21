"""Jitter filters on the real Kinect v2 recordings (issue 2): jitter (mean frame-to-frame joint acceleration)
relative to the raw take, and lag in frames. Goal for 'default': jitter at most half, lag at most one frame."""
from __future__ import annotations

import time

from _common import shared_data_or_skip

from kinect_retarget.core.filters import jitter, lag_frames, make_filter
from kinect_retarget.takes import load_take

SHARED_DATA = shared_data_or_skip(__file__)
TAKES = sorted((SHARED_DATA / "kinect_v2").glob("*.csv")) + [SHARED_DATA / "kinect_v2" / "recorded_skeleton.json"]


def main() -> None:
    print(f"{'take':28s} {'filter':11s} {'jitter ratio':>12s} {'lag frames':>10s} {'us/frame':>9s}")
    worst = {}
    for path in TAKES:
        take = load_take(path)
        for name in ("default", "kinect_sdk", "hold"):
            f = make_filter(name, take.rate)
            t0 = time.process_time()
            out = f.run(take.positions, take.states, take.times)
            cost = (time.process_time() - t0) / take.frame_count * 1e6
            ratio, lag = jitter(out) / jitter(take.positions), lag_frames(take.positions, out)
            w = worst.setdefault(name, [0.0, 0.0])
            w[0], w[1] = max(w[0], ratio), max(w[1], lag)
            print(f"{path.name:28s} {name:11s} {ratio:12.3f} {lag:10.2f} {cost:9.1f}")
    for name, (ratio, lag) in worst.items():
        print(f"worst over the real takes, {name}: jitter ratio {ratio:.3f}, lag {lag:.2f} frames")


if __name__ == "__main__":
    main()
