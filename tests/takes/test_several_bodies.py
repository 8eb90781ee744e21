"""Takes with several performers: each body reads as its own take (NTU, Kinectron); formats with one body
refuse any other; a .krtake keeps which body it was, not the source's body count."""
from __future__ import annotations

import json

import numpy as np
import pytest

from kinect_retarget.core.skeletons import NOT_TRACKED
from kinect_retarget.takes import TakeError, body_count, kinectron_json, krtake, load_take
from tests.takes.two_performers import performers, write_two_person_ntu


@pytest.fixture
def two_ntu(data_dir, tmp_path):
    return write_two_person_ntu(data_dir, tmp_path / "S001C001P001R001A050.skeleton")


def test_ntu_bodies_read_as_their_own_performers(two_ntu, data_dir):
    first, second = performers(data_dir)
    a, b = load_take(two_ntu), load_take(two_ntu, body=1)
    assert body_count(a) == body_count(b) == 2 and b.metadata["body"] == 1 and "body" not in a.metadata
    np.testing.assert_allclose(a.positions, first.positions, atol=5e-6)
    np.testing.assert_allclose(b.positions, second.positions + [1.0, 0, 0], atol=5e-6)
    np.testing.assert_array_equal(b.states, second.states)
    # the two gestures differ: a mix-up of bodies would show
    assert np.abs(a.positions - (b.positions - [1.0, 0, 0])).max() > 0.2
    with pytest.raises(TakeError, match="no body 2"):
        load_take(two_ntu, body=2)


def test_ntu_frames_without_the_second_body_are_untracked(data_dir, tmp_path):
    from tests.takes import format_fixtures as fx
    path = fx.FIXTURES / "S001C001P001R001A001_converted_Ges01.skeleton"  # a second body in frames 10-19
    b = load_take(path, body=1)
    assert np.all(b.states[:10] == NOT_TRACKED) and np.all(b.states[20:] == NOT_TRACKED)
    np.testing.assert_allclose(b.positions[10:20], load_take(path).positions[10:20] + [1.0, 0, 0], atol=5e-6)


def test_single_body_formats_refuse_other_bodies(data_dir):
    path = data_dir / "kinect_v2" / "Ges01_wavehand.csv"
    assert body_count(load_take(path)) == 1
    with pytest.raises(TakeError, match="hold one body"):
        load_take(path, body=1)
    with pytest.raises(TakeError, match="whole number"):
        load_take(path, body=-1)


def test_kinectron_two_performers(data_dir, tmp_path):
    raw = json.loads((data_dir / "kinect_v2" / "recorded_skeleton.json").read_text())[:30]
    out = []
    for rec in raw:  # a second performer, 1 m along X, tracked from the 10th record on, listed first
        out.append(rec)
        if rec is not raw[0] and raw.index(rec) >= 10:
            other = {**rec, "trackingId": "999", "bodyIndex": 3,
                     "joints": [{**j, "cameraX": j["cameraX"] + 1.0} for j in rec["joints"]]}
            out.insert(len(out) - 1, other)
    (tmp_path / "two.json").write_text(json.dumps(out))
    a, b = kinectron_json.read(tmp_path / "two.json"), load_take(tmp_path / "two.json", body=1)
    assert a.frame_count == b.frame_count == 30 and body_count(a) == 2
    np.testing.assert_allclose(a.positions[:, 0, 0], [r["joints"][0]["cameraX"] for r in raw])
    assert np.all(b.states[:10] == NOT_TRACKED)
    np.testing.assert_allclose(b.positions[10:, 0, 0], [r["joints"][0]["cameraX"] + 1.0 for r in raw[10:]])
    # one performer whose id changes (reacquired): still one body, followed across the change
    single = [{**r, "trackingId": "7" if k < 15 else "8"} for k, r in enumerate(raw)]
    (tmp_path / "one.json").write_text(json.dumps(single))
    one = load_take(tmp_path / "one.json")
    assert body_count(one) == 1 and np.all(one.states[:, 0] != NOT_TRACKED)


def test_krtake_keeps_the_body_it_was(two_ntu, tmp_path):
    b = load_take(two_ntu, body=1)
    krtake.write(tmp_path / "b.krtake", b)
    back = load_take(tmp_path / "b.krtake")
    assert back.metadata["body"] == 1 and body_count(back) == 1
