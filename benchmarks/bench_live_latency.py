"""Arrival-to-applied latency and dropped frames with a 30 fps source, driven like the sidebar's timer.

    .venv/bin/python benchmarks/bench_live_latency.py [--seconds 60]

Goal (issue 3): p99 <= 33 ms (one Kinect frame) and 0 dropped frames over 60 s. The source is a real take
played at real time (30 fps, looping) on its own thread; the main thread pumps every 1/120 s, poses the
generated Kinect rig and updates the depsgraph, as the viewport would.
"""
from __future__ import annotations

import argparse
import json

from _live_bench import live_scene, pump_like_the_timer


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seconds", type=float, default=60.0)
    args = ap.parse_args()
    import bpy

    import kinect_retarget
    from kinect_retarget.blender.live import live_runtime as live

    live_scene(speed=1.0)
    c = live.start_live(bpy.context, use_timer=False)
    pump_like_the_timer(args.seconds, live.TIMER_INTERVAL)
    stats = c.session.statistics()
    error = c.session.error
    live.stop_live(bake=False)
    kinect_retarget.unregister()
    print(f"30 fps source for {args.seconds:.0f} s: received {stats['received']}, applied {stats['applied']}, "
          f"dropped {stats['dropped']} (superseded {stats['superseded']}, stale {stats['stale']}, "
          f"overflowed {stats['overflowed']}); latency p50 {stats['latency_p50_ms']} ms, "
          f"p99 {stats['latency_p99_ms']} ms (goal p99 <= 33 ms, 0 dropped); error: {error}")
    print(json.dumps({**stats, "seconds": args.seconds, "error": error}))


if __name__ == "__main__":
    main()
