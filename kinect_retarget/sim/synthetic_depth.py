"""Synthetic Kinect v1 depth sequences with ground truth: real CMU mocap on the MakeHuman body.

`render_sequence(bvh, ...)` returns a `SyntheticSequence` (raw 11-bit frames, millimetres, timestamps,
gravity, ground-truth Kinect v1 joints in camera space). The motion keeps its shape; only its path on the
floor is turned to face the sensor and compressed to stay 1.5-3.5 m away (a Kinect's working range).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..core.conventions import kinect_to_depth_pixel
from ..device.protocol import TIMESTAMP_HZ
from .makehuman_body import load_body
from .bvh_motion import read_bvh_positions
from ..depth.depth_camera import DepthCamera, raw_to_mm
from .mocap_pose import cmu_points, pose_from_points
from .depth_render import (Room, fill_pinholes, gravity_in_camera, kinect_artifacts, quad_sampler, room_depth, splat,
                     surface_points, _tilt)



@dataclass
class Scenario:
    """What else is in the scene and how the performer moves through it."""
    distance: float = 2.5            # mean distance of the performer's path from the sensor
    lateral: float = 0.0             # mean X of the path
    tilt_deg: float = 0.0            # sensor pitched down
    second_person: tuple | None = None   # (x, z) of a bystander standing still, or None
    boxes: list = field(default_factory=list)
    enter_exit: bool = False         # performer walks in from the side at the start and out at the end
    turn_deg: float = 0.0            # turn the performer away from facing the sensor (occludes one side)
    noise_raw: float = 0.4
    seed: int = 0


@dataclass
class SyntheticSequence:
    raw: np.ndarray          # (F, 480, 640) uint16, 2047 = no reading
    mm: np.ndarray           # (F, 480, 640) uint16, 0 = no reading
    timestamp: np.ndarray    # (F,) device ticks (60 MHz)
    times: np.ndarray        # (F,) seconds
    gravity: np.ndarray      # (3,) camera space, pointing down
    joints: np.ndarray       # (F, 20, 3) ground truth, Kinect camera space metres
    present: np.ndarray      # (F,) performer fully or partly in view
    camera: DepthCamera

    def save_npz(self, path: str) -> None:
        np.savez_compressed(path, raw=self.raw, mm=self.mm, timestamp=self.timestamp, times=self.times,
                            gravity=self.gravity, gt_joints=self.joints, gt_present=self.present,
                            focal=self.camera.f, cx=self.camera.cx, cy=self.camera.cy)


def _placement(cmu: dict, sc: Scenario, nf: int, fps: float):
    """Yaw (3, 3) and per-frame translation (F, 3) putting the performer facing the sensor."""
    lat = np.mean(cmu["hip.L"] - cmu["hip.R"], axis=0)
    fwd = np.cross(lat, [0.0, 1.0, 0.0])
    fwd[1] = 0
    ang = np.arctan2(fwd[0], fwd[2])  # heading about Y, relative to +Z
    turn = np.pi - ang + np.radians(sc.turn_deg)  # face -Z (toward the sensor), then turn as asked
    c, s = np.cos(turn), np.sin(turn)
    yaw = np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    root = (cmu["hips"] @ yaw.T)[:, [0, 2]]
    mean = root.mean(axis=0)
    span = np.maximum(root.max(axis=0) - root.min(axis=0), 1e-6)
    squeeze = min(1.0, 1.2 / span[0], 1.4 / span[1])
    new = (root - mean) * squeeze + [sc.lateral, sc.distance]
    if sc.enter_exit:  # slide in from outside the view during the first second, out during the last
        ramp = np.clip(np.minimum(np.arange(nf), nf - 1 - np.arange(nf)) / fps, 0, 1)
        new[:, 0] += (1 - ramp) * 2.6
    shift = np.zeros((nf, 3))
    shift[:, [0, 2]] = new - root
    return yaw, shift


def render_sequence(bvh_path: str, mesh_dir: str, scenario: Scenario | None = None, start: int = 0,
                    frames: int = 60, step: int = 4, camera: DepthCamera | None = None) -> SyntheticSequence:
    """Render `frames` frames of a 120 fps CMU BVH taken every `step` frames (4 -> 30 fps)."""
    sc = scenario or Scenario()
    cam = camera or DepthCamera()
    rng = np.random.default_rng(sc.seed)
    body = load_body(mesh_dir)
    names, _, pos, frame_time = read_bvh_positions(bvh_path)
    pos = pos[start:start + frames * step:step]
    nf = pos.shape[0]
    fps = 1.0 / (frame_time * step)
    cmu = cmu_points(names, pos)
    posed = pose_from_points(body, cmu)
    yaw, shift = _placement(cmu, sc, nf, fps)
    to_cam = _tilt(sc.tilt_deg).T  # level frame -> camera frame
    room = Room(boxes=list(sc.boxes))
    groups = quad_sampler(body.rest_vertices, body.quads, 1.4, cam)  # dense enough from 1.4 m
    background = room_depth(room, cam, sc.tilt_deg)
    bystander = None
    if sc.second_person is not None:  # a second person standing still (the body's first frame, turned)
        v0 = posed.vertices(body, slice(0, 1))[0] @ yaw.T
        v0 = v0 - v0.mean(axis=0) + [sc.second_person[0], 0.0, sc.second_person[1]]
        bystander = v0
    verts_all, floor = [], []
    for a in range(0, nf, 16):
        v = posed.vertices(body, slice(a, a + 16)) @ yaw.T + shift[a:a + 16, None]
        verts_all.append(v)
        floor.append(v[..., 1].min(axis=1))
    lift = room.floor_y - np.percentile(np.concatenate(floor), 2)
    if bystander is not None:   # standing still: rendered once into the background
        bystander[:, 1] += room.floor_y - bystander[:, 1].min()
        bystander = bystander @ to_cam.T
        background = np.minimum(background, fill_pinholes(splat(surface_points(bystander, body.quads, groups), cam)))
    joints = (posed.joints @ yaw.T + shift[:, None] + [0, lift, 0]) @ to_cam.T
    raw = np.empty((nf, cam.height, cam.width), np.uint16)
    for i, v in enumerate(np.concatenate(verts_all)):
        v = (v + [0, lift, 0]) @ to_cam.T
        depth = np.minimum(fill_pinholes(splat(surface_points(v, body.quads, groups), cam)), background)
        raw[i] = kinect_artifacts(depth, cam, rng, noise_raw=sc.noise_raw)
    times = np.arange(nf) / fps
    uv_x = kinect_to_depth_pixel(joints, cam.f, cam.cx, cam.cy)[..., 0]
    present = np.any((uv_x > 0) & (uv_x < cam.width), axis=1)
    return SyntheticSequence(raw, raw_to_mm(raw), (times * TIMESTAMP_HZ).astype(np.int64), times,
                             gravity_in_camera(sc.tilt_deg), joints, present, cam)
