"""Render Kinect v1 depth images of a skinned body in a simple room, with the sensor's artefacts.

Surfaces are sampled densely (bilinear points per skin quad, enough for one sample per pixel at the
nearest distance) and z-buffered by sorting; the room (floor, back wall, optional boxes) is ray-cast
analytically. Artefacts: the projector's shadow (points the projector cannot see have no reading),
dropouts along silhouette edges, disparity noise and 11-bit quantisation.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..core.conventions import depth_pixel_to_kinect, kinect_to_depth_pixel
from ..device.depth_unpack import NO_READING_RAW
from ..depth.depth_camera import DepthCamera, metres_to_raw


@dataclass
class Room:
    floor_y: float = -0.9           # floor height in camera space (camera ~0.9 m above the floor)
    back_wall_z: float = 4.6
    boxes: list = field(default_factory=list)  # [(min xyz, max xyz)] axis-aligned furniture


def quad_sampler(rest_vertices: np.ndarray, quads: np.ndarray, min_distance: float, cam: DepthCamera):
    """Per-quad bilinear sample weights, grouped by density: [(quad indices, weights (n*n, 4))]."""
    corners = rest_vertices[quads]
    edge = np.max(np.linalg.norm(corners - np.roll(corners, 1, axis=1), axis=-1), axis=1)
    n = np.clip(np.ceil(edge * cam.f / min_distance * 1.1), 2, 24).astype(int)
    groups = []
    for k in np.unique(n):
        s = (np.arange(k) + 0.5) / k
        u, v = np.meshgrid(s, s)
        u, v = u.ravel(), v.ravel()
        w = np.stack([(1 - u) * (1 - v), u * (1 - v), u * v, (1 - u) * v], axis=1)
        groups.append((np.flatnonzero(n == k), w))
    return groups


def splat(points: np.ndarray, cam: DepthCamera, values: np.ndarray | None = None):
    """Z-buffer (H, W) of the nearest point per pixel (inf where empty); with `values` (one per point), also
    the (H, W) image of the nearest point's value (-1 where empty)."""
    z = points[:, 2]
    ok = z > 0.3
    p = points[ok]
    z = z[ok]
    u, v = np.round(kinect_to_depth_pixel(p, cam.f, cam.cx, cam.cy)).astype(np.int64).T
    inside = (u >= 0) & (u < cam.width) & (v >= 0) & (v < cam.height)
    idx, z = v[inside] * cam.width + u[inside], z[inside]
    order = np.argsort(-z, kind="stable")  # nearest written last wins
    buf = np.full(cam.width * cam.height, np.inf)
    buf[idx[order]] = z[order]
    if values is None:
        return buf.reshape(cam.height, cam.width)
    vals = np.full(cam.width * cam.height, -1, np.int64)
    vals[idx[order]] = np.asarray(values)[ok][inside][order]
    return buf.reshape(cam.height, cam.width), vals.reshape(cam.height, cam.width)


def fill_pinholes(depth: np.ndarray) -> np.ndarray:
    """Fill empty pixels whose 4-neighbours are mostly surface (sampling gaps, not real holes)."""
    d = depth.copy()
    pad = np.pad(d, 1, constant_values=np.inf)
    nb = np.stack([pad[:-2, 1:-1], pad[2:, 1:-1], pad[1:-1, :-2], pad[1:-1, 2:]])
    finite = np.isfinite(nb)
    fill = ~np.isfinite(d) & (finite.sum(0) >= 3)
    nbz = np.where(finite, nb, np.inf).min(0)
    d[fill] = nbz[fill]
    return d


def surface_points(vertices: np.ndarray, quads: np.ndarray, groups) -> np.ndarray:
    corners = vertices[quads]
    return np.concatenate([np.einsum("sk,qkc->qsc", w, corners[idx]).reshape(-1, 3) for idx, w in groups])


