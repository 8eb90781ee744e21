"""Partly broken frames: a joint whose value is NaN, infinite or absurd (> 20 m from the sensor) becomes not
tracked in that frame, the take loads and says how many samples were dropped and where the first was; only a
file with no usable frame is refused. One mechanism (takes/_screening.py) behind every reader family."""
from __future__ import annotations

import json
import shutil

import numpy as np
import pytest

from kinect_retarget.core.skeletons import NOT_TRACKED
from kinect_retarget.core.take import TakeError
from kinect_retarget.takes import krtake, load_take, ntu_skeleton
from tests.conftest import SAMPLE_TAKES
from tests.takes import format_fixtures as fx
from tests.takes import real_layout_fixtures as real
from tests.takes.test_time_units import _kinectron

BAD_VALUES = ("nan", "inf", "-inf", "25000.0")  # the last: 25 km from the sensor


def _set_fields(line: str, sep: str, edits: dict[int, str]) -> str:
    end = "\n" if line.endswith("\n") else ""
    fields = line.rstrip("\r\n").split(sep)
    for i, v in edits.items():
        fields[i] = v
    return sep.join(fields) + end


def _check(take, clean, frame_joints, line, label="line"):
    """`take` equals `clean` except the (frame, joint) samples listed, which are dropped."""
    expect = clean.states.copy()
    for f, j in frame_joints:
        expect[f, j] = NOT_TRACKED
    np.testing.assert_array_equal(take.states, expect)
    keep = expect != NOT_TRACKED
    np.testing.assert_allclose(take.positions[keep], clean.positions[keep])
    assert np.isnan(take.positions[~keep]).all()
    m = take.metadata
    assert m["dropped_joint_samples"] == len(frame_joints) and m[f"first_dropped_{label}"] == line
    warning = m["warnings"][-1]
    assert f"{len(frame_joints)} joint samples in" in warning and f"first at {label} {line}" in warning


# (file, field separator, first data line index (0-based), fields per joint, first joint field, time columns)
LINE_READERS = {
    "msrc12": (real.MSRC12_REAL, " ", 0, 4, 1),
    "utkinect": (fx.FIXTURES / "joints_s01_e01_converted_joints.txt", " ", 0, 3, 1),
    "krtake": (SAMPLE_TAKES / "kinect_v2_ges03_drawlines.krtake", " ", 1, 4, 1),
}


@pytest.mark.parametrize("bad", BAD_VALUES)
@pytest.mark.parametrize("fmt", sorted(LINE_READERS))
def test_line_formats_drop_bad_joint_samples(tmp_path, fmt, bad):
    src, sep, first, per_joint, col0 = LINE_READERS[fmt]
    clean = load_take(src)
    lines = src.read_text().splitlines(keepends=True)
    # frames 30 and 41: joint 3's x (and in frame 41 also joint 7's z) are broken
    damage = {30: {3: 0}, 41: {3: 0, 7: 2}}
    for frame, joints in damage.items():
        lines[first + frame] = _set_fields(lines[first + frame], sep,
                                           {col0 + per_joint * j + axis: bad for j, axis in joints.items()})
    path = tmp_path / f"broken{src.suffix}"
    path.write_text("".join(lines))
    take = load_take(path)
    assert take.source_format == clean.source_format and take.frame_count == clean.frame_count
    _check(take, clean, [(30, 3), (41, 3), (41, 7)], first + 31)
    assert take.metadata["warnings"][-1].startswith(f"{path}:{first + 31}: ")


def test_kinect_v2_csv_drops_bad_samples(data_dir, tmp_path):
    src = data_dir / "kinect_v2" / "Ges04_comehere.csv"
    lines = src.read_text().splitlines(keepends=True)
    lines[7] = _set_fields(lines[7], ",", {1 + 4 * 5 + 1: "NaN"})         # ElbowLeft y, line 8
    lines[90] = _set_fields(lines[90], ",", {1 + 4 * 11 + 2: "1e300"})    # HandRight z, absurdly far
    (tmp_path / "g4.csv").write_text("".join(lines))
    _check(load_take(tmp_path / "g4.csv"), load_take(src), [(7, 5), (90, 11)], 8)


def test_ntu_names_the_joint_line(tmp_path):
    src = fx.FIXTURES / "S001C001P001R001A001_converted_Ges01.skeleton"
    lines = src.read_text().splitlines(keepends=True)
    # line 211 (index 210) is a joint line of the first body; its depth pixel is broken, then its position
    lines[210] = _set_fields(lines[210], " ", {3: "nan"})
    lines[260] = _set_fields(lines[260], " ", {1: "inf"})
    (tmp_path / "n.skeleton").write_text("".join(lines))
    take, two_d = ntu_skeleton.read_with_2d(tmp_path / "n.skeleton")
    clean = load_take(src)
    dropped = np.argwhere(take.states != clean.states)
    assert len(dropped) == 2 and take.metadata["first_dropped_line"] == 211
    assert np.isnan(two_d["depth_px"][tuple(dropped[0])]).all()


