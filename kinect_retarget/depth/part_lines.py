"""The torso's left-right line from the forest's body parts, which the torso frame turns to (numpy only).

The facing is read from the line between the forest's shoulder parts where it sees both, else from the
chest's surface normals (facing.py). On real depth (UTD-MHAD subjects 1-2) the shoulders' line lay 4.6
degrees of yaw from the SDK's shoulders (median 2.3), the normals 12.1 (7.2): arms held before the chest tilt
the normals, and Kinect v1's depth steps make flat patches facing the sensor (a fifth to two fifths of a turned
chest's cells), so turns of 52-72 degrees read as none. A shoulder part is small too: an arm raised before its
shoulder (a bat held at it) carries the part onto the arm, at the arm's depth, and the line reads the
performer as facing the sensor.

So both readings are checked against a third, the line between the centres of the upper torso's two quarters
(torso_upper_right -> torso_upper_left): large parts on the chest itself, which read a turn surely but not all
of it (their centres lie on the surface the sensor sees, whose near side shows more of itself: 25 of 43
degrees on a rendered performer). Where the quarters read a turn and the reading lies well on its frontal side
or mirrored (checked_by_torso), the quarters' facing is taken; a reading turned further is kept.

Measured on all 216 UTD-MHAD sequences (what `track` writes, yaw of the shoulders against the SDK's, mean over
the 27 actions): 3.8 -> 3.5 degrees (right arm swipe left 10.0 -> 6.8, baseball swing 15.7 -> 14.2); limb
directions 8.71 -> 8.55 degrees. The normals' closer check (NORMALS_AGREE_DEG) was chosen on subjects 1-2:
the quarters' facing taken wherever the normals read less of its turn or its mirror made subjects 1-2 7.83
degrees against 7.89, but on rendered depth, whose normals read a turn exactly, a walk's right hand went
wrong for 30 frames (4.1 -> 4.6 cm).
"""
from __future__ import annotations

import numpy as np

from ..core.skeletons import KINECT_V1
from .body_parts import PART
from .part_fit import USE_CONFIDENCE
from .part_proposals import PROB_MIN
from .two_bone import unit

SHOULDER_LINE = True
SHOULDER_LINE_CONFIDENCE = USE_CONFIDENCE   # square metres of likely part around each shoulder's proposal
SHOULDER_LINE_SPAN = (0.2, 0.55)    # m between the two proposals: a shoulder line, not a confused part
TORSO_LINE = True
TORSO_LINE_MASS = 0.002     # square metres of likely part each upper quarter needs (10-40 cm² measured alike)
LINE_AGREE_DEG = 20.0       # degrees of yaw: the torso's turn beyond which it checks the shoulders' line, and by
                            # how much that line may read less of it
NORMALS_AGREE_DEG = 5.0     # ... the same for the chest's normals (on real depth the worse reading)
UPPER_QUARTERS = (PART["torso_upper_left"], PART["torso_upper_right"])


def shoulder_line(proposals) -> np.ndarray | None:
    """Right shoulder -> left shoulder of the forest's shoulder parts, where it sees both and they lie a
    shoulder width apart; else None."""
    if not SHOULDER_LINE or proposals is None:
        return None
    left, right = KINECT_V1.index("ShoulderLeft"), KINECT_V1.index("ShoulderRight")
    if min(proposals.confidence[left], proposals.confidence[right]) < SHOULDER_LINE_CONFIDENCE:
        return None
    line = proposals.positions[left] - proposals.positions[right]
    return line if SHOULDER_LINE_SPAN[0] < np.linalg.norm(line) < SHOULDER_LINE_SPAN[1] else None


def torso_line(proposals) -> np.ndarray | None:
    """Centre of the upper torso's right quarter -> its left quarter's (each cell weighted, as the proposals'
    votes are, by its probability times the area it stands for), where the forest sees both quarters; else
    None."""
    if not TORSO_LINE or proposals is None or not len(proposals.probs):
        return None
    centres = []
    for part in UPPER_QUARTERS:
        p = proposals.probs[:, part]
        w = np.where(p > PROB_MIN, p, 0.0) * proposals.areas
        if w.sum() < TORSO_LINE_MASS:
            return None
        centres.append(w @ proposals.points / w.sum())
    return centres[0] - centres[1]


def line_facing(line: np.ndarray | None, axis: np.ndarray, toward: np.ndarray) -> np.ndarray | None:
    """The facing (across `axis`) square to a right -> left `line`, or None without one or where it would face
    away from the sensor (`toward`): the performer is taken to face it, as with the chest's normals."""
    if line is None:
        return None
    square = np.cross(line, axis)   # across the axis, whatever the line's tilt along it
    if np.linalg.norm(square) < 1e-6:
        return None
    facing = unit(square)
    return facing if facing @ toward > 0 else None


def checked_by_torso(reading: np.ndarray | None, torso: np.ndarray | None, axis: np.ndarray,
                     toward: np.ndarray, agree_deg: float = LINE_AGREE_DEG) -> np.ndarray | None:
    """The facing read from the shoulders' line or the chest's normals, unless the torso quarters' facing
    (`torso`; all across `axis`) reads a turn from the sensor (`toward`) of more than `agree_deg` and the
    reading lies more than that on its frontal side (or beyond it, the mirror image): then the torso's. The
    quarters' centres lie on the surface the sensor sees and read less than the whole turn (25 of 43 degrees
    on a rendered performer), so a reading turned further is kept."""
    if torso is None:
        return reading
    if reading is None:
        return torso
    t = _signed_turn_deg(torso, axis, toward)
    short = np.sign(t) * (t - _signed_turn_deg(reading, axis, toward))
    return torso if abs(t) > agree_deg and short > agree_deg else reading


def _signed_turn_deg(facing: np.ndarray, axis: np.ndarray, toward: np.ndarray) -> float:
    """Degrees a facing is turned from the sensor's direction about `axis`, signed by the way it turns."""
    return float(np.degrees(np.arctan2(np.cross(toward, facing) @ axis, toward @ facing)))
