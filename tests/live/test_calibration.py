import numpy as np
import pytest

from kinect_retarget.core.skeletons import KINECT_V2, NOT_TRACKED
from kinect_retarget.core.performer_calibration import Calibration, CalibrationError, calibrate
from kinect_retarget.live.session import LiveSession
from kinect_retarget.sources import TakePlayback


def standing(wave_take, n=30):
    """The first second of the wave take: the performer stands with arms down."""
    return wave_take.positions[:n], wave_take.states[:n]


def test_calibration_measures_legs_and_root_scale(wave_take):
    pos, st = standing(wave_take)
    cal = calibrate(KINECT_V2, pos, st, target_leg=0.9)
    k = KINECT_V2.index
    p = np.median(pos, axis=0)
    expect_leg = np.mean([np.linalg.norm(p[k(f"Knee{s}")] - p[k(f"Hip{s}")]) +
                          np.linalg.norm(p[k(f"Ankle{s}")] - p[k(f"Knee{s}")]) for s in ("Left", "Right")])
    assert cal.source_leg == pytest.approx(expect_leg, rel=0.02)
    assert 0.5 < cal.source_leg < 1.2  # a human leg
    assert cal.root_scale == pytest.approx(0.9 / cal.source_leg)
    np.testing.assert_allclose(cal.root_reference, p[0], atol=0.02)
    assert cal.pose in ("T-pose", "A-pose", "arms down")
    assert calibrate(KINECT_V2, pos, st, target_leg=0.9, generated_rig=True).root_scale == 1.0


def test_calibration_round_trips_through_json(wave_take):
    cal = calibrate(KINECT_V2, *standing(wave_take), target_leg=1.0)
    back = Calibration.from_json(cal.to_json())
    assert back == cal
    with pytest.raises(CalibrationError):
        Calibration.from_json('{"version": 1, "skeleton": "kinect_v2", "root_scale": -1}')
    with pytest.raises(CalibrationError):
        Calibration.from_json("not json")


def test_calibration_rejects_a_moving_performer(wave_take):
    pos, st = standing(wave_take)
    pos = pos.copy()
    pos[:, :, 0] += np.linspace(0, 0.5, len(pos))[:, None]  # walks half a metre sideways
    with pytest.raises(CalibrationError, match="moved"):
        calibrate(KINECT_V2, pos, st)


def test_calibration_needs_the_legs_in_view(wave_take):
    pos, st = standing(wave_take)
    st = st.copy()
    st[:, KINECT_V2.index("KneeLeft")] = NOT_TRACKED
    with pytest.raises(CalibrationError, match="legs"):
        calibrate(KINECT_V2, pos, st)


def test_session_calibration_collects_a_window(wave_take, stand_in):
    got = []
    s = LiveSession(TakePlayback(wave_take, speed=4.0), stand_in, lambda p: None)
    s.start()
    s.start_calibration(got.append, duration=0.2)
    while s.pump() and not got:
        pass
    s.stop()
    assert len(got) == 1 and not s.calibrating
    cap = got[0]
    assert len(cap.positions) >= 0.2 * 4 * 30 - 2
    assert cap.result(KINECT_V2, 0.9, False).source_leg > 0.5