def room_depth(room: Room, cam: DepthCamera, tilt_deg: float = 0.0) -> np.ndarray:
    """Depth (H, W) of floor, back wall and boxes; the camera is pitched down by tilt_deg."""
    v, u = np.mgrid[0:cam.height, 0:cam.width].astype(np.float64)
    d = depth_pixel_to_kinect(u, v, np.ones_like(u), cam.f, cam.cx, cam.cy)  # z = 1 rays
    dw = d @ _tilt(tilt_deg).T  # ray directions in the level (world-aligned) frame
    t = np.full(u.shape, np.inf)
    with np.errstate(divide="ignore", invalid="ignore"):
        tf = room.floor_y / dw[..., 1]
        t = np.where((dw[..., 1] < 0) & (tf > 0), tf, t)
        tw = room.back_wall_z / dw[..., 2]
        t = np.minimum(t, np.where(dw[..., 2] > 0, tw, np.inf))
        for lo, hi in room.boxes:
            t1 = np.asarray(lo) / dw   # the rays start at the sensor's origin
            t2 = np.asarray(hi) / dw
            tmin = np.max(np.minimum(t1, t2), axis=-1)
            tmax = np.min(np.maximum(t1, t2), axis=-1)
            t = np.where((tmax >= tmin) & (tmin > 0), np.minimum(t, tmin), t)
    return t  # rays have z = 1 in the camera frame, so t is the depth


def _tilt(deg: float) -> np.ndarray:
    """Camera -> level frame for a sensor pitched down by `deg` degrees."""
    a = np.radians(deg)
    return np.array([[1, 0, 0], [0, np.cos(a), np.sin(a)], [0, -np.sin(a), np.cos(a)]]).T


def gravity_in_camera(tilt_deg: float) -> np.ndarray:
    """Unit gravity vector (pointing down) in camera space, as the accelerometer reports it."""
    return _tilt(tilt_deg).T @ np.array([0.0, -1.0, 0.0])


def kinect_artifacts(depth: np.ndarray, cam: DepthCamera, rng: np.random.Generator,
                     noise_raw: float = 0.4, edge_drop: float = 0.5) -> np.ndarray:
    """Metric depth (inf = nothing) -> raw 11-bit frame with shadow, edge dropouts, noise, quantisation."""
    h, w = depth.shape
    z = np.where(np.isfinite(depth), depth, 0.0)
    valid = (z > 0.4) & (z < 8.0)
    # Projector shadow: reproject every point into the projector (shifted along X); hidden points vanish.
    v, u = np.nonzero(valid)
    zz = z[v, u]
    x = depth_pixel_to_kinect(u, v, zz, cam.f, cam.cx, cam.cy)[:, 0]
    up = np.round(cam.cx - cam.f * (x - cam.projector_x) / zz).astype(np.int64)
    inside = (up >= 0) & (up < w)
    key = v * w + np.clip(up, 0, w - 1)
    buf = np.full(h * w, np.inf)
    np.minimum.at(buf, key[inside], zz[inside])
    buf = buf.reshape(h, w)
    buf = np.minimum(buf, np.minimum(np.roll(buf, 1, axis=1), np.roll(buf, -1, axis=1)))
    seen = zz <= buf[v, np.clip(up, 0, w - 1)] * 1.02 + 0.01
    valid[v[~seen], u[~seen]] = False
    # Dropouts along depth discontinuities (the speckle pattern breaks up there).
    zc = np.where(valid, z, 0.0)
    jump = np.zeros_like(valid)
    for ax in (0, 1):
        dz = np.abs(np.diff(zc, axis=ax)) > 0.05
        if ax == 0:
            jump[1:] |= dz
            jump[:-1] |= dz
        else:
            jump[:, 1:] |= dz
            jump[:, :-1] |= dz
    valid &= ~(jump & (rng.random(valid.shape) < edge_drop))
    raw = metres_to_raw(np.where(valid, z, 1.0)) + rng.normal(0.0, noise_raw, z.shape)
    raw = np.clip(np.round(raw), 0, NO_READING_RAW - 1).astype(np.uint16)
    raw[~valid] = NO_READING_RAW
    return raw
