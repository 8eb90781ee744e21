"""What a BVH skeleton is: its Kinect v1 joints (by structure), which way is up, and its unit.

* joints: core/structure_mapping.py on the posed joints over the take (names only break ties);
* up: the floor under the feet's lowest points when they spread over it, else the lab axis along which the
  head stays furthest above the feet over the take (core/floor_plane.py; never the rest offsets, which
  exporters such as Rokoko or Bandai-Namco write along each bone's own X);
* unit: the one among metres, decimetres, CMU units, inches, centimetres and millimetres that makes the
  figure's height (standing_height) closest to 1.7 m; a CMU-named skeleton keeps CMU units when they give a
  plausible height. A figure still outside
  1.0-2.3 m after the guess is read with a warning that names its height.
"""
from __future__ import annotations

import numpy as np

from ..core.skeletons import KINECT_V1
from ..core.structure_mapping import StructureError, StructureMapping, map_structure
from ..core.take import TakeError
from . import bvh_names

UNITS = ((1.0, "metres"), (0.1, "decimetres"), (0.0254 / 0.45, "CMU units (1/0.45 inch)"), (0.0254, "inches"),
         (0.01, "centimetres"), (0.001, "millimetres"))
NOMINAL_HEIGHT = 1.7         # metres: the height a unit guess aims for
HEIGHT_RANGE = (1.0, 2.3)    # metres: outside this the bake warns
MAPPING_FRAMES = 400         # frames (evenly spread over the take) the structural mapping looks at
HAND_REACH = 0.3             # wrist -> hand centre as a fraction of the forearm, for skeletons without hands
FOOT_REACH = 0.25            # ankle -> toe base as a fraction of the shin, for skeletons without feet


def map_figure(path: str, names, parents, rest, positions, ends) -> StructureMapping:
    """The structural mapping, or TakeError saying why the skeleton is not a humanoid."""
    good = np.flatnonzero(np.all(np.isfinite(positions), axis=(1, 2)))  # frames a NaN channel spared
    if good.size == 0:
        raise TakeError(f"{path}: no frame without NaN or infinite channel values: cannot tell the figure's shape")
    pick = good[np.unique(np.linspace(0, good.size - 1, min(MAPPING_FRAMES, good.size)).astype(int))]
    try:
        return map_structure(names, parents, rest, positions[pick], ends)
    except StructureError as exc:
        shown = ", ".join(n for n, e in zip(names[:14], ends[:14]) if not e)
        raise TakeError(f"{path}: BVH skeleton not recognised as a humanoid: {exc} "
                        f"(its joints: {shown}...)") from None


def standing_height(positions: np.ndarray, structure: StructureMapping, parents: np.ndarray) -> float:
    """The figure's height in file units: the taller of how tall it stands over the take (top of the head above
    the lowest foot point, 90th percentile) and its bone chain from the top of the head down the spine and a
    leg to the ankle, stretched out (so a take that only crouches, sits or lies is not taken for a child)."""
    up = structure.up
    top = positions[:, structure.top] @ up
    low = (positions[:, list(structure.feet)] @ up).min(axis=1)
    posed = float(np.nanpercentile(top - low, 90))

    def bone(a: int, b: int) -> float:
        return float(np.nanmedian(np.linalg.norm(positions[:, a] - positions[:, b], axis=-1)))

    pelvis, j, chain = structure.roles["HipCenter"].node, structure.top, 0.0
    while j != pelvis and parents[j] >= 0:
        chain, j = chain + bone(j, parents[j]), int(parents[j])
    node = {r: m.node for r, m in structure.roles.items() if m.node is not None}
    legs = [bone(node[f"Hip{s}"], node[f"Knee{s}"]) + bone(node[f"Knee{s}"], node[f"Ankle{s}"])
            for s in ("Left", "Right")]
    return max(posed, chain + float(np.mean(legs)))


def choose_unit(height_units: float, family: str | None, scale: float | None, path: str) -> tuple[float, str]:
    """(metres per file unit, how it was chosen)."""
    if scale is not None:
        if not (np.isfinite(scale) and scale > 0):
            raise TakeError(f"{path}: scale must be a positive number of metres per unit, got {scale}")
        return float(scale), f"{scale:g} m per unit (given)"
    if not height_units > 0:
        return 1.0, "metres (assumed: the figure has no height)"
    known = bvh_names.FAMILY_UNITS.get(family) if family is not None else None
    if known and HEIGHT_RANGE[0] <= height_units * known <= HEIGHT_RANGE[1]:
        name = dict(UNITS).get(known, f"{known:g} m per unit")
        return known, f"{name} ({family} joint names)"
    s, name = min(UNITS, key=lambda u: abs(np.log(height_units * u[0] / NOMINAL_HEIGHT)))
    return s, f"{name} (guessed from the standing height, {height_units:.4g} units)"


def height_warning(height_m: float, unit_how: str) -> str | None:
    if HEIGHT_RANGE[0] <= height_m <= HEIGHT_RANGE[1]:
        return None
    return (f"the figure is {height_m:.2f} m tall with the unit {unit_how}: outside "
            f"{HEIGHT_RANGE[0]:g}-{HEIGHT_RANGE[1]:g} m; pass --scale (metres per file unit) to fix it")


def kinect_joints(positions: np.ndarray, structure: StructureMapping) -> tuple[np.ndarray, np.ndarray]:
    """(F, 20, 3) Kinect v1 joints in lab axes and file units, and (20,) True for joints the skeleton lacks
    (hands, feet), which are extrapolated: the hand along the forearm, the foot forward from the ankle."""
    k = KINECT_V1.index
    out = np.empty((positions.shape[0], len(KINECT_V1), 3))
    missing = np.zeros(len(KINECT_V1), dtype=bool)
    for role, match in structure.roles.items():
        if match.average:
            out[:, k(role)] = positions[:, list(match.average)].mean(axis=1)
        else:
            missing[k(role)] = True
    up = structure.up
    left = out[:, k("HipLeft")] - out[:, k("HipRight")]
    forward = np.cross(left - (left @ up)[:, None] * up, up)
    forward /= np.maximum(np.linalg.norm(forward, axis=-1, keepdims=True), 1e-12)
    for side in ("Left", "Right"):
        if missing[k("Hand" + side)]:
            wrist, elbow = out[:, k("Wrist" + side)], out[:, k("Elbow" + side)]
            out[:, k("Hand" + side)] = wrist + HAND_REACH * (wrist - elbow)
        if missing[k("Foot" + side)]:
            ankle, knee = out[:, k("Ankle" + side)], out[:, k("Knee" + side)]
            shin = np.linalg.norm(ankle - knee, axis=-1, keepdims=True)
            out[:, k("Foot" + side)] = ankle + FOOT_REACH * shin * (forward - 0.4 * up)
    return out, missing
