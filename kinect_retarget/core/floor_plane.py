"""Which way is up for a figure in a take: the floor under its feet, checked against its head. Pure numpy.

Two estimates (issue 21), used by core/structure_mapping.py:

* **head over feet**: the mean direction from the ankles to the top of the head over the take. Right for a
  figure that stands for most of the take, wrong for one that lies down or bends over for most of it.
* **floor**: gravity from the feet's lowest points. Every foot node (ankle, toe, end site) in every frame is a
  candidate floor contact; a plane is fitted to the lower envelope of each node's points over the take, one
  height per node (the same for left and right), one shared slope; points above it (a lifted foot, a jump)
  are trimmed away and each place a node touches counts once, however long it rests there. Its normal is up,
  whatever the body does above the feet: a performer lying on the floor still has their heels on it.

How they combine: the floor wins when it is well determined: at least MIN_CONTACTS frames with a foot on it,
spread over MIN_SPREAD of the stature in both directions (a performer standing in one place gives a patch too
small to tell a tilt from foot roll), and a figure that stands up straight on it (within STANDS_DEG) in some
frames (a slanted plane through a dancer's feet on one spot is not believed). It is oriented so the body is
above it. Within LEVEL_DEG of a lab axis it is snapped to that axis (capture volumes are level; real level
takes measure 0-3 degrees of foot-roll noise), beyond that the capture volume is taken as tilted and the
floor's own normal is up. Without a usable floor, up is the lab axis nearest the head-over-feet direction.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

LEVEL_DEG = 5.0       # a floor normal this close to a lab axis is that axis (level real takes measure 0-3)
CONTACT_TOL = 0.02    # a contact more than this fraction of the stature above the floor is in the air
MIN_SPREAD = 0.12     # contacts must spread (std along their narrower direction) this fraction of the stature,
CELL = 0.05          # ... measured over the distinct cells of this fraction of the stature the feet touch
MIN_CONTACTS = 20     # and be at least this many frames
STANDS_DEG = 10.0     # a floor is believed only if the figure stands this straight on it in some frames (5 %)
LEANING_DEG = 30.0    # head-over-feet this far from the floor's normal: say that the figure lies or bends


@dataclass(frozen=True)
class UpEstimate:
    up: np.ndarray      # (3,) unit vector pointing up, in lab axes
    axis: int           # the lab axis nearest to it (0, 1, 2) ...
    sign: float         # ... and its direction
    how: str            # one line for reports: which estimate decided, and how well


@dataclass(frozen=True)
class FloorFit:
    normal: np.ndarray  # (3,) unit, pointing to the side the body is on
    contacts: int       # frames whose lowest foot point lies on the plane
    spread: float       # std of those points along their narrower direction on the plane, in stature units
    rms: float          # their distance from the plane, in stature units


def estimate_up(pos: np.ndarray, top: int, feet: tuple[tuple[int, ...], tuple[int, ...]]) -> UpEstimate:
    """Up for (F, N, 3) node positions: `top` is the top of the head, `feet` the nodes of each leg from the ankle
    down (ankle, toes, end sites)."""
    head = pos[:, top] - pos[:, [feet[0][0], feet[1][0]]].mean(axis=1)
    mean = head.mean(axis=0)
    stature = float(np.percentile(np.linalg.norm(head, axis=-1), 90))
    head_dir = mean / max(np.linalg.norm(mean), 1e-12)
    fit, why = fit_floor(pos, feet, head_dir, stature)
    if fit is not None:  # a floor the figure never stands up on is a foot-roll artefact, not the floor
        best = float(np.percentile(head @ fit.normal / np.maximum(np.linalg.norm(head, axis=-1), 1e-12), 95))
        if best < np.cos(np.radians(STANDS_DEG)):
            fit, why = None, (f"the figure never stands up on the floor fitted under its feet (at best "
                              f"{np.degrees(np.arccos(np.clip(best, -1, 1))):.0f} degrees off)")
    if fit is None:
        axis, sign = _nearest_axis(head_dir)
        how = f"head above the feet (no floor estimate: {why})"
        tilt = _angle(head_dir, np.eye(3)[axis] * sign)
        if tilt > LEANING_DEG:
            how += f"; head-over-feet direction is {tilt:.0f} degrees off the nearest axis"
        return UpEstimate(np.eye(3)[axis] * sign, axis, sign, how)
    axis, sign = _nearest_axis(fit.normal)
    axis_dir = np.eye(3)[axis] * sign
    tilt = _angle(fit.normal, axis_dir)
    where = f"floor under the feet ({fit.contacts} contacts, spread {fit.spread:.2f}, rms {fit.rms:.3f} of the stature)"
    if tilt <= LEVEL_DEG:
        up, how = axis_dir, f"{where}, level ({tilt:.1f} degrees from the axis)"
    else:
        up, how = fit.normal, f"{where}, tilted {tilt:.1f} degrees from the axis: the capture volume is not level"
    lean = _angle(head_dir, up)
    if lean > LEANING_DEG:
        how += f"; the head is {lean:.0f} degrees off above the feet on average (the figure lies or bends over)"
    return UpEstimate(up, axis, sign, how)


def fit_floor(pos: np.ndarray, feet, guess: np.ndarray, stature: float) -> tuple[FloorFit | None, str]:
    """The floor plane under the feet, or (None, why not). `feet`: each leg's nodes from the ankle down;
    `guess`: a rough up (unit) to start from.

    Every foot node (ankle, toes, end site) rests at its own height above the floor when planted, so the plane
    is fitted with one height per node (the same for the left and right node) and a shared slope: the ankle at
    the heel's height and the toe tip at the floor's do not pull it askew as the foot rolls, and a foot held
    up in the air is not a second floor."""
    if not stature > 0:
        return None, "the figure has no height"
    if pos.shape[0] < MIN_CONTACTS:
        return None, f"{pos.shape[0]} frame(s): too few to find the floor (at least {MIN_CONTACTS})"
    depth = min(len(feet[0]), len(feet[1]))
    nodes = list(feet[0][:depth]) + list(feet[1][:depth])
    pts = pos[:, nodes].reshape(-1, 3)
    node = np.tile(np.arange(len(nodes)) % depth, pos.shape[0])
    onehot = np.eye(depth)[node]
    feet = nodes
    n = guess
    for _ in range(8):  # refit in the axes of the last estimate (the first guess may be far off) until it settles
        last = n
        e1, e2 = _basis(n)
        xy, h = np.stack([pts @ e1, pts @ e2], axis=1), pts @ n
        cell = np.column_stack([np.round(xy / (CELL * stature)), node])
        keep = np.ones(len(h), dtype=bool)
        for _ in range(6):  # each node's lower envelope: trim points above it (a lifted foot), refit
            if keep.sum() < depth + 3:
                return None, "no frame has a foot on a common floor"
            # each place a foot node touches counts once, however long it rests there
            _, where, count = np.unique(cell[keep], axis=0, return_inverse=True, return_counts=True)
            w = 1.0 / np.sqrt(count[where.ravel()])
            coef = np.linalg.lstsq(np.column_stack([xy, onehot])[keep] * w[:, None], h[keep] * w, rcond=None)[0]
            r = h - np.column_stack([xy, onehot]) @ coef
            base = np.array([np.percentile(r[keep & (node == j)], 10) if np.any(keep & (node == j)) else 0.0
                             for j in range(depth)])
            keep = np.abs(r - base[node]) <= CONTACT_TOL * stature
        normal = n - coef[0] * e1 - coef[1] * e2
        n = normal / np.linalg.norm(normal)
        if n @ last > np.cos(np.radians(0.05)):
            break
    frames = len(np.unique(np.flatnonzero(keep) // len(feet)))
    if frames < MIN_CONTACTS:
        return None, f"{frames} frames with a foot on the floor (fewer than {MIN_CONTACTS})"
    # how far the contacts spread over the floor: over the distinct places the feet touch (cells of CELL of the
    # stature), not weighted by how long they stay there (a long rest in one place does not level a floor)
    e1, e2 = _basis(n)
    cells = np.unique(np.round(np.stack([pts[keep] @ e1, pts[keep] @ e2], axis=1) / (CELL * stature)), axis=0)
    cells -= cells.mean(axis=0)
    spread = float(np.sqrt(max(np.linalg.eigvalsh(cells.T @ cells / len(cells))[0], 0.0))) * CELL
    if spread < MIN_SPREAD:
        return None, f"the feet stay on a patch too small to level (spread {spread:.2f} of the stature)"
    # the body is above the floor: most of it, most of the time (lying, sitting or standing)
    above = float(np.mean(pos.mean(axis=1) @ n) - np.median(pts[keep] @ n))
    n = n if above >= 0 else -n
    rms = float(np.sqrt(np.mean((r - base[node])[keep] ** 2))) / stature
    return FloorFit(n, frames, spread, rms), ""


def _basis(n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    helper = np.eye(3)[int(np.argmin(np.abs(n)))]
    e1 = np.cross(n, helper)
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(n, e1)


def _nearest_axis(v: np.ndarray) -> tuple[int, float]:
    axis = int(np.argmax(np.abs(v)))
    return axis, float(np.sign(v[axis]) or 1.0)


def _angle(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.degrees(np.arccos(np.clip(a @ b / max(np.linalg.norm(a) * np.linalg.norm(b), 1e-12), -1, 1))))
