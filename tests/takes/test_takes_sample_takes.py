"""sample_takes/: present, credited, equal to their sources, and round-tripping through .krtake."""
from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from kinect_retarget.core.skeletons import NOT_TRACKED
from kinect_retarget.takes import detect_format, krtake, load_take

REPO = Path(__file__).resolve().parents[2]
SAMPLES = REPO / "sample_takes"


def _tool():
    spec = importlib.util.spec_from_file_location("make_sample_takes", REPO / "tools" / "make_sample_takes.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.fixture(scope="module")
def tool():
    return _tool()


@pytest.fixture(scope="module")
def sources(tool, data_dir):
    """The takes the tool converts, read straight from the repository's tests/data."""
    return {**tool.kinect_v2_takes(data_dir), **tool.cmu_takes(data_dir)}


def test_every_sample_is_listed_and_credited(tool):
    names = set(tool.KINECT_V2_TAKES) | set(tool.CMU_TAKES)
    files = {p.stem for p in SAMPLES.glob("*.krtake")}
    assert files == names
    credits = (SAMPLES / "CREDITS.md").read_text()
    for name in names:
        assert f"`{name}.krtake`" in credits
    assert "NSF EIA-0196217" in credits and "Microsoft" in credits and "Kinectron" in credits
    for rel in tool.LICENSES:
        assert (SAMPLES / "licenses" / Path(rel).name).is_file()
    total = sum(p.stat().st_size for p in SAMPLES.rglob("*"))
    assert total < 4 * 1024 * 1024


def _same(a, b, atol):
    assert a.skeleton is b.skeleton and a.rate == b.rate and a.frame_count == b.frame_count
    np.testing.assert_array_equal(a.states, b.states)
    seen = a.states != NOT_TRACKED
    np.testing.assert_allclose(a.positions[seen], b.positions[seen], atol=atol)
    np.testing.assert_allclose(a.times, b.times, atol=1e-6)


@pytest.mark.parametrize("name", sorted(p.stem for p in SAMPLES.glob("*.krtake")))
def test_sample_matches_its_source(name, sources):
    path = SAMPLES / f"{name}.krtake"
    assert detect_format(path) == "krtake"
    take = load_take(path)
    _same(take, sources[name], atol=5e-6)  # .krtake keeps 5 decimals (10 micrometres)
    assert take.metadata["license"] and take.metadata["credit"] and take.metadata["source"]


def test_cmu_samples_are_30fps_mocap(sources):
    jumps = sources["kinect_v1_cmu_01_01_jumps"]
    assert jumps.rate == 30.0 and jumps.frame_count == 688
    assert np.allclose(np.diff(jumps.times), 4 / 120, atol=1e-3)
    assert jumps.duration == pytest.approx(22.9, abs=0.05)


def test_round_trip_through_krtake(tmp_path):
    for path in sorted(SAMPLES.glob("*.krtake")):
        take = krtake.read(path)
        again = tmp_path / path.name
        krtake.write(again, take)
        assert again.read_bytes() == path.read_bytes()  # write(read(x)) == x, byte for byte
        _same(krtake.read(again), take, atol=0)


def test_tool_output_is_what_is_committed(sources, tmp_path):
    """The tool's takes, converted again now, write exactly the committed bytes (nothing stale)."""
    for name, take in sources.items():
        krtake.write(tmp_path / f"{name}.krtake", take)
        assert (tmp_path / f"{name}.krtake").read_bytes() == (SAMPLES / f"{name}.krtake").read_bytes(), \
            f"sample_takes/{name}.krtake is stale: run tools/make_sample_takes.py"
