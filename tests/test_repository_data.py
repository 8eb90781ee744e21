"""The data the repository ships: credited, licensed, large files compressed, nothing research-only, and the
simulated Kinect's clip a faithful cut of the CMU recording."""
from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np

from kinect_retarget.assets import ASSETS_DIR, MAKEHUMAN_DIR, motion_clip

REPO = Path(__file__).resolve().parents[1]
TESTS_DATA = REPO / "tests" / "data"
NOTES = ("CREDITS.md", "README.md")


def _is_licence(p: Path) -> bool:
    return p.name.upper().startswith(("LICENSE", "COPYING")) or p.parent.name == "licenses"


def _data_files(root: Path):
    for p in sorted(root.rglob("*")):
        if p.is_file() and p.suffix not in (".py", ".pyc") and p.name not in NOTES and not _is_licence(p) \
                and "__pycache__" not in p.parts:
            yield p


def _licences_above(path: Path, root: Path) -> list[Path]:
    found, d = [], path.parent
    while True:
        found += [p for p in d.glob("*") if p.is_file() and _is_licence(p)]
        found += list((d / "licenses").glob("*"))
        if d == root:
            return found
        d = d.parent


def test_every_test_data_file_is_credited_and_has_a_licence_beside_it():
    credits = (TESTS_DATA / "CREDITS.md").read_text(encoding="utf-8")
    files = list(_data_files(TESTS_DATA))
    assert len(files) > 40
    for p in files:
        rel = p.relative_to(TESTS_DATA)
        assert f"`{rel.parts[0]}/" in credits, f"tests/data/CREDITS.md does not mention {rel.parts[0]}/"
        assert _licences_above(p, TESTS_DATA), f"no licence file for tests/data/{rel}"


def test_large_test_data_files_are_compressed():
    big = [str(p.relative_to(TESTS_DATA)) for p in _data_files(TESTS_DATA)
           if p.stat().st_size > 512 * 1024 and p.suffix != ".gz"]
    assert not big


THIRD_PARTY_ASSETS = ("makehuman", "motion")   # folders copied from elsewhere: each keeps its licence file


def test_package_assets_are_credited_and_licensed():
    credits = (ASSETS_DIR / "CREDITS.md").read_text(encoding="utf-8")
    files = list(_data_files(ASSETS_DIR))
    assert {p.name for p in files} >= {"base.obj", "default.mhskel", "default_weights.mhw", "131_03.bvh"}
    for p in files:
        top = p.relative_to(ASSETS_DIR).parts[0]
        assert f"`{top}" in credits, f"kinect_retarget/assets/CREDITS.md does not name {top}"
    for folder in THIRD_PARTY_ASSETS:
        for p in _data_files(ASSETS_DIR / folder):
            assert f"`{p.relative_to(ASSETS_DIR).as_posix()}`" in credits
            assert _licences_above(p, ASSETS_DIR), f"no licence file for kinect_retarget/assets/{p}"
    assert (MAKEHUMAN_DIR / "base.obj").is_file()


def test_nothing_research_only_is_tracked():
    tracked = subprocess.run(["git", "ls-files"], cwd=REPO, capture_output=True, text=True, check=True).stdout
    assert "utd_mhad" not in tracked.lower() and "utd-mhad" not in tracked.lower()


def test_the_simulator_clip_is_the_first_three_seconds_of_cmu_131_03(data_dir):
    from kinect_retarget.sim.bvh_motion import read_bvh_positions
    names, parents, cut, dt = read_bvh_positions(motion_clip("131_03"))
    names_full, parents_full, full, dt_full = read_bvh_positions(data_dir / "mocap_bvh" / "131_03.bvh")
    assert (names, list(parents), dt) == (names_full, list(parents_full), dt_full)
    assert len(cut) == 360                            # 90 frames at 30 fps: what the simulated Kinect renders
    np.testing.assert_array_equal(cut, full[:360])
