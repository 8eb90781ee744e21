"""Copy the real data the repository needs from the workshop's shared/data (deterministic; run again after
changing the lists below):

    .venv/bin/python tools/vendor_data.py [--data ../shared/data]

* tests/data/<same sub-path as under shared/data>: what the tests read. Files over 256 KB are stored gzipped
  (`name.gz`, no timestamp in the header, so a rerun writes the same bytes); tests/conftest.py serves them
  decompressed. The MakeHuman body files are not copied there: tests read the package's copy.
* kinect_retarget/assets/: what the product needs at run time (the simulated Kinect's body and motion).
  Plain files: the extension zip compresses them, and `autorig` reads the OBJ as it is.

Credits and licences: tests/data/CREDITS.md and kinect_retarget/assets/CREDITS.md (written by hand).
utd_mhad_dev/ is research-only and never copied.
"""
from __future__ import annotations

import argparse
import gzip
import shutil
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
TESTS_DATA = REPO / "tests" / "data"
ASSETS = REPO / "kinect_retarget" / "assets"
GZIP_OVER = 256 * 1024

FAKENECT = "depth_real/fakenect_openiss/fakenect-record"
FAKENECT_FRAMES = 12          # the first 12 of the 40 shared frames: the person is in every one
TEST_FILES = [
    *(f"kinect_v2/{n}" for n in ("Ges01_wavehand.csv", "Ges02_balancinghands.csv", "Ges03_drawlines.csv",
                                 "Ges04_comehere.csv", "Ges05_demopoint.csv", "Ges06_chickenwing.csv",
                                 "joints.csv", "recorded_skeleton.json", "LICENSE.LabanotationSuite.txt",
                                 "LICENSE.kinectron.txt")),
    *(f"kinect_v2_vicon_uiprmd/Kinect/m{m}_s01_e01_{k}.txt" for m in ("01", "05", "07")
      for k in ("positions", "angles")),
    *(f"mocap_bvh/{n}" for n in ("01_01.bvh", "131_01.bvh", "131_02.bvh", "131_03.bvh", "LICENSE.fairmotion.txt",
                                 "LICENSE.bvh11.txt", "README.bvh11_resources.md")),
    *(f"meshes/makehuman/{n}" for n in ("tpose.bvh", "tpose.meta", "benchmark.bvh", "benchmark.meta",
                                        "LICENSE.ASSETS.md")),
    "depth_real/fakenect_openiss/LICENSE.OpenISS.txt",
    "depth_real/skeltrack/COPYING.Skeltrack.LGPL-3.0.txt",
]
TEST_GLOBS = {FAKENECT: ("d-*.pgm", FAKENECT_FRAMES), "depth_real/skeltrack/tests/resources": ("depth-data-*", None)}

# package asset: source under shared/data (+ how many BVH frames to keep)
SIM_BVH_FRAMES = 360          # 90 frames at 30 fps, every 4th of the 120 fps clip: all the simulator renders
ASSET_FILES = {
    "makehuman/base.obj": ("meshes/makehuman/base.obj", None),
    "makehuman/default.mhskel": ("meshes/makehuman/default.mhskel", None),
    "makehuman/default_weights.mhw": ("meshes/makehuman/default_weights.mhw", None),
    "makehuman/LICENSE.ASSETS.md": ("meshes/makehuman/LICENSE.ASSETS.md", None),
    "motion/131_03.bvh": ("mocap_bvh/131_03.bvh", SIM_BVH_FRAMES),
    "motion/LICENSE.bvh11.txt": ("mocap_bvh/LICENSE.bvh11.txt", None),
}


def _write(src: Path, dst: Path) -> Path:
    dst.parent.mkdir(parents=True, exist_ok=True)
    data = src.read_bytes()
    if len(data) > GZIP_OVER:
        dst = dst.with_name(dst.name + ".gz")
        with open(dst, "wb") as raw, gzip.GzipFile(filename="", mode="wb", fileobj=raw, mtime=0,
                                                   compresslevel=9) as gz:
            gz.write(data)
    else:
        shutil.copyfile(src, dst)
    return dst


def first_bvh_frames(text: str, keep: int) -> str:
    """The BVH with only its first `keep` motion frames (the hierarchy and frame time unchanged)."""
    head, motion = text.split("MOTION", 1)
    lines = motion.strip("\r\n").splitlines()
    frames_at = next(i for i, l in enumerate(lines) if l.strip().startswith("Frames:"))
    body = lines[frames_at + 2:]
    if len(body) < keep:
        raise SystemExit(f"only {len(body)} frames, {keep} asked")
    return "\n".join([head + "MOTION", f"Frames: {keep}", lines[frames_at + 1], *body[:keep]]) + "\n"


def vendor(data: Path) -> list[Path]:
    written = []
    for rel in TEST_FILES:
        written.append(_write(data / rel, TESTS_DATA / rel))
    for folder, (pattern, limit) in TEST_GLOBS.items():
        for src in sorted((data / folder).glob(pattern))[:limit]:
            written.append(_write(src, TESTS_DATA / folder / src.name))
    for rel, (src, frames) in ASSET_FILES.items():
        dst = ASSETS / rel
        dst.parent.mkdir(parents=True, exist_ok=True)
        if frames:
            dst.write_text(first_bvh_frames((data / src).read_text(encoding="utf-8"), frames), encoding="utf-8")
        else:
            shutil.copyfile(data / src, dst)
        written.append(dst)
    return written


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", type=Path, default=REPO.parent / "shared" / "data")
    args = ap.parse_args()
    if not args.data.is_dir():
        raise SystemExit(f"{args.data}: the shared data folder is not there")
    for p in vendor(args.data):
        print(f"{p.stat().st_size:>9}  {p.relative_to(REPO)}")


if __name__ == "__main__":
    main()
