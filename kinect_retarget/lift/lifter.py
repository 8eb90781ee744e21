"""2D joint tracks -> a 3D take (paper 004 §3.2, with the extensions described in docs/lifting.md).

1. short gaps filled in 2D; 2. per-frame scale (scale.py); 3. each bone's depth magnitude
dz = sqrt(L^2 - d^2 / s^2); 4. the depth signs over the whole take (signs.py); 5. joints placed along the
tree from the pelvis: on the joint's image ray (perspective, when the focal length is known) or on its
orthographic line, at the bone's length from its parent; joints never seen are placed by a default
direction and marked inferred.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..core.conventions import depth_pixel_to_kinect
from ..core.skeletons import INFERRED, KINECT_V1, NOT_TRACKED, TRACKED, topological_order
from ..core.take import Take, nominal_rate
from .bone_depth import jitter_px
from .bones import DEFAULT_HEIGHT_M, lengths_from_height
from .gaps import fill_gaps
from .geometry import JointLines
from .paper_lift import METHODS, continuity_signs, paper_settings
from .scale import SCALE_BONES, fill_missing, scale_envelope, scale_lower_bound, scale_paper, smooth_lengths
from .signs import SignPriors, choose_signs
from .smoothing import gaussian_kernel, gaussian_smooth
from .tracks2d import LiftError, Tracks2D
from .video_camera import Camera

SK = KINECT_V1
PARENTS = SK.parent_array


def _shallow_first_order() -> np.ndarray:
    """Parents before children, shallow joints first (both hips are placed before a foot needs "forward")."""
    depth = np.zeros(len(SK), dtype=np.int64)
    for j in topological_order(SK)[1:]:
        depth[j] = depth[PARENTS[j]] + 1
    return np.argsort(depth, kind="stable")


ORDER = _shallow_first_order()


@dataclass
class LiftSettings:
    """height_m sets anthropometric bone lengths unless `lengths` (J,) are given (calibrated, metres).
    focal_px: the camera's focal length in pixels; None means unknown (scaled orthographic model).
    image_size: (W, H) overriding the tracks' own. scale: "envelope" or "paper" (eq. 3). signs: "viterbi",
    "greedy" or "camera" (signs.py), or "continuity" (paper_lift.py). max_gap_s: longest 2D gap filled by
    interpolation. method "paper" runs paper 004 as published (paper_lift.py), overriding the camera,
    scale, signs and every smoothing below; "ours" (default) uses them as set."""

    method: str = "ours"

    height_m: float = DEFAULT_HEIGHT_M
    lengths: np.ndarray | None = None
    focal_px: float | None = None
    image_size: tuple[float, float] | None = None
    principal_point: tuple[float, float] | None = None  # pixels; default the image centre
    scale: str = "envelope"
    scale_window_s: float = 1.0
    scale_quantile: float = 0.8
    signs: str = "viterbi"
    priors: SignPriors = field(default_factory=SignPriors)
    max_gap_s: float = 0.5
    smooth_2d_s: float = 0.05
    smooth_depth_s: float = 0.08
    noise_aware: bool = True
    noise_px: float | None = None  # 2D noise (std, px); None: measured from the tracks' jitter
    min_confidence: float = 0.05


@dataclass
class LiftResult:
    take: Take
    scale: np.ndarray          # (F,) pixels per metre
    signs: np.ndarray          # (F, J) depth sign of each bone (by child joint)
    camera: Camera
    problems: list[str]


def lift(tracks: Tracks2D, settings: LiftSettings | None = None, *, scale: np.ndarray | None = None,
         signs: np.ndarray | None = None) -> LiftResult:
    """Lift 2D tracks to a Kinect v1 take in the video camera's space (Kinect camera-space axes).

    scale (F,) px/m and signs (F, J) override the estimates (evaluation with known ground truth)."""
    st = settings or LiftSettings()
    if st.method not in METHODS:
        raise LiftError(f"unknown lifting method {st.method!r} ({', '.join(METHODS)})")
    if st.method == "paper":
        st = paper_settings(st)
    if st.scale not in ("paper", "envelope"):
        raise LiftError(f"unknown scale method {st.scale!r} (envelope, paper)")
    problems = list(tracks.problems)
    lengths = lengths_from_height(st.height_m) if st.lengths is None else np.asarray(st.lengths, dtype=float)
    if lengths.shape != (len(SK),) or np.any(lengths[PARENTS >= 0] <= 0):
        raise LiftError(f"bone lengths must be {len(SK)} positive values (one per joint, root 0)")
    cam = _camera(tracks, st, problems)
    present = tracks.confidence >= st.min_confidence
    uv, filled = fill_gaps(tracks.uv, present, tracks.times, st.max_gap_s)
    have = present | filled
    noise_px = jitter_px(uv, present & ~filled) if st.noise_px is None else st.noise_px
    uv = gaussian_smooth(uv, have[..., None], tracks.times, st.smooth_2d_s)
    sigma_px = noise_px * _smoothing_gain(tracks.times, st.smooth_2d_s) if st.noise_aware else 0.0
    body = have[:, SK.root]
    if not body.any():
        raise LiftError(f"{tracks.source}: the hips (HipCenter, or both hips) are never visible: the body "
                        f"cannot be placed")
    for i in np.flatnonzero(~body & have.any(axis=1)):
        problems.append(f"{tracks.source}: {tracks.frame_label(i)}: hips not visible, frame left untracked")
    measured = present & ~tracks.inferred

    # Orthographic image coordinates in Kinect axes (pixels, relative to the principal point).
    unit = np.ones(uv.shape[:-1])   # unit depth and focal: pixel offsets in Kinect axes
    xy = depth_pixel_to_kinect(uv[..., 0], uv[..., 1], unit, 1.0, cam.cx, cam.cy)[..., :2]
    d_vec = xy - xy[:, np.maximum(PARENTS, 0)]
    s = _scale(tracks, st, d_vec, measured, body, lengths) if scale is None else np.asarray(scale, float)

    z_root = cam.focal_px / s
    lines = JointLines.build(uv, cam, z_root, st.focal_px is not None, sigma_px)
    r = SK.root
    root = lines.origin[:, r] + lines.direction[:, r] * (z_root / lines.direction[:, r, 2])[:, None]
    if signs is None and st.signs == "continuity":
        signs = continuity_signs(lines, lengths, root, body, ORDER)
    elif signs is None:
        travel = _travel_direction(root, tracks.times, body)
        signs = choose_signs(lines, lengths, root, tracks.times, body, travel, st.priors, st.signs)
    positions = _place_joints(lines, root, have, body, signs, lengths, tracks.times, st.smooth_depth_s)
    states = np.where(measured & ~filled, TRACKED, INFERRED).astype(np.uint8)
    states[~body] = NOT_TRACKED
    positions[~body] = np.nan
    meta = {"lifted_from": tracks.source, "focal_px": cam.focal_px, "focal_known": cam.focal_known,
            "method": st.method, "scale_method": st.scale, "sign_method": st.signs, "noise_px": round(noise_px, 3),
            "problems": len(problems)}
    take = Take(SK, positions, states, tracks.times, nominal_rate(tracks.times), "lift", meta)
    return LiftResult(take, s, signs, cam, problems)


def _scale(tracks, st: LiftSettings, d_vec, measured, body, lengths) -> np.ndarray:
    """Per-frame s (px/m) from the long bones measured in both ends (eq. 2, then eq. 3 or the envelope)."""
    idx = np.array([SK.index(n) for n in SCALE_BONES])
    d_px = np.linalg.norm(d_vec[:, idx], axis=-1)
    usable = measured[:, idx] & measured[:, PARENTS[idx]] & body[:, None]
    s_min = fill_missing(scale_lower_bound(d_px, lengths[idx], usable), tracks.source or "2D tracks")
    if st.scale == "paper":
        return scale_paper(d_px * usable, lengths[idx], s_min)
    ratios = np.where(usable, smooth_lengths(d_px, usable) / lengths[idx], np.nan)
    return scale_envelope(ratios, tracks.times, st.scale_window_s, st.scale_quantile)


def _smoothing_gain(times: np.ndarray, sigma_s: float) -> float:
    """Factor by which gaussian_smooth reduces white noise (the kernel's L2 norm)."""
    if len(times) < 3 or sigma_s <= 0:
        return 1.0
    k = gaussian_kernel(times, sigma_s)
    if k is None:
        return 1.0
    return float(np.sqrt(np.sum((k / k.sum()) ** 2)))


def _camera(tracks: Tracks2D, st: LiftSettings, problems: list[str]) -> Camera:
    size = st.image_size or tracks.image_size
    if size is None:
        ok = tracks.present
        if not ok.any():
            raise LiftError(f"{tracks.source}: no joint is visible in any frame")
        pts = tracks.uv[ok]
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        size = tuple(float(v) for v in (lo + hi))  # centred on the keypoints' bounding box
        problems.append(f"{tracks.source}: image size unknown; assuming the principal point at the "
                        f"keypoints' centre ({size[0] / 2:.0f}, {size[1] / 2:.0f}) px (use --image-size)")
    w, h = float(size[0]), float(size[1])
    if not (w > 0 and h > 0):
        raise LiftError(f"image size must be positive, got {w} x {h}")
    if st.focal_px is not None and not st.focal_px > 0:
        raise LiftError(f"focal length must be positive, got {st.focal_px}")
    cam = Camera.for_image(w, h, st.focal_px)
    if st.principal_point is not None:
        cam = Camera(cam.focal_px, float(st.principal_point[0]), float(st.principal_point[1]), cam.focal_known)
    return cam


def _travel_direction(root: np.ndarray, times: np.ndarray, body: np.ndarray):
    """(F, 3) horizontal direction of the body's travel, weighted 0..1 by speed (0 when standing)."""
    f = len(times)
    if f < 3:
        return np.zeros((f, 3))
    p = root.copy()
    p[:, 1] = 0.0
    p = gaussian_smooth(p, body[:, None], times, 0.25)
    v = np.gradient(p, times, axis=0)
    v[~body] = 0.0
    speed = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.maximum(speed, 1e-9) * np.clip((speed - 0.2) / 0.5, 0.0, 1.0)


# Directions (Kinect axes, facing the camera) for joints never seen: limbs hang, the trunk stands.
_DOWN, _UP = np.array([0.0, -1.0, 0.0]), np.array([0.0, 1.0, 0.0])
_DEFAULT_DIR = {name: _DOWN for name in SK.joints}
_DEFAULT_DIR.update({"Spine": _UP, "ShoulderCenter": _UP, "Head": _UP,
                     "ShoulderLeft": np.array([-1.0, 0, 0]), "ShoulderRight": np.array([1.0, 0, 0]),
                     "HipLeft": np.array([-0.9, -0.45, 0]), "HipRight": np.array([0.9, -0.45, 0])})


def _place_joints(lines: JointLines, root, have, body, signs, lengths, times, smooth_s: float) -> np.ndarray:
    """Walk the tree from the pelvis, putting each joint on its line at its bone's length from the parent,
    on the chosen side, so it reprojects onto its 2D track. The signed offset along the line is smoothed
    over time (it is the noisy part). Joints never seen hang from their parent in a default direction."""
    f = root.shape[0]
    pos = np.full((f, len(SK), 3), np.nan)
    pos[:, SK.root] = root
    fwd = None
    for j in ORDER[1:]:
        parent = pos[:, PARENTS[j]]
        foot, along, u = lines.offsets(j, parent, lengths[j])
        along = gaussian_smooth(signs[:, j] * along, have[:, j] & body, times, smooth_s)
        if fwd is None and SK.joints[j].startswith("Foot"):
            fwd = _forward(pos)
        guessed = parent + lengths[j] * _default_direction(SK.joints[j], pos, PARENTS[j], fwd)
        pos[:, j] = np.where(have[:, j, None], foot + along[:, None] * u, guessed)
    return pos


def _forward(pos: np.ndarray) -> np.ndarray:
    left = pos[:, SK.index("HipLeft")] - pos[:, SK.index("HipRight")]
    fwd = np.cross(left, _UP)
    return fwd / np.maximum(np.linalg.norm(fwd, axis=1, keepdims=True), 1e-9)


def _default_direction(name: str, pos: np.ndarray, parent: int, fwd) -> np.ndarray:
    if name.startswith("Foot") and fwd is not None:
        d = 0.94 * fwd - 0.34 * _UP
    elif name.startswith("Hand"):  # continue the forearm
        d = pos[:, parent] - pos[:, PARENTS[parent]]
    else:
        d = np.broadcast_to(_DEFAULT_DIR[name], pos[:, parent].shape)
    d = np.nan_to_num(d)
    n = np.linalg.norm(d, axis=1, keepdims=True)
    return np.where(n > 1e-9, d / np.maximum(n, 1e-9), _DOWN)
