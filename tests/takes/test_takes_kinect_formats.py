"""Kinect take readers on the real recordings (v2 CSV, Kinectron JSON) and on converted fixtures in the exact
NTU RGB+D, MSRC-12 and UTKinect layouts (no real file of those is redistributable here)."""
from __future__ import annotations

import json

import numpy as np
import pytest

from kinect_retarget.core.skeletons import INFERRED, KINECT_V1, KINECT_V2, NOT_TRACKED, TRACKED
from kinect_retarget.core.take import TakeError
from kinect_retarget.takes import kinect_v2_csv, kinectron_json, msrc12, ntu_skeleton, utkinect

from tests.takes import format_fixtures as fx

V2_CSV = {  # file: (frames, duration s) from data/README.md
    "Ges01_wavehand.csv": (154, 5.2), "Ges02_balancinghands.csv": (161, 5.4),
    "Ges03_drawlines.csv": (213, 7.2), "Ges04_comehere.csv": (172, 5.9), "Ges05_demopoint.csv": (190, 6.4),
    "Ges06_chickenwing.csv": (160, 5.3), "joints.csv": (371, 12.4),
}


@pytest.mark.parametrize("name", sorted(V2_CSV))
def test_kinect_v2_csv_real_files(data_dir, name, rng):
    path = data_dir / "kinect_v2" / name
    frames, duration = V2_CSV[name]
    take = kinect_v2_csv.read(path)
    assert take.skeleton is KINECT_V2 and take.source_format == "kinect_v2_csv"
    assert take.frame_count == frames
    assert take.duration == pytest.approx(duration, abs=0.06)
    assert take.rate == 30.0
    # Spot-check random lines against the raw text, parsed here independently.
    raw = path.read_text().splitlines()
    t0 = int(raw[0].split(",")[0])
    for i in rng.integers(0, frames, size=5):
        fields = [v for v in raw[i].split(",") if v.strip()]
        assert len(fields) == 101
        values = np.array(fields, dtype=float)
        np.testing.assert_allclose(take.positions[i].ravel(), values[1:].reshape(25, 4)[:, :3].ravel())
        np.testing.assert_array_equal(take.states[i], values[4::4])
        assert take.times[i] == pytest.approx((int(fields[0]) - t0) / 1e7)


def test_kinect_v2_csv_first_line_of_joints(data_dir):
    take = kinect_v2_csv.read(data_dir / "kinect_v2" / "joints.csv")
    np.testing.assert_allclose(take.positions[0, 0], [0.0710328, -0.600598, 0.978207])
    np.testing.assert_allclose(take.positions[0, 1], [0.0733363, -0.285628, 0.946217])
    assert take.states[0, 0] == INFERRED and take.states[0, 1] == TRACKED
    assert take.metadata["first_timestamp"] == 31867373716 and take.metadata["time_unit"] == "100 ns ticks"


def test_kinectron_json_real_file(data_dir):
    path = data_dir / "kinect_v2" / "recorded_skeleton.json"
    take, two_d = kinectron_json.read_with_2d(path)
    assert take.skeleton is KINECT_V2 and take.source_format == "kinectron_json"
    assert take.frame_count == 286
    assert take.duration == pytest.approx(9.6, abs=0.05)
    assert take.rate == 30.0
    assert np.all(take.states == TRACKED)
    raw = json.loads(path.read_text())
    for i in (0, 143, 285):
        for j in (0, 7, 24):
            rj = raw[i]["joints"][j]
            np.testing.assert_allclose(take.positions[i, j], [rj["cameraX"], rj["cameraY"], rj["cameraZ"]])
            np.testing.assert_allclose(two_d["color"][i, j], [rj["colorX"], rj["colorY"]])
            np.testing.assert_allclose(two_d["orientation"][i, j], [rj["orientationW"], rj["orientationX"],
                                                                    rj["orientationY"], rj["orientationZ"]])
        assert take.times[i] == pytest.approx((raw[i]["record_timestamp"] - raw[0]["record_timestamp"]) / 1e3)
    # Unmirrored depth pixels follow the pinhole model of the project conventions (u = cx - f x / z,
    # v = cy - f y / z) with the fit quoted in data/README.md: f ~ 366 px, sub-pixel residual. The SDK's own
    # pixels are mirrored: u grows with x.
    p = take.positions.reshape(-1, 3)
    for key, sign in (("depth_px_unmirrored", 1), ("depth_px", -1)):
        uv = two_d[key].reshape(-1, 2)
        for axis in (0, 1):
            a = np.stack([-p[:, axis] / p[:, 2], np.ones(len(p))], axis=1)
            (f, c), *_ = np.linalg.lstsq(a, uv[:, axis], rcond=None)
            rms = np.sqrt(np.mean((a @ [f, c] - uv[:, axis]) ** 2))
            assert f == pytest.approx(366 * (sign if axis == 0 else 1), abs=4) and rms < 0.5
    np.testing.assert_allclose(two_d["color_px"][0, 0], np.array([raw[0]["joints"][0]["colorX"],
                                                                  raw[0]["joints"][0]["colorY"]]) * (1920, 1080))
    assert two_d["left_hand_state"].shape == (286,)


