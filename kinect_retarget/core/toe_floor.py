"""Toes at or above the floor (issue 16): when a foot points down more steeply than the rig's rest foot allows,
its tip (the foot bone's tail, and the tails of the toe bones in front of the ankle) would dip under the floor.
The foot then pitches up about the ankle by the smallest angle that lifts every tip onto the floor; the angle
eases in and out over a few frames (each frame takes the largest nearby need, scaled by a smoothstep of its
distance), so nothing pops, and frames far from a dip are left alone. Turning about the ankle moves no ankle, so
planted feet stay pinned. Pure numpy: the caller applies the returned rotations to the foot.
"""
from __future__ import annotations

import numpy as np


def tip_bones(rig, foot: int) -> list[int]:
    """The foot bone and those of its descendants whose rest tail lies in front of the ankle (toes, not heels)."""
    ankle = rig.heads[foot]
    fwd = rig.tails[foot] - ankle
    out = [foot]
    for b in range(len(rig.bone_names)):
        if foot in rig.ancestors(b) and float((rig.tails[b] - ankle) @ fwd) > 0:
            out.append(b)
    return out


def tips(rig, posed: np.ndarray, bones: list[int]) -> np.ndarray:
    """(F, K, 3) posed tails of `bones`."""
    sel = posed[:, bones]
    return sel[..., :3, 3] + sel[..., :3, 1] * rig.lengths[bones][None, :, None]


def rest_pitch_axis(rig, foot: int, up: np.ndarray) -> np.ndarray:
    """The foot's across axis in its own (bone) coordinates: horizontal and square to the rest foot's forward
    direction, so that turning by +angle about it raises the toes. Carried by the posed foot, it stays defined
    when the foot points straight down (where "the horizontal across the foot's direction" is not)."""
    fwd = rig.tails[foot] - rig.heads[foot]
    fwd = fwd - (fwd @ up) * up
    axis = np.cross(fwd, up) if np.linalg.norm(fwd) > 1e-9 else rig.rest[foot, :3, 0]
    return rig.rest[foot, :3, :3].T @ (axis / np.linalg.norm(axis))


def pitch_axes(foot_matrices: np.ndarray, local_axis: np.ndarray, up: np.ndarray) -> np.ndarray:
    """(F, 3) unit axes a foot pitches up about: its across axis (rest_pitch_axis) as posed, made horizontal,
    and turned round where the foot clearly points forward (less than ~75 degrees from level) but that axis
    would lower its tip (a foot rolled over in the take)."""
    axis = foot_matrices[:, :3, :3] @ local_axis
    axis -= np.outer(axis @ up, up)
    y = foot_matrices[:, :3, 1]
    rolled = np.linalg.norm(axis, axis=-1) < 1e-6       # a foot rolled onto its side: across its own direction
    axis[rolled] = np.cross(y[rolled], up)
    level = np.linalg.norm(y - np.outer(y @ up, up), axis=-1) >= 0.25
    lowers = np.cross(axis, y) @ up < 0
    axis[level & lowers] *= -1
    return axis / np.linalg.norm(axis, axis=-1, keepdims=True)


def needed_pitch(ankle: np.ndarray, tip: np.ndarray, axis: np.ndarray, up: np.ndarray, floor: float) -> np.ndarray:
    """(F,) smallest turn up (rad, >= 0) about `axis` through the ankle that puts every tip (F, K, 3) at or
    above the floor. A tip's height after turning by t is base + b cos t + c sin t (Rodrigues): it is at or
    above the floor on an arc of turns, which it enters at a closed-form angle; the answer is the first of 0
    and those entry angles at which every tip is up. Always turning up (never the other way, even for a foot
    kicked back past pointing straight down) keeps the turn continuous from frame to frame."""
    b, c, need = _arcs(ankle, tip, axis, up, floor)
    dips = (b < need - 1e-7).any(axis=1)
    reach = np.arccos(np.clip(need / np.maximum(np.hypot(b, c), 1e-12), -1.0, 1.0))
    enter = np.mod(np.arctan2(c, b) - reach, 2 * np.pi) + 1e-9    # where each tip's arc starts, turning up
    cand = np.concatenate([np.zeros((len(b), 1)), enter], axis=1)  # (F, C)
    height = b[:, None] * np.cos(cand)[..., None] + c[:, None] * np.sin(cand)[..., None] - need[:, None]
    low = height.min(axis=-1)                                # (F, C) the lowest tip over the floor at each turn
    up_all = low >= -1e-9
    first = np.where(up_all, cand, np.inf).min(axis=1)
    best = np.take_along_axis(cand, low.argmax(axis=1)[:, None], axis=1)[:, 0]  # unreachable: the highest
    return np.where(dips, np.where(np.isfinite(first), first, best), 0.0)


def _arcs(ankle, tip, axis, up, floor):
    """Each tip's height over the floor after turning by t about `axis` through the ankle is
    b cos t + c sin t - need (Rodrigues): (b, c, need), each (F, K)."""
    r = tip - ankle[:, None]
    a = axis[:, None]
    along = np.sum(r * a, -1, keepdims=True) * a
    perp = r - along
    return perp @ up, np.cross(a, perp) @ up, floor - ((ankle @ up)[:, None] + along @ up)


def pitch_room(ankle, tip, axis, up, floor, start: np.ndarray) -> np.ndarray:
    """(F,) the largest turn up from `start` (F,) (where every tip is at or above the floor) through which they
    all stay there: where an ease may turn the foot to without sinking a toe it did not need to lift."""
    b, c, need = _arcs(ankle, tip, axis, up, floor)
    reach = np.arccos(np.clip(need / np.maximum(np.hypot(b, c), 1e-12), -1.0, 1.0))
    leave = np.arctan2(c, b) + reach - 1e-9                # where each tip's arc ends, turning up
    room = start[:, None] + np.mod(leave - start[:, None], 2 * np.pi)
    return np.where(reach >= np.pi, np.inf, room).min(axis=1, initial=np.inf)


def eased(angle: np.ndarray, ramp: int) -> np.ndarray:
    """(F,) turns at least `angle` (>= 0) everywhere, easing to 0 over `ramp` frames before and after each need:
    each frame takes the largest need within the ramp, scaled by a smoothstep of the distance."""
    out = angle.copy()
    n = len(angle)
    for k in range(1, ramp + 1):
        x = 1 - k / (ramp + 1)
        w = x * x * (3 - 2 * x)
        out[k:] = np.maximum(out[k:], w * angle[:n - k])
        out[:n - k] = np.maximum(out[:n - k], w * angle[k:])
    return out


def axis_angle_quats(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """(F, 4) quaternions (w, x, y, z) turning by angle (F,) about unit axis (F, 3)."""
    h = angle[:, None] / 2
    return np.concatenate([np.cos(h), np.sin(h) * axis], axis=-1)
