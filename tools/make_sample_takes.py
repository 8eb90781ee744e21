"""Build sample_takes/: real recordings converted to the project's .krtake format (deterministic).

    .venv/bin/python tools/make_sample_takes.py [--data DIR] [--out sample_takes]

DIR defaults to the repository's tests/data (decompressed into a temporary folder by tests/repo_data.py).

* Kinect v2 (25 joints): Microsoft LabanotationSuite gestures Ges01-06 and joints.csv, the Kinectron recording.
* Kinect v1 (20 joints): CMU optical mocap (BVH) sampled at the Kinect v1 joints, seen by a virtual sensor
  (takes/bvh.py), resampled 120 -> 30 fps by keeping every 4th frame (120 is a multiple of 30, so no
  interpolation is needed and every kept frame is a real mocap sample).

Each take's header metadata names its source, licence and required credit; sample_takes/CREDITS.md lists them.
Running it twice gives byte-identical files.
"""
from __future__ import annotations

import argparse
import shutil
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from kinect_retarget.core.take import Take  # noqa: E402
from kinect_retarget.takes import bvh, kinect_v2_csv, kinectron_json, krtake  # noqa: E402
from tests.repo_data import materialize  # noqa: E402

LABAN = {"source": "microsoft/LabanotationSuite @ c135c9016783444b112083aad3dd63e851b9f8fe",
         "license": "MIT", "credit": "LabanotationSuite, Copyright (c) Microsoft Corporation"}
KINECTRON = {"source": "kinectron/kinectron @ 35f0dd9cc890c4d7c1d0566707da0fe38126f339, "
                       "examples/windows_examples/p5_examples/shared/recorded_skeleton.json",
             "license": "MIT", "credit": "Kinectron, Copyright (c) Shawn Van Every, David Gochfield, Lisa Jamhoury"}
CMU = {"license": "CMU Graphics Lab Motion Capture Database terms: free for all uses, no resale",
       "credit": "The data used in this project was obtained from mocap.cs.cmu.edu. "
                 "The database was created with funding from NSF EIA-0196217."}

# output name: (reader, path under data/, provenance)
KINECT_V2_TAKES = {
    "kinect_v2_ges01_wavehand": ("kinect_v2/Ges01_wavehand.csv", LABAN),
    "kinect_v2_ges02_balancinghands": ("kinect_v2/Ges02_balancinghands.csv", LABAN),
    "kinect_v2_ges03_drawlines": ("kinect_v2/Ges03_drawlines.csv", LABAN),
    "kinect_v2_ges04_comehere": ("kinect_v2/Ges04_comehere.csv", LABAN),
    "kinect_v2_ges05_demopoint": ("kinect_v2/Ges05_demopoint.csv", LABAN),
    "kinect_v2_ges06_chickenwing": ("kinect_v2/Ges06_chickenwing.csv", LABAN),
    "kinect_v2_upper_body_joints": ("kinect_v2/joints.csv", LABAN),
    "kinect_v2_kinectron_recorded_skeleton": ("kinect_v2/recorded_skeleton.json", KINECTRON),
}
CMU_TAKES = {  # output name: (BVH under data/, CMU trial, description, release)
    "kinect_v1_cmu_01_01_jumps": ("mocap_bvh/01_01.bvh", "subject 1 trial 1",
                                  "playground: forward jumps, turn around",
                                  "cgspeed MotionBuilder-friendly BVH via facebookresearch/fairmotion "
                                  "@ e400e564deac93bb74ffecd9c366d76b3406e217"),
    "kinect_v1_cmu_131_01_walk": ("mocap_bvh/131_01.bvh", "subject 131 trial 1", "start, walk, stop",
                                  "cgspeed 3dsMax-friendly BVH via yuki-koyama/bvh11 "
                                  "@ c9072174fe89e0bf9776a092179b464ea39975e5"),
    "kinect_v1_cmu_131_02_walk": ("mocap_bvh/131_02.bvh", "subject 131 trial 2", "start, walk, stop",
                                  "cgspeed 3dsMax-friendly BVH via yuki-koyama/bvh11 "
                                  "@ c9072174fe89e0bf9776a092179b464ea39975e5"),
    "kinect_v1_cmu_131_03_hop": ("mocap_bvh/131_03.bvh", "subject 131 trial 3", "start, hop, stop",
                                 "cgspeed 3dsMax-friendly BVH via yuki-koyama/bvh11 "
                                 "@ c9072174fe89e0bf9776a092179b464ea39975e5"),
}
TARGET_RATE = 30.0
LICENSES = ("kinect_v2/LICENSE.LabanotationSuite.txt", "kinect_v2/LICENSE.kinectron.txt",
            "mocap_bvh/LICENSE.fairmotion.txt", "mocap_bvh/LICENSE.bvh11.txt")


