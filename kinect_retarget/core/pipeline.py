"""Take or frame in, pose-bone rotations and root location out: filter -> joint frames -> retarget.

The bake (`process_take`) and live (`process_frame`) paths share the filter state machine and the solver,
so a live pose equals the baked pose for the same frame and settings.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .conventions import mirror_positions
from .filters import FILTERS, make_filter
from .joint_frames import resolver
from .quat import make_continuous
from .retarget import ROOT_MODES, Retargeter, leg_length
from .skeletons import NOT_TRACKED, Skeleton
from .take import Take, TakeError
from .target_rig import TargetRig


@dataclass(frozen=True)
class RetargetSettings:
    filter: str = "default"          # see filters.FILTERS
    root_mode: str = "xyz"           # xyz | xy (no vertical motion) | none
    fps: float | None = None         # scene rate; None = the take's nominal rate
    frame_start: int = 1
    mirror: bool = False             # swap the performer's left and right
    root_scale: float | None = None  # n of eq. 13; None = target leg / source leg (1 on the generated rig)

    def __post_init__(self) -> None:
        if self.filter not in FILTERS:
            raise ValueError(f"unknown filter {self.filter!r} (choose from {', '.join(FILTERS)})")
        if self.root_mode not in ROOT_MODES:
            raise ValueError(f"unknown root mode {self.root_mode!r} (choose from {', '.join(ROOT_MODES)})")
        if self.fps is not None and not self.fps > 0:
            raise ValueError(f"fps must be positive, got {self.fps}")


@dataclass
class BakedMotion:
    """Keys for one rig: frames (N,) scene frames, quats (N, M, 4) wxyz sign-continuous for bone_names,
    root_location (N, 3) pose location of root_bone; samples (N,) the take sample each key came from."""

    frames: np.ndarray
    bone_names: tuple[str, ...]
    quats: np.ndarray
    root_bone: str | None
    root_location: np.ndarray
    fps: float
    samples: np.ndarray
    extras: dict = field(default_factory=dict)


@dataclass
class FramePose:
    bone_names: tuple[str, ...]
    quats: np.ndarray          # (M, 4)
    root_bone: str | None
    root_location: np.ndarray  # (3,)
    time: float
    desired: np.ndarray        # (M, 4) armature-space rotations, for rigs with constrained parents
    positions: np.ndarray | None = None  # (J, 3) the frame's filtered joints (Kinect space), for the hands


class RetargetPipeline:
    def __init__(self, skeleton: Skeleton, rig: TargetRig, mapping: dict[str, str],
                 settings: RetargetSettings | None = None):
        self.skeleton, self.rig = skeleton, rig
        self.settings = settings or RetargetSettings()
        self.retargeter = Retargeter(skeleton, rig, mapping, root_mode=self.settings.root_mode,
                                     root_scale=self.settings.root_scale)
        self.source_leg: float | None = None  # set by live calibration; process_take measures it when unset
        self.reset()

    @property
    def bone_names(self) -> tuple[str, ...]:
        return self.retargeter.bone_names

    @property
    def root_bone(self) -> str | None:
        return self.retargeter.root.bone if self.retargeter.root else None

    def reset(self, rate: float = 30.0) -> None:
        """Forget filter history and the root reference (a new take or a new live session). The calibrated
        source leg length (root scale) is kept: it belongs to the performer, not the take."""
        self.filter = make_filter(self.settings.filter, rate)
        self.root_reference: np.ndarray | None = None
        self._last_seen = np.full((len(self.skeleton), 3), np.nan)  # last finite position of each joint

    def _fill_missing(self, positions: np.ndarray, backfill: bool) -> tuple[np.ndarray, np.ndarray]:
        """Readers mark joints they have no position for with NaN (untracked): carry each joint's last known
        position forward (and, for a whole take, its first one backward), so nothing NaN reaches the solver.
        Returns the positions and (M,) True for mapped bones on a joint still unknown at the last frame: such
        joints stand at the root (NaN while the root itself is unknown) and their bones are not driven."""
        finite = np.all(np.isfinite(positions), axis=-1)
        if finite.all():
            self._last_seen = positions[-1].copy()
            return positions, np.zeros(len(self.retargeter.mapped), dtype=bool)
        nf, nj = finite.shape
        src = np.maximum.accumulate(np.where(finite, np.arange(nf)[:, None], -1), axis=0)
        out = positions[np.maximum(src, 0), np.arange(nj)]
        before = src < 0
        out[before] = np.broadcast_to(self._last_seen, out.shape)[before]
        if backfill:
            first = np.argmax(finite, axis=0)
            lead = before & finite.any(axis=0)
            out[lead] = positions[first, np.arange(nj)][np.nonzero(lead)[1]]
        self._last_seen = np.where(np.isfinite(out[-1]), out[-1], self._last_seen)
        unknown = ~np.all(np.isfinite(out[-1]), axis=-1)
        unseen = np.array([unknown[m.head] or unknown[m.tail] for m in self.retargeter.mapped])
        root = self.skeleton.root
        return np.where(np.isfinite(out), out, out[:, root:root + 1]), unseen

    def _mirrored(self, positions: np.ndarray) -> np.ndarray:
        return mirror_positions(positions, self.skeleton.mirror) if self.settings.mirror else positions

    def _filtered(self, positions, states, times) -> np.ndarray:
        if self.settings.mirror:
            states = states[..., self.skeleton.mirror]
        positions = self._mirrored(positions)
        if self.filter is None:
            return positions
        return self.filter.run(positions, states, times)

    def process_take(self, take: Take) -> BakedMotion:
        if take.skeleton.name != self.skeleton.name:
            raise TakeError(f"take skeleton {take.skeleton.name} does not match pipeline {self.skeleton.name}")
        fps = float(self.settings.fps or take.rate)
        self.reset(take.rate)
        keyed = np.flatnonzero(take.any_tracked)
        if keyed.size == 0:
            raise TakeError("take has no frame with a tracked joint: nothing to bake")
        positions, unseen = self._fill_missing(take.positions[keyed], backfill=True)
        if self.retargeter.root is not None and unseen[self.retargeter.mapped.index(self.retargeter.root)]:
            raise TakeError(f"take never gives a position for the root joint "
                            f"{self.skeleton.joints[self.skeleton.root]}: nothing to bake")
        positions = self._filtered(positions, take.states[keyed], take.times[keyed])
        if self.source_leg is None:
            self.source_leg = leg_length(resolver(self.skeleton.joints, positions))
        self.root_reference = positions[0, self.skeleton.root].copy()
        frames = self.settings.frame_start + np.round((take.times[keyed] - take.times[0]) * fps).astype(np.int64)
        first = np.concatenate([[True], np.diff(frames) > 0])  # one key per scene frame: the first sample
        quats, location, desired = self.retargeter.solve(positions[first], self.root_reference, self.source_leg,
                                                         want_desired=True)
        keep = ~unseen  # bones on joints the take never saw are left alone, not keyed
        names = np.array(self.bone_names)
        return BakedMotion(frames[first], tuple(names[keep]), make_continuous(quats[:, keep], axis=0),
                           self.root_bone, location, fps, keyed[first],
                           {"desired": desired[:, keep], "positions": positions[first],
                            "skipped_bones": tuple(names[unseen])})

    def process_frame(self, positions: np.ndarray, states: np.ndarray, time: float) -> FramePose | None:
        """One live frame; None when no joint is tracked (nothing to apply, filter untouched)."""
        return self.process_frames(np.asarray(positions)[None], np.asarray(states)[None], np.array([time]))

    def process_frames(self, positions: np.ndarray, states: np.ndarray, times: np.ndarray) -> FramePose | None:
        """Several live frames that arrived together: every one goes through the filter (so live equals the
        bake), only the newest is solved. (K, J, 3), (K, J), (K,) -> pose of the last tracked frame or None."""
        positions = np.asarray(positions, dtype=np.float64)
        states, times = np.asarray(states), np.asarray(times, dtype=np.float64)
        keep = np.flatnonzero(np.any(states != NOT_TRACKED, axis=1))
        if keep.size == 0:
            return None
        positions, states, times = positions[keep], states[keep], times[keep]
        if not np.all(np.isfinite(positions[states != NOT_TRACKED])):
            raise ValueError("frame has NaN or infinite positions for tracked joints")
        positions, unseen = self._fill_missing(positions, backfill=False)
        root = self.skeleton.root
        if not np.all(np.isfinite(positions[:, root])):
            return None  # nothing known about the root yet
        p = self._filtered(positions, states, times)
        if self.root_reference is None:
            self.root_reference = p[0, root].copy()
        quats, location, desired = self.retargeter.solve(p[-1:], self.root_reference, self.source_leg,
                                                         want_desired=True)
        quats[0, unseen] = (1.0, 0.0, 0.0, 0.0)  # joints never seen yet: their bones stay at rest
        return FramePose(self.bone_names, quats[0], self.root_bone, location[0], float(times[-1]), desired[0],
                         p[-1])
