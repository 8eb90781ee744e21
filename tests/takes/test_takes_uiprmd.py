"""UI-PRMD Kinect positions + angles -> Kinect v2 takes (real files, data/README.md section 2)."""
from __future__ import annotations

import shutil

import numpy as np
import pytest

from kinect_retarget.core.skeletons import KINECT_V2, NOT_TRACKED, TRACKED
from kinect_retarget.core.take import TakeError
from kinect_retarget.takes import detect_format, load_take

FRAMES = {"m01": 73, "m05": 80, "m07": 63}  # deep squat, sit-to-stand, shoulder abduction


@pytest.mark.parametrize("move", sorted(FRAMES))
def test_real_movements(data_dir, move):
    folder = data_dir / "kinect_v2_vicon_uiprmd" / "Kinect"
    pos_file, ang_file = folder / f"{move}_s01_e01_positions.txt", folder / f"{move}_s01_e01_angles.txt"
    assert detect_format(pos_file) == "uiprmd" and detect_format(ang_file) == "uiprmd"
    take = load_take(pos_file)
    assert take.skeleton is KINECT_V2 and take.rate == 30.0 and take.frame_count == FRAMES[move]
    np.testing.assert_array_equal(load_take(ang_file).positions, take.positions)
    # Waist is absolute: (-x, y - 80, -z) cm -> m, checked against the raw first line.
    raw = np.array((pos_file.read_text().splitlines()[0]).split(","), dtype=float)
    np.testing.assert_allclose(take.positions[0, KINECT_V2.index("SpineBase")],
                               [-raw[0] / 100, (raw[1] - 80) / 100, -raw[2] / 100])
    k = KINECT_V2.index
    missing = [k(j) for j in ("HandLeft", "HandRight", "HandTipLeft", "ThumbLeft", "HandTipRight", "ThumbRight")]
    assert np.all(take.states[:, missing] == NOT_TRACKED)
    assert np.sum(take.states[0] == TRACKED) == 19
    p = take.positions
    # A person about 2.3 m in front of the sensor, facing it: their left on Kinect -X, upright.
    assert np.all((p[:, k("SpineBase"), 2] > 1.9) & (p[:, k("SpineBase"), 2] < 2.8))
    assert np.all(p[:, k("HipLeft"), 0] < p[:, k("HipRight"), 0])
    assert np.all(p[:, k("ShoulderLeft"), 0] < p[:, k("ShoulderRight"), 0])
    assert np.all(p[:, k("Head"), 1] > p[:, k("SpineShoulder"), 1])
    # Bone lengths come from the offsets: the thigh keeps its per-frame length |LeftLowerLeg offset|.
    offsets = np.loadtxt(pos_file, delimiter=",").reshape(-1, 22, 3)
    thigh = np.linalg.norm(p[:, k("KneeLeft")] - p[:, k("HipLeft")], axis=1)
    np.testing.assert_allclose(thigh, np.linalg.norm(offsets[:, 15], axis=1) / 100, rtol=1e-9)


def test_squat_goes_down_and_up(data_dir):
    take = load_take(data_dir / "kinect_v2_vicon_uiprmd" / "Kinect" / "m01_s01_e01_positions.txt")
    hips = take.positions[:, KINECT_V2.index("SpineBase"), 1]
    assert hips.max() - hips.min() > 0.3  # a deep squat lowers the hips by well over 30 cm
    assert np.argmin(hips) not in (0, take.frame_count - 1)


def test_errors(data_dir, tmp_path):
    folder = data_dir / "kinect_v2_vicon_uiprmd" / "Kinect"
    shutil.copy(folder / "m07_s01_e01_positions.txt", tmp_path / "m07_s01_e01_positions.txt")
    with pytest.raises(TakeError, match=r"m07_s01_e01_angles\.txt not found"):
        load_take(tmp_path / "m07_s01_e01_positions.txt")
    lines = (folder / "m07_s01_e01_angles.txt").read_text().splitlines(keepends=True)
    (tmp_path / "m07_s01_e01_angles.txt").write_text("".join(lines[:-3]))
    with pytest.raises(TakeError, match=r"63 frames but m07_s01_e01_angles\.txt has 60"):
        load_take(tmp_path / "m07_s01_e01_positions.txt")
    (tmp_path / "m07_s01_e01_angles.txt").write_text("".join(lines[:10] + [lines[10][:30] + "\n"] + lines[11:]))
    with pytest.raises(TakeError, match=r"m07_s01_e01_angles\.txt:11: expected 66 values"):
        load_take(tmp_path / "m07_s01_e01_positions.txt")
    shutil.copy(folder / "m07_s01_e01_positions.txt", tmp_path / "renamed.txt")
    with pytest.raises(TakeError, match=r"renamed\.txt: UI-PRMD files are named"):
        load_take(tmp_path / "renamed.txt")


@pytest.mark.parametrize("how, pattern", [
    ("truncated", r"positions\.txt:13: expected 66 values, found \d+"),
    ("garbage", r"positions\.txt:13: non-numeric value 'oops'"),
    ("columns", r"positions\.txt:13: expected 66 values, found 65"),
])
def test_corrupted_positions_name_the_line(data_dir, tmp_path, how, pattern):
    folder = data_dir / "kinect_v2_vicon_uiprmd" / "Kinect"
    shutil.copy(folder / "m01_s01_e01_angles.txt", tmp_path / "m01_s01_e01_angles.txt")
    lines = (folder / "m01_s01_e01_positions.txt").read_text().splitlines(keepends=True)
    fields = lines[12].strip().split(",")
    if how == "truncated":
        lines = lines[:12] + [",".join(fields[:30])]
    elif how == "columns":
        lines[12] = ",".join(fields[:-1]) + "\n"
    else:
        fields[4] = "nan" if how == "nan" else "oops"
        lines[12] = ",".join(fields) + "\n"
    (tmp_path / "m01_s01_e01_positions.txt").write_text("".join(lines))
    with pytest.raises(TakeError, match=pattern):
        load_take(tmp_path / "m01_s01_e01_positions.txt")
