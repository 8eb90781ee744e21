"""A facing reading that jumps in one frame is not believed (skeleton_fit.next_lateral)."""
import numpy as np

from kinect_retarget.depth.skeleton_fit import LATERAL_SMOOTHING, TURN_CREEP_DEG, next_lateral

AXIS = np.array([0.0, 1.0, 0.0])
TOWARD = np.array([0.0, 0.0, -1.0])   # from the performer to the sensor


def lateral(facing_deg: float) -> np.ndarray:
    """The left-right direction of a performer turned facing_deg from the sensor."""
    a = np.radians(facing_deg)
    facing = np.array([np.sin(a), 0.0, -np.cos(a)])
    return np.cross(AXIS, facing)


def turned_deg(lat: np.ndarray) -> float:
    return float(np.degrees(np.arccos(np.clip(np.cross(lat, AXIS) @ TOWARD, -1, 1))))


def test_a_jump_from_facing_only_creeps():
    out = next_lateral(lateral(57.0), lateral(4.0), AXIS, TOWARD)
    assert abs(turned_deg(out) - (4.0 + TURN_CREEP_DEG)) < 0.5


def test_a_gradual_turn_is_followed():
    out = next_lateral(lateral(15.0), lateral(4.0), AXIS, TOWARD)
    blended = LATERAL_SMOOTHING * 4.0 + (1 - LATERAL_SMOOTHING) * 15.0   # with the last frame, as before
    assert abs(turned_deg(out) - blended) < 1.0


def test_once_turned_a_jump_is_taken():
    blended = LATERAL_SMOOTHING * 30.0 + (1 - LATERAL_SMOOTHING) * 60.0
    assert abs(turned_deg(next_lateral(lateral(60.0), lateral(30.0), AXIS, TOWARD)) - blended) < 1.0
    mirrored = next_lateral(lateral(-70.0), lateral(70.0), AXIS, TOWARD)   # the mirror image flipping over
    assert abs(turned_deg(mirrored) - 70.0) < 0.5