def test_kinectron_untracked_and_duplicate_bodies(tmp_path, data_dir):
    raw = json.loads((data_dir / "kinect_v2" / "recorded_skeleton.json").read_text())[:20]
    raw[3] = {**raw[3], "tracked": False, "joints": []}
    other = {**raw[5], "trackingId": "999", "bodyIndex": 1}
    other["joints"] = [{**j, "cameraX": j["cameraX"] + 1.0} for j in raw[5]["joints"]]
    raw.insert(5, other)  # a second body at the same timestamp, listed first
    (tmp_path / "two.json").write_text(json.dumps(raw))
    take = kinectron_json.read(tmp_path / "two.json")
    assert take.frame_count == 20
    assert np.all(take.states[3] == NOT_TRACKED) and np.all(np.isnan(take.positions[3]))
    assert take.positions[5, 0, 0] == pytest.approx(raw[6]["joints"][0]["cameraX"])  # the first body kept


@pytest.fixture(scope="module")
def fixtures(data_dir, tmp_path_factory):
    """The committed converted fixtures, checked to be exactly what the converters make today."""
    fresh = fx.make_all(data_dir, tmp_path_factory.mktemp("fixtures"))
    for name, path in fresh.items():
        committed = fx.FIXTURES / path.name
        assert committed.read_bytes() == path.read_bytes(), f"{committed} is stale: regenerate it"
    return {name: fx.FIXTURES / path.name for name, path in fresh.items()}


def test_ntu_fixture(fixtures, data_dir):
    take, two_d = ntu_skeleton.read_with_2d(fixtures["ntu"])
    src = kinect_v2_csv.read(data_dir / "kinect_v2" / "Ges01_wavehand.csv").slice(slice(0, 40))
    assert take.skeleton is KINECT_V2 and take.rate == 30.0 and take.frame_count == 40
    assert np.all(take.states[:3] == NOT_TRACKED) and take.metadata["frames_without_body"] == 3
    assert take.metadata["max_bodies"] == 2
    # The first body listed drives the take (the second one, in frames 10-19, is 1 m to the side).
    np.testing.assert_allclose(take.positions[3:], src.positions[3:], atol=5e-6)
    np.testing.assert_array_equal(take.states[3:], src.states[3:])
    assert take.times[-1] == pytest.approx(39 / 30)
    expected = fx.kinect_to_depth_pixel(src.positions[3:, 0], *fx.DEPTH_CAMERA)
    np.testing.assert_allclose(two_d["depth_px_unmirrored"][3:, 0], expected, atol=1e-3)
    np.testing.assert_allclose(two_d["depth_px"][3:, 0, 0], 511 - expected[:, 0], atol=1e-3)
    assert np.all(two_d["body_count"][:3] == 0) and np.all(two_d["body_count"][10:20] == 2)


def test_msrc12_fixture(fixtures, data_dir):
    take = msrc12.read(fixtures["msrc12"])
    src = fx.v1_from_v2(kinect_v2_csv.read(data_dir / "kinect_v2" / "joints.csv").slice(slice(0, 60)))
    assert take.skeleton is KINECT_V1 and take.frame_count == 60 and take.rate == 30.0
    assert take.metadata["first_timestamp"] == pytest.approx(0.033333) and take.metadata["time_unit"] == "s"
    tracked = src.states != NOT_TRACKED
    np.testing.assert_array_equal(take.states, np.where(tracked, TRACKED, NOT_TRACKED))
    np.testing.assert_allclose(take.positions[tracked], src.positions[tracked], atol=5e-6)
    np.testing.assert_allclose(take.times, src.times, atol=2e-6)


def test_utkinect_fixture(fixtures, data_dir):
    take = utkinect.read(fixtures["utkinect"])
    keep = np.ones(60, dtype=bool)
    keep[[7, 8, 30]] = False
    src = fx.v1_from_v2(kinect_v2_csv.read(data_dir / "kinect_v2" / "joints.csv").slice(slice(0, 60)))
    assert take.skeleton is KINECT_V1 and take.frame_count == 57 and take.rate == 30.0
    np.testing.assert_allclose(take.positions, src.positions[keep], atol=5e-6)
    # Frame numbers keep the gaps: frame 7 follows frame 6 after 3 video frames (0.1 s).
    assert take.times[7] - take.times[6] == pytest.approx(3 / 30)
    assert take.metadata["first_video_frame"] == 248 and take.metadata["time_unit"] == "frame numbers"


def test_utkinect_repeated_frame_numbers(fixtures, tmp_path):
    lines = fixtures["utkinect"].read_text().splitlines(keepends=True)
    (tmp_path / "rep.txt").write_text("".join(lines[:5] + [lines[4]] + lines[5:]))
    take = utkinect.read(tmp_path / "rep.txt")
    assert take.frame_count == 57 and take.metadata["repeated_frames_dropped"] == 1
    (tmp_path / "back.txt").write_text("".join(lines[:5] + [lines[2]] + lines[5:]))
    with pytest.raises(TakeError, match=r"back\.txt:6: frame number 250 comes after 252"):
        utkinect.read(tmp_path / "back.txt")


def test_ntu_fast_layout_agrees_with_the_walk(fixtures):
    """The vectorised layout (used for valid files) gives what the frame-by-frame walk gives."""
    import warnings
    from kinect_retarget.takes import _numeric
    text = _numeric.normalise(fixtures["ntu"].read_bytes())
    counts = _numeric.field_counts(text)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        flat = np.fromstring(text.decode(), sep=" ")
    lines = np.flatnonzero(counts)
    start = np.concatenate([[0], np.cumsum(counts)[:-1]])
    fast = ntu_skeleton._layout_fast(counts[lines], flat[start[lines]], 40)
    assert fast is not None
    slow = ntu_skeleton._layout_walk("x", lines, counts, 40, lambda k, n, what: int(lines[k]),
                                     lambda li, what: int(flat[start[li]]))
    for a, b in zip(fast, slow):
        np.testing.assert_array_equal(a, b)
