"""The repository's copy of the real data (tests/data) as one folder laid out like the workshop's shared/data.

tests/data keeps files over 256 KB gzipped and holds no copy of the MakeHuman body the package ships
(kinect_retarget/assets/makehuman); `materialize` builds a folder with every file plain and the body under
meshes/makehuman/, so readers see the files exactly as they come.
"""
from __future__ import annotations

import gzip
import os
import shutil
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
TESTS_DATA = REPO / "tests" / "data"
PACKAGE_MAKEHUMAN = REPO / "kinect_retarget" / "assets" / "makehuman"


def _place(src: Path, dst: Path) -> None:
    dst.parent.mkdir(parents=True, exist_ok=True)
    if src.suffix == ".gz":
        with gzip.open(src, "rb") as fin, open(dst.with_suffix(""), "wb") as fout:
            shutil.copyfileobj(fin, fout)
    else:
        os.symlink(src, dst)


def materialize(out: Path) -> Path:
    """Fill `out` (an empty or missing folder) with tests/data decompressed; returns `out`."""
    out.mkdir(parents=True, exist_ok=True)
    for src in sorted(TESTS_DATA.rglob("*")):
        if src.is_file():
            _place(src, out / src.relative_to(TESTS_DATA))
    for src in sorted(PACKAGE_MAKEHUMAN.glob("*")):
        if not (out / "meshes" / "makehuman" / src.name).exists():
            _place(src, out / "meshes" / "makehuman" / src.name)
    return out
