"""Timestamps are read as files write them: the unit comes from the spacing of consecutive samples, is kept in
the take's metadata and printed by `info`; a spacing no unit explains names the file, the line and the spacing."""
from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from kinect_retarget.core.skeletons import KINECT_V2, NOT_TRACKED
from kinect_retarget.core.take import TakeError
from kinect_retarget.takes import krtake, load_take
from kinect_retarget.takes._timebase import infer_unit
from tests.conftest import SAMPLE_TAKES
from tests.takes import real_layout_fixtures as real

GES01 = SAMPLE_TAKES / "kinect_v2_ges01_wavehand.krtake"


@pytest.mark.parametrize("spacing, whole, unit", [
    (0.0333, False, "s"), (0.067, False, "s"), (33.0, True, "ms"), (16.7, False, "ms"),
    (33150.0, True, "µs"), (66300.0, True, "µs"), (333333.0, True, "100 ns ticks"), (1.0, True, "frame numbers"),
    (2.0, True, "frame numbers"), (1.0, False, None), (1000.0, True, None), (0.5, False, None),
])
def test_unit_from_spacing(spacing, whole, unit):
    assert infer_unit(spacing, whole) == unit


def test_msrc12_real_layout_fixture_is_current(tmp_path):
    fresh = real.write_msrc12_real(tmp_path / real.MSRC12_REAL.name)
    assert fresh.read_bytes() == real.MSRC12_REAL.read_bytes(), "regenerate: tests/takes/real_layout_fixtures.py"


def test_msrc12_real_layout_reads_microsecond_counter():
    """81 space-separated columns, 642926216 + ~33,150 per frame, 20 leading rows with nothing tracked."""
    take = load_take(real.MSRC12_REAL)
    src = krtake.read(real.SOURCE)
    assert take.source_format == "msrc12" and take.frame_count == real.LEADING_EMPTY + real.FRAMES
    assert take.metadata["time_unit"] == "µs" and take.metadata["first_timestamp"] == real.FIRST_STAMP
    assert take.rate == 30.0
    steps = np.diff(take.times)
    assert steps.min() > 0.0330 and steps.max() < 0.0333  # 33,150 ± 80 µs
    # the leading untracked rows keep their time: the body appears 20 frames (about 0.66 s) in
    assert not take.any_tracked[:real.LEADING_EMPTY].any() and take.any_tracked[real.LEADING_EMPTY:].all()
    assert take.times[real.LEADING_EMPTY] == pytest.approx(real.LEADING_EMPTY * 0.03315, abs=1e-4)
    body = take.positions[real.LEADING_EMPTY:, 0]
    v1_spine_base = src.positions[:real.FRAMES, KINECT_V2.index("SpineBase")]
    np.testing.assert_allclose(body, v1_spine_base, atol=1e-5)


def _v2_csv(path, take, stamps, fmt="%d"):
    """Kinect v2 CSV lines (KinectReader layout) with the given timestamp column."""
    f, nj = take.states.shape
    block = np.concatenate([np.nan_to_num(take.positions), take.states[..., None]], axis=2).reshape(f, -1)
    path.write_text("".join((fmt % t) + "," + ",".join(f"{v:.6g}" for v in row) + "\n"
                            for t, row in zip(stamps, block)))
    return path


@pytest.mark.parametrize("per_second, unit", [(1e7, "100 ns ticks"), (1e3, "ms"), (1e6, "µs")])
def test_kinect_v2_csv_units(tmp_path, per_second, unit):
    take = krtake.read(GES01).slice(slice(0, 40))
    stamps = np.round(31867373716 + take.times * per_second)
    back = load_take(_v2_csv(tmp_path / "g.csv", take, stamps))
    assert back.metadata["time_unit"] == unit and back.rate == take.rate
    np.testing.assert_allclose(back.times, take.times - take.times[0], atol=1.0 / per_second + 1e-9)


