"""Every BVH file in the repository (and the workshop's shared data when it is there): the Kinect joints the
structural mapper found, the unit, the up axis (and what gave it: the floor under the feet, with its angle to
the axis, or the head above the feet), the position-channel reading, and the baked figure.

    .venv/bin/python benchmarks/bench_bvh_files.py [--mapping]

Baked figure: the take baked onto the generated Kinect rig without Blender (solver + Blender-like forward
kinematics, tests/takes/baked_figure.py); its height is the Head joint above the lowest ankle or foot joint
(90th percentile over the frames; the head joint is the head's centre, so about 0.9 of the standing height),
"upright" means head above pelvis above both ankles in every frame. Prints figures only.
"""
from __future__ import annotations

import argparse
import gzip
import re
import tempfile
import time
from pathlib import Path

import _common

from kinect_retarget.core.take import TakeError
from kinect_retarget.takes import bvh
from tests.takes import baked_figure

SHORT = {"HipCenter": "pelvis", "ShoulderLeft": "shoulderL", "ElbowLeft": "elbowL", "WristLeft": "wristL",
         "HandLeft": "handL", "HipRight": "hipR", "KneeRight": "kneeR", "AnkleRight": "ankleR", "FootRight": "footR",
         "Head": "head"}


def files() -> list[Path]:
    found = sorted(p for p in _common.REPO.rglob("*.bvh*") if p.suffix in (".bvh", ".gz")
                   and ".venv" not in p.parts and p.name.endswith((".bvh", ".bvh.gz")))
    if _common.SHARED_DATA.is_dir():
        found += sorted(_common.SHARED_DATA.rglob("*.bvh"))
    return found


def plain(path: Path, tmp: Path) -> Path:
    if path.suffix != ".gz":
        return path
    out = tmp / path.name[:-3]
    out.write_bytes(gzip.decompress(path.read_bytes()))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mapping", action="store_true", help="print every joint's mapping, not just a summary")
    args = ap.parse_args()
    print(f"{'file':58s} {'frames':>6s} {'unit':12s} {'up':3s} {'up from':12s} {'pos.ch':8s} {'stand m':>7s} "
          f"{'baked m':>7s} {'upright':7s} {'read s':>6s}  mapping (selected joints)")
    with tempfile.TemporaryDirectory() as tmp:
        for path in files():
            rel = path.relative_to(_common.REPO) if _common.REPO in path.parents else path
            try:
                t0 = time.perf_counter()
                take = bvh.read(plain(path, Path(tmp)), min_range=None)
                dt = time.perf_counter() - t0
            except TakeError as exc:
                print(f"{rel!s:58s} refused: {exc}")
                continue
            meta = take.metadata
            joints, _ = baked_figure.bake(take)
            fig = baked_figure.heights(joints, take.skeleton)
            reading = meta["bvh_position_channels"]
            mode = "full" if "full local" in reading else ("delta" if "added" in reading else "root")
            mapping = meta["bvh_mapping"]
            note = next((n for n in meta["bvh_mapping_notes"] if n.startswith("up: ")), "")
            tilt = re.search(r"(?:level \(|tilted )([0-9.]+) degrees", note)
            source = f"floor {tilt.group(1)}deg" if note.startswith("up: floor") and tilt else "head"
            summary = ", ".join(f"{SHORT[j]}={mapping[j].split(' (')[0]}" for j in SHORT)
            print(f"{rel!s:58s} {take.frame_count:6d} {meta['bvh_unit'].split(' (')[0]:12s} "
                  f"{meta['bvh_up_axis']:3s} {source:12s} {mode:8s} {meta['bvh_standing_height_m']:7.3f} "
                  f"{fig['head_to_foot_m']:7.3f} {fig['upright']!s:7s} {dt:6.3f}  {summary}")
            for w in meta.get("warnings", ()):
                print(f"{'':58s} warning: {w}")
            if args.mapping:
                for joint, how in mapping.items():
                    print(f"{'':8s}{joint:15s} {how}")


if __name__ == "__main__":
    main()
