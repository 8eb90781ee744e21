"""A 10-minute live run (take playback at high speed) with recording on: memory must stay flat.

    .venv/bin/python benchmarks/bench_live_soak.py [--minutes 10] [--speed 5]

`--minutes` is minutes of performance (30 fps source time); at --speed 5 it takes a fifth of that in wall
time. Prints resident memory (RSS) sampled through the run, the queue's largest size and what was recorded.
Goal (issue 3): flat memory, no queue or recording growth in memory beyond what is recorded (on disk).
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import tempfile
import time

import numpy as np

from _live_bench import live_scene, pump_like_the_timer


def rss_mb() -> float:
    with open("/proc/self/statm") as fh:
        return int(fh.read().split()[1]) * resource.getpagesize() / 2**20


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--minutes", type=float, default=10.0)
    ap.add_argument("--speed", type=float, default=5.0)
    args = ap.parse_args()
    import bpy

    import kinect_retarget
    from kinect_retarget.blender.live import live_runtime as live

    live_scene(speed=args.speed)
    c = live.start_live(bpy.context, use_timer=False)
    rec = os.path.join(tempfile.mkdtemp(prefix="kr_soak_"), "soak.krtake")
    c.start_recording(bpy.context, rec)
    samples, queue_max = [], [0]
    last = [time.perf_counter()]

    def on_tick():
        queue_max[0] = max(queue_max[0], len(c.session.queue))
        if time.perf_counter() - last[0] >= 5.0:
            last[0] = time.perf_counter()
            samples.append((round(c.session.now(), 1), round(rss_mb(), 1), c.session.stats.recorded))

    wall = args.minutes * 60 / args.speed
    pump_like_the_timer(wall, live.TIMER_INTERVAL, on_tick)
    stats = c.session.statistics()
    error = c.session.error
    live.stop_live(bake=False)  # the recording is kept on disk; baking 18k frames is another benchmark
    kinect_retarget.unregister()
    rss = np.array([s[1] for s in samples])
    warm = rss[len(rss) // 5:] if len(rss) >= 5 else rss  # after warm-up (first fifth)
    growth = float(warm[-1] - warm[0]) if warm.size else float("nan")
    size_mb = os.path.getsize(rec) / 2**20
    print(f"{args.minutes:.0f} min of 30 fps source at speed {args.speed}: {wall:.0f} s wall; received "
          f"{stats['received']}, recorded {stats['recorded']} ({size_mb:.1f} MB on disk), applied {stats['applied']},"
          f" dropped {stats['dropped']}; queue max {queue_max[0]} frames; RSS {rss.min():.1f}-{rss.max():.1f} MB, "
          f"growth after warm-up {growth:+.1f} MB; error: {error}")
    print(json.dumps({**stats, "rss_samples": samples, "rss_growth_after_warmup_mb": round(growth, 2),
                      "queue_max": queue_max[0], "recording_mb": round(size_mb, 2), "error": error}))
    os.remove(rec)


if __name__ == "__main__":
    main()
