"""Reader speed on 10,000-frame files (goal: well under 0.1 s where the format allows). Prints figures only.

    PYTHONPATH=. .venv/bin/python benchmarks/bench_readers.py

Each file is real data tiled to 10,000 frames (timestamps continued), written to a temporary folder.
"""
from __future__ import annotations

import json
import tempfile
import time
from pathlib import Path

import numpy as np

import _common  # noqa: F401 (puts the repository on sys.path)
from kinect_retarget.takes import bvh, kinect_v2_csv, kinectron_json, krtake, msrc12, ntu_skeleton, utkinect
from tests.takes import format_fixtures as fx

DATA = _common.shared_data_or_skip(__file__)
N = 10_000


def tiled_csv(out: Path) -> Path:
    lines = (DATA / "kinect_v2" / "joints.csv").read_text().splitlines()
    rows = []
    for i in range(N):
        fields = lines[i % len(lines)].split(",", 1)
        rows.append(f"{31867373716 + i * 333333},{fields[1]}")
    path = out / "tiled.csv"
    path.write_text("\r\n".join(rows) + "\r\n")
    return path


def tiled_bvh(out: Path) -> Path:
    text = (DATA / "mocap_bvh" / "01_01.bvh").read_text().splitlines()
    first = next(i for i, line in enumerate(text) if line.startswith("Frame Time")) + 1
    motion = text[first:]
    body = [motion[i % len(motion)] for i in range(N)]
    head = [("Frames: %d" % N) if line.startswith("Frames:") else line for line in text[:first]]
    path = out / "tiled.bvh"
    path.write_text("\n".join(head + body) + "\n")
    return path


def tiled_json(out: Path) -> Path:
    raw = json.loads((DATA / "kinect_v2" / "recorded_skeleton.json").read_text())
    frames = [{**raw[i % len(raw)], "record_timestamp": i * 33} for i in range(N)]
    path = out / "tiled.json"
    path.write_text(json.dumps(frames))
    return path


def tiled_take(csv: Path):
    return kinect_v2_csv.read(csv)


def timed(fn, path, repeats=5):
    """Best wall-clock and best CPU time of `repeats` reads (CPU time is steadier on a shared machine)."""
    wall = cpu = float("inf")
    for _ in range(repeats):
        t, c = time.perf_counter(), time.process_time()
        take = fn(path)
        wall, cpu = min(wall, time.perf_counter() - t), min(cpu, time.process_time() - c)
    return wall, cpu, take


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp)
        csv = tiled_csv(out)
        v2 = kinect_v2_csv.read(csv)
        v1 = fx.v1_from_v2(v2)
        krtake.write(out / "tiled.krtake", v2)
        fx.write_ntu(v2, out / "tiled.skeleton")
        fx.write_msrc12(v1, out / "tiled_msrc.csv")
        fx.write_utkinect(v1, out / "tiled_ut.txt")
        files = [("kinect_v2_csv", kinect_v2_csv.read, csv),
                 ("krtake", krtake.read, out / "tiled.krtake"),
                 ("msrc12", msrc12.read, out / "tiled_msrc.csv"),
                 ("utkinect", utkinect.read, out / "tiled_ut.txt"),
                 ("ntu_skeleton", ntu_skeleton.read, out / "tiled.skeleton"),
                 ("bvh (read_bvh_skeleton, 36 joints)", bvh.read_bvh_skeleton, tiled_bvh(out)),
                 ("bvh (read -> Kinect v1 take)", bvh.read, out / "tiled.bvh"),
                 ("kinectron_json", kinectron_json.read, tiled_json(out))]
        print(f"{'reader':38s} {'frames':>7s} {'MB':>6s} {'wall s':>8s} {'CPU s':>8s}  (best of 5)")
        for name, fn, path in files:
            wall, cpu, take = timed(fn, path)
            frames = take.frame_count if hasattr(take, "frame_count") else take.values.shape[0]
            print(f"{name:38s} {frames:7d} {path.stat().st_size / 1e6:6.1f} {wall:8.3f} {cpu:8.3f}")


if __name__ == "__main__":
    np.seterr(all="ignore")
    main()