def _kinectron(path, take, stamps):
    fields = ("cameraX", "cameraY", "cameraZ")
    records = [{"bodyIndex": 0, "tracked": True, "trackingId": "7", "record_startime": 1, "record_timestamp": t,
                "joints": [{**dict(zip(fields, p)), "depthX": 0.5, "depthY": 0.5, "colorX": 0.5, "colorY": 0.5,
                            "orientationW": 1, "orientationX": 0, "orientationY": 0, "orientationZ": 0}
                           for p in frame.tolist()]}
               for t, frame in zip(stamps, take.positions)]
    path.write_text(json.dumps(records))
    return path


@pytest.mark.parametrize("per_second, unit", [(1e3, "ms"), (1.0, "s")])
def test_kinectron_units(tmp_path, per_second, unit):
    take = krtake.read(SAMPLE_TAKES / "kinect_v2_kinectron_recorded_skeleton.krtake").slice(slice(0, 30))
    stamps = (1500000000 + take.times * 1000).round() / 1000 * per_second
    back = load_take(_kinectron(tmp_path / "k.json", take, stamps.tolist()))
    assert back.source_format == "kinectron_json" and back.metadata["time_unit"] == unit
    np.testing.assert_allclose(back.times, take.times - take.times[0], atol=2e-3)


def test_utkinect_frame_numbers_and_krtake_declared_unit(tmp_path):
    from tests.takes import format_fixtures as fx
    ut = load_take(fx.FIXTURES / "joints_s01_e01_converted_joints.txt")
    assert ut.metadata["time_unit"] == "frame numbers" and ut.rate == 30.0
    # a .krtake declares its column's unit in the header; version 1 writes seconds, others are honoured
    lines = GES01.read_text().splitlines(keepends=True)
    header = json.loads(lines[0])
    assert load_take(GES01).metadata["time_unit"] == "s"
    header["time_unit"] = "ms"
    body = ["%.3f" % (float(ln.split(" ", 1)[0]) * 1000) + " " + ln.split(" ", 1)[1] for ln in lines[1:]]
    (tmp_path / "ms.krtake").write_text(json.dumps(header) + "\n" + "".join(body))
    ms = load_take(tmp_path / "ms.krtake")
    np.testing.assert_allclose(ms.times, load_take(GES01).times, atol=1e-6)
    header["time_unit"] = "fortnights"
    (tmp_path / "bad.krtake").write_text(json.dumps(header) + "\n" + "".join(lines[1:]))
    with pytest.raises(TakeError, match=r"bad\.krtake: unknown time unit 'fortnights'"):
        load_take(tmp_path / "bad.krtake")


def test_spacing_that_fits_no_unit_names_file_line_and_spacing(tmp_path):
    lines = real.MSRC12_REAL.read_text().splitlines()
    rows = [f"{1000 * i + 5000} {ln.split(' ', 1)[1]}" for i, ln in enumerate(lines)]  # 1000 apart: 1 s or 1 ms
    (tmp_path / "odd.csv").write_text("\n".join(rows) + "\n")
    with pytest.raises(TakeError, match=r"odd\.csv:2: timestamps are 1000 apart, which fits no time unit"):
        load_take(tmp_path / "odd.csv")
    rows[30] = rows[30].replace(rows[30].split(" ", 1)[0], "nan", 1)
    (tmp_path / "nan_time.csv").write_text("\n".join(rows) + "\n")
    with pytest.raises(TakeError, match=r"nan_time\.csv:31: timestamp is NaN or infinite"):
        load_take(tmp_path / "nan_time.csv")


def test_info_prints_time_unit():
    r = subprocess.run([sys.executable, "-m", "kinect_retarget", "info", str(real.MSRC12_REAL)],
                       capture_output=True, text=True, check=True)
    assert any(line.split() == ["time_unit", "µs"] for line in r.stdout.splitlines()), r.stdout
    assert "rate_fps          30.0" in r.stdout and "frames            80" in r.stdout


def test_untracked_frames_are_not_screened(tmp_path):
    """Rows of zeros are 'nothing tracked', not bad samples: nothing is reported as dropped."""
    take = load_take(real.MSRC12_REAL)
    assert np.all(take.states[:real.LEADING_EMPTY] == NOT_TRACKED)
    assert "dropped_joint_samples" not in take.metadata and "warnings" not in take.metadata