def test_kinectron_names_the_record(tmp_path):
    take = krtake.read(SAMPLE_TAKES / "kinect_v2_kinectron_recorded_skeleton.krtake").slice(slice(0, 30))
    path = _kinectron(tmp_path / "k.json", take, (1500000000 + np.arange(30) * 33.3).round(1).tolist())
    doc = json.loads(path.read_text())
    doc[11]["joints"][3]["cameraZ"] = float("nan")
    doc[12]["joints"][4]["cameraX"] = None
    doc[13]["joints"][5]["depthX"] = float("inf")
    path.write_text(json.dumps(doc))
    clean = load_take(_kinectron(tmp_path / "c.json", take, (1500000000 + np.arange(30) * 33.3).round(1).tolist()))
    _check(load_take(path), clean, [(11, 3), (12, 4), (13, 5)], 11, label="record")


def test_uiprmd_drops_joints_below_a_broken_angle(data_dir, tmp_path):
    folder = data_dir / "kinect_v2_vicon_uiprmd" / "Kinect"
    shutil.copy(folder / "m01_s01_e01_positions.txt", tmp_path / "m01_s01_e01_positions.txt")
    lines = (folder / "m01_s01_e01_angles.txt").read_text().splitlines(keepends=True)
    lines[12] = _set_fields(lines[12], ",", {3 * 8: "nan"})  # LeftForearm's angle: the wrist below it is lost
    (tmp_path / "m01_s01_e01_angles.txt").write_text("".join(lines))
    take = load_take(tmp_path / "m01_s01_e01_positions.txt")
    clean = load_take(folder / "m01_s01_e01_positions.txt")
    lost = np.argwhere(take.states != clean.states)
    assert lost.tolist() == [[12, take.skeleton.index("WristLeft")]]
    assert take.metadata["dropped_joint_samples"] == 1 and take.metadata["first_dropped_line"] == 13


def test_bvh_drops_joints_below_a_broken_channel(data_dir, tmp_path):
    lines = (data_dir / "mocap_bvh" / "131_03.bvh").read_text().splitlines(keepends=True)
    tokens = lines[400].split()
    tokens[5] = "nan"  # the root's third rotation: every joint of that frame but the root itself
    lines[400] = " ".join(tokens) + "\n"
    (tmp_path / "nan.bvh").write_text("".join(lines))
    take = load_take(tmp_path / "nan.bvh")
    clean = load_take(data_dir / "mocap_bvh" / "131_03.bvh")
    frame = int(np.argmax(take.states.min(axis=1) != clean.states.min(axis=1)))
    assert take.metadata["first_dropped_line"] == 401
    assert take.states[frame].tolist() == [2] + [NOT_TRACKED] * 19  # HipCenter is the root's own position
    assert take.metadata["dropped_joint_samples"] == 19
    np.testing.assert_allclose(np.delete(take.positions, frame, 0), np.delete(clean.positions, frame, 0))


def test_no_usable_frame_is_refused(tmp_path):
    lines = real.MSRC12_REAL.read_text().splitlines()
    dead = []
    for ln in lines:
        fields = ln.split(" ")
        if any(float(v) for v in fields[1:]):
            fields[1::4] = ["nan"] * 20
        dead.append(" ".join(fields))
    (tmp_path / "dead.csv").write_text("\n".join(dead) + "\n")
    with pytest.raises(TakeError, match=r"dead\.csv:21: no usable frame: all 1200 tracked joint samples are NaN"):
        load_take(tmp_path / "dead.csv")


def test_structural_damage_keeps_its_errors(tmp_path):
    lines = real.MSRC12_REAL.read_text().splitlines(keepends=True)
    cases = {
        "cols.csv": (lines[:30] + [lines[30].rsplit(" ", 1)[0] + "\n"] + lines[31:], r"cols\.csv:31: expected 81"),
        "text.csv": (lines[:30] + [_set_fields(lines[30], " ", {5: "abc"})] + lines[31:],
                     r"text\.csv:31: non-numeric value 'abc'"),
        "cut.csv": (lines[:-1] + [lines[-1][:100]], rf"cut\.csv:{len(lines)}: expected 81 values, found"),
    }
    for name, (content, pattern) in cases.items():
        (tmp_path / name).write_text("".join(content))
        with pytest.raises(TakeError, match=pattern):
            load_take(tmp_path / name)