def decimate(take: Take, rate: float) -> Take:
    """Keep every n-th frame when the take's rate is a whole multiple of `rate`."""
    step = take.rate / rate
    if abs(step - round(step)) > 1e-9 or step < 1:
        raise ValueError(f"cannot decimate {take.rate} fps to {rate} fps exactly")
    out = take.slice(slice(None, None, int(round(step))))
    out.rate = rate
    return out


def kinect_v2_takes(data: Path) -> dict[str, Take]:
    takes = {}
    for name, (rel, prov) in KINECT_V2_TAKES.items():
        reader = kinectron_json if rel.endswith(".json") else kinect_v2_csv
        take = reader.read(data / rel)
        take.metadata = {**take.metadata, **prov, "converted": "converted to .krtake by "
                         "tools/make_sample_takes.py; joints and timestamps unchanged"}
        takes[name] = take
    return takes


def cmu_takes(data: Path) -> dict[str, Take]:
    takes = {}
    for name, (rel, trial, motion, release) in CMU_TAKES.items():
        full = bvh.read(data / rel)
        take = decimate(full, TARGET_RATE)
        frame_time = float(full.times[1])  # the BVH's Frame Time (times are frame * frame_time)
        # the reader's report on the mapping (bvh_mapping, bvh_unit, ...) stays out of the headers: `info` on
        # the BVH shows it, and the joints it describes are the ones the takes hold
        meta = {k: v for k, v in take.metadata.items() if k in ("source_file", "bvh_family", "bvh_units_to_metres",
                                                                  "virtual_camera", "converted")}
        take.metadata = {**meta, "source": f"CMU Graphics Lab Motion Capture Database, {trial} "
                         f"({motion}); {release}", **CMU,
                         "resampled": f"{frame_time:g} s frames, every 4th frame kept (120 -> 30 fps)"}
        takes[name] = take
    return takes


def build(data: Path, out: Path) -> dict[str, Path]:
    out.mkdir(parents=True, exist_ok=True)
    written = {}
    for name, take in {**kinect_v2_takes(data), **cmu_takes(data)}.items():
        path = out / f"{name}.krtake"
        krtake.write(path, take)
        written[name] = path
    lic = out / "licenses"
    lic.mkdir(exist_ok=True)
    for rel in LICENSES:
        shutil.copyfile(data / rel, lic / Path(rel).name)
    return written


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", type=Path, help="a folder laid out like shared/data (default: tests/data)")
    ap.add_argument("--out", type=Path, default=REPO / "sample_takes")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        written = build(args.data or materialize(Path(tmp) / "data"), args.out)
    total = 0
    for name, path in written.items():
        take = krtake.read(path)
        size = path.stat().st_size
        total += size
        print(f"{path.name:45s} {take.skeleton.name:9s} {take.frame_count:5d} frames {take.duration:6.2f} s "
              f"{take.rate:5.1f} fps {size / 1024:7.1f} KiB")
    print(f"total {total / 1024 / 1024:.2f} MiB")


if __name__ == "__main__":
    main()
