"""SkeletonTracker: Kinect v1 depth frames in, Kinect v1 skeleton frames out (the SDK's job, in numpy).

    tracker = SkeletonTracker()
    positions, states = tracker.update(depth_mm, timestamp_seconds)   # (20, 3) metres, (20,) 0/1/2

The joints are where the Kinect SDK puts them (sdk_joints.py), so a tracked take reads like a recorded one.

Safe for any input: a frame of the wrong size or type, all zeros or all "no reading" gives every joint
NOT_TRACKED (and `tracker.status` says why), never an exception or NaN. Runs on the caller's thread (a
device thread may call it; it never touches bpy).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.skeletons import INFERRED, KINECT_V1, TRACKED
from ..core.take import Take
from .arm_reach import ArmSpeedGate, fold_overreaching_hands
from .arm_search import hands_at_tracked_wrists
from .body_model_fit import BodyCalibration
from .depth_camera import DepthCamera
from .limb_ends import BORDER_CELLS
from .confidence import ConfidenceCheck
from .output_smoothing import OutputSmoothing
from .part_fit import apply_proposals, body_frame, disagreeing, ends_seen, hands_backed, seen_on_parts
from .part_forest import MODEL_PATH, load_forest
from .part_proposals import propose
from .sdk_joints import to_sdk_joints
from .segmentation import DepthGrid, FloorPlane, PersonMask, find_people, fit_floor
from .skeleton_fit import HEAD_PART_NEAR, FitResult, confident_head_part, fit_person
from .take_smoothing import smooth_recorded_joints

LOST_RESET_S = 0.5   # forget the previous pose after this long without the person (then re-acquire)
CALIBRATION_MEMORY = 300   # standing measurements kept for the height
STANDING_PATCH = 0.53      # torso patch above the feet, fraction of the height so far, below which one is seated
HANDS_AT_TRACKED_WRISTS = True   # a hand off a tracked elbow and wrist, on the surface seen there, is tracked


@dataclass
class TrackerSettings:
    step: int = 4                 # grid stride on the 640x480 image
    smoothing: float = 0.35       # 0 = raw fit; blends toward the previous frame for small moves only
    floor_refit_every: int = 15   # frames between floor fits (the floor does not move)
    part_forest: str | None = MODEL_PATH   # body-part forest (.npz) whose joint proposals refine the fit; None = off
    steady_output: bool = True    # reported joints about as steady as the SDK's (output_smoothing.py); False = raw


class SkeletonTracker:
    def __init__(self, camera: DepthCamera | None = None, gravity=None, settings: TrackerSettings | None = None):
        self.camera = camera or DepthCamera()
        self.gravity: np.ndarray | None = None
        self.settings = settings or TrackerSettings()
        self.skeleton = KINECT_V1
        self.forest = load_forest(self.settings.part_forest) if self.settings.part_forest else None
        self.reset()
        if gravity is not None:
            self.set_gravity(gravity)   # any scale (an accelerometer reads about 9.8): kept as a unit vector

    def reset(self) -> None:
        self.floor: FloorPlane | None = None
        self.calibration = BodyCalibration()
        self._heights: list[tuple[float, float]] = []
        self.confidence = ConfidenceCheck()
        self.status = "waiting for a person"
        self.frames = 0
        self._prev: np.ndarray | None = None
        self._prev_states: np.ndarray | None = None
        self._lateral: np.ndarray | None = None
        self._person_centroid: np.ndarray | None = None
        self._last_seen: float | None = None
        self.last_grid: DepthGrid | None = None
        self.last_mask: np.ndarray | None = None
        self.last_good: FitResult | None = None
        self.last_proposals = None
        self.arm_gate = ArmSpeedGate()
        self.output_smoothing = OutputSmoothing()

    def set_gravity(self, gravity) -> None:
        """Accelerometer reading (any scale), pointing down in camera space."""
        g = np.asarray(gravity, dtype=np.float64)
        if g.shape == (3,) and np.all(np.isfinite(g)) and np.linalg.norm(g) > 1e-6:
            self.gravity = g / np.linalg.norm(g)
            self.floor = None

    def _none(self, why: str):
        self.status = why
        return np.zeros((20, 3)), np.zeros(20, np.uint8)

    def update(self, depth_mm: np.ndarray, timestamp: float):
        """One depth frame (480, 640) uint16 millimetres (0 = no reading) -> (positions, states)."""
        self.frames += 1
        d = np.asarray(depth_mm)
        if d.shape != (self.camera.height, self.camera.width):
            return self._none(f"depth frame has shape {d.shape}, expected "
                              f"({self.camera.height}, {self.camera.width})")
        if d.dtype.kind not in "ui":
            d = np.nan_to_num(d.astype(np.float64), nan=0.0, posinf=0.0, neginf=0.0).clip(0, 65535)
        try:
            ts = float(timestamp)
        except (TypeError, ValueError):
            ts = float("nan")
        grid = DepthGrid.from_mm(d, self.camera, self.settings.step)
        self.last_grid, self.last_mask = grid, None
        if grid.valid.sum() < 100:
            self._lose(ts)
            return self._none("no depth readings in this frame")
        up = -(self.gravity if self.gravity is not None else np.array([0.0, -1.0, 0.0]))
        if self.floor is None or self.frames % self.settings.floor_refit_every == 0:
            self.floor = fit_floor(grid, self.gravity, self.floor)
        if self.floor is not None:
            up = self.floor.normal
        people = find_people(grid, self.floor, -up)
        person = self._choose(people, ts)
        if person is None:
            self._lose(ts)
            return self._none("no person in view")
        last = self.last_good
        self.last_proposals = None if self.forest is None else propose(self.forest, grid, person.mask)
        fit = fit_person(grid, person.mask, up, self.calibration, self._prev, self._prev_states, self._lateral,
                         None if last is None else last.torso_centre, self.confidence.predict(ts),
                         self.confidence.settled, self.confidence.facing_steady, self.last_proposals,
                         self.confidence.frames_since(ts))
        if fit is None or not np.all(np.isfinite(fit.positions)):
            self._lose(ts)
            return self._none("person found but no skeleton fitted")
        if self.forest is not None:
            in_view = grid.in_view(fit.positions)   # a limb the fit continued past the image's edge keeps its end
            frame, turned = body_frame(fit.lateral, fit.axis), fit.turned or fit.edge_on
            before, before_st = fit.positions.copy(), fit.states.copy()
            doubt, own = apply_proposals(fit.positions, fit.states, self.last_proposals, self.calibration.height,
                                         no_floor=self.floor is None, in_view=in_view, frame=frame, turned=turned)
            seen = seen_on_parts(before, fit.positions, self.last_proposals, frame, own, turned, before_st)
            ends = ends_seen(self.last_proposals)
        else:
            doubt = own = seen = np.zeros(20, bool)
            ends, frame = frozenset(), None
        report = fit.states.copy()   # what is reported; the fit's history keeps its own states
        report[seen] = TRACKED
        if HANDS_AT_TRACKED_WRISTS:
            # with a forest, a hand hanging off a tracked wrist also needs its own evidence
            backed = None if self.forest is None else hands_backed(fit.positions, self.last_proposals, seen)
            report[hands_at_tracked_wrists(fit.positions, report, fit.projector, backed)] = TRACKED
        pos, st = fit.positions, self.confidence.assess(fit.positions, report, fit, own, ends, seen, ts)
        if self.forest is not None:   # reported states only (the fit's history keeps its own)
            doubt |= disagreeing(pos, self.last_proposals, frame)
            st[doubt & (st == TRACKED)] = INFERRED
        self._calibrate(person, fit, up)
        if self._prev is not None and self.settings.smoothing > 0:
            step = np.linalg.norm(pos - self._prev, axis=1, keepdims=True)
            w = self.settings.smoothing * np.clip(1.0 - step / 0.08, 0.0, 1.0)  # fast moves are not lagged
            pos = pos + w * (self._prev - pos)
        self.confidence.remember(pos, ts)
        self._prev, self._prev_states, self._lateral = pos.copy(), fit.states.copy(), fit.lateral
        self._person_centroid, self._last_seen = person.centroid, ts
        self.last_mask, self.last_good = person.mask, fit
        self.status = "tracking" if self.calibration.frames else "tracking (calibrating)"
        out = to_sdk_joints(pos)   # the fit's history stays on its own (MakeHuman's) convention
        fold_overreaching_hands(out, st, None if self.forest is None else self.last_proposals.positions,
                                self.calibration.height)
        self.arm_gate.apply(out, st, ts)
        if self.settings.steady_output:
            self.output_smoothing.apply(out, st, ts)
        return out, st

    def _lose(self, ts: float) -> None:
        if self._last_seen is None or not np.isfinite(ts) or ts - self._last_seen > LOST_RESET_S:
            self._prev = self._prev_states = self._lateral = self._person_centroid = self.last_good = None
            self.confidence.reset()
            self.arm_gate.reset()   # its history is the forgotten person's too
            self.output_smoothing.reset()

    def _choose(self, people: list[PersonMask], ts: float) -> PersonMask | None:
        """The tracked person by continuity; a new one is the largest person-like, most central region."""
        if not people:
            return None
        if self._person_centroid is not None:
            near = min(people, key=lambda p: np.linalg.norm(p.centroid - self._person_centroid))
            if np.linalg.norm(near.centroid - self._person_centroid) < 0.6:
                return near
        tall = [p for p in people if p.height > 1.1] or people
        return max(tall, key=lambda p: p.pixels / (1.0 + abs(p.centroid[0]) / max(p.centroid[2], 0.5)))

    def _calibrate(self, person: PersonMask, fit: FitResult, up: np.ndarray) -> None:
        """Measure standing height where the head and both feet are seen, both feet down, on the floor or, with
        no floor in view (pre-segmented frames, a sensor that does not see the floor), above the person's lowest
        point. Every pose but standing upright is shorter (seated, crouched, bowing, sitting down), so the
        height is a high percentile of all measurements, and the torso patch's place their median near that
        height. A head extremity far from a confident head part is hands held over the head, not a height."""
        labels = {k: p for k, p in fit.extrema}
        if not {"head", "FootLeft", "FootRight"} <= set(labels):
            return
        if person.mask[-1 - BORDER_CELLS:].any():
            return   # cut off by the image's bottom edge: the lowest point seen is no foot, the height no height
        head_part = confident_head_part(self.last_proposals if self.forest is not None else None)
        if head_part is not None and np.linalg.norm(labels["head"] - head_part) > HEAD_PART_NEAR:
            return   # hands held over the head (a basketball shot) measured as the head: 1.81 m for 1.69
        pts = self.last_grid.xyz[person.mask]
        if self.floor is not None:
            height = self.floor.height
        else:
            base = float(np.min(pts @ up))
            height = lambda p: p @ up - base
        feet_h = [height(labels[k]) for k in ("FootLeft", "FootRight")]
        near_head = pts[np.linalg.norm(pts - labels["head"], axis=1) < 0.2]
        top = float(np.max(height(near_head))) if len(near_head) else float(height(labels["head"]))
        # the torso patch where it grew, not where the head top pinned it: the calibration sets where the head
        # top is expected, which the pin then follows
        patch = float(height(fit.patch_centre))
        if max(feet_h) > 0.15 or not 1.2 < top < 2.2:  # not standing on the floor
            return
        if patch < STANDING_PATCH * self.calibration.height:
            # seated: the torso sits low above the feet for the height so far (not for this frame's head top:
            # a patch grown from the forest's torso sits as high on a seated trunk as on a standing one)
            return
        self._heights = (self._heights + [(top, patch)])[-CALIBRATION_MEMORY:]
        tops = np.array([h for h, _ in self._heights])
        c = self.calibration
        c.height = float(np.percentile(tops, 90))
        c.torso_patch_height = float(np.median([p / h for h, p in self._heights if h >= 0.97 * c.height]))
        c.frames = len(self._heights)


def track_depth_frames(depth_mm: np.ndarray, times: np.ndarray, camera: DepthCamera | None = None,
                       gravity=None, settings: TrackerSettings | None = None, progress=None,
                       cleanup: bool = True) -> Take:
    """Run the tracker over a capture: (F, 480, 640) millimetres and (F,) seconds -> a Kinect v1 Take.
    `cleanup`: with steady output, the recorded take's joints are also cleaned with its future frames
    (take_smoothing.py: no lag, wrong limbs of a frame or two dropped); False gives what the live tracker
    reported."""
    tracker = SkeletonTracker(camera, gravity, settings)
    n = len(depth_mm)
    pos = np.zeros((n, 20, 3))
    st = np.zeros((n, 20), np.uint8)
    for i in range(n):
        pos[i], st[i] = tracker.update(depth_mm[i], times[i])
        if progress is not None:
            progress(i + 1, n)
    if cleanup and tracker.settings.steady_output:
        pos = smooth_recorded_joints(pos, st, times)
    rate = 30.0 if n < 2 else float(np.clip(round(1.0 / np.median(np.diff(times)), 3), 1, 240))
    return Take(KINECT_V1, pos, st, np.asarray(times, dtype=np.float64), rate, "depth",
                {"tracker": "kinect_retarget.depth", "calibrated_height_m": round(tracker.calibration.height, 3)})
