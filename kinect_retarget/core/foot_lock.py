"""Planted feet and the floor at bake time (issue 16), on the target rig.

For each leg (the bones mapped to the thigh, shin and foot segments) the ankle's path comes from the rig's
forward kinematics of the baked keys. During a contact (foot_contacts.py) the ankle is pinned where the foot
stood (its mean place over the contact, a little raised), easing in and out; every ankle is kept at or above
its height over the floor in the rig's rest pose. First the whole body moves up or down once, so planted
ankles stand at that height (a vertical shift of the hips turns no bone). The leg reaches each new ankle by
two-bone IK: the hip-ankle line turns the shortest way onto it, the bend plane turns with the line (the knee
stays in it, no twist about the leg), the knee takes the angle that fits the distance; the foot keeps its
orientation in the armature. Last, where a foot points down more steeply than the rest foot, its tip and toes
would dip under the floor: the foot pitches up about the ankle just enough, eased in and out (toe_floor.py).
Only the three leg bones' keys change, and only on frames that need it. Pure numpy; the rig's rest matrices are
not touched.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .foot_contacts import RAMP_S, detect_contacts, intervals, pin_weights
from .quat import conjugate, from_matrix, make_continuous, mul, normalize, to_matrix
from .target_rig import evaluate_pose
from .toe_floor import axis_angle_quats, eased, needed_pitch, pitch_axes, pitch_room, rest_pitch_axis, tip_bones, tips

FEET_MODES = ("lock", "floor", "off")
PIN_HEIGHT_PERCENTILE = 90
REACH = 0.999  # the IK never straightens a leg fully (a straight knee has no bend plane)


@dataclass
class LegReport:
    side: str
    contacts: int
    contact_frames: int
    slide_before_cm: tuple[float, float]   # median, p95 horizontal distance from the contact's place
    slide_after_cm: tuple[float, float]
    below_floor_before_cm: float           # deepest ankle below its rest height over the floor
    below_floor_after_cm: float
    frames_changed: int
    changed: np.ndarray = field(default_factory=lambda: np.zeros(0, bool), repr=False)  # (F,) keys edited
    contact: np.ndarray = field(default_factory=lambda: np.zeros(0, bool), repr=False)  # (F,) planted
    toe_below_before_cm: float = 0.0       # deepest foot tip or toe tip below the floor
    toe_below_after_cm: float = 0.0
    pitched: np.ndarray = field(default_factory=lambda: np.zeros(0, bool), repr=False)  # (F,) foot pitched up
    toe_frames: int = 0                    # how many (to keep the toes on the floor)


@dataclass
class FeetReport:
    mode: str
    legs: list[LegReport] = field(default_factory=list)
    height_shift_cm: float = 0.0  # the whole body raised by this much so planted feet stand on the floor

    def summary(self) -> str:
        if self.mode == "off" or not self.legs:
            return "feet: off" if self.mode == "off" else "feet: no leg mapped"
        parts = [f"{g.side} {g.contacts} contacts, slide p95 {g.slide_before_cm[1]:.1f} -> {g.slide_after_cm[1]:.1f}"
                 f" cm, below floor {g.below_floor_before_cm:.1f} -> {g.below_floor_after_cm:.1f} cm"
                 f" (toes {g.toe_below_before_cm:.1f} -> {g.toe_below_after_cm:.1f} cm)"
                 for g in self.legs]
        return f"feet ({self.mode}, body raised {self.height_shift_cm:.1f} cm): " + "; ".join(parts)


def key_rate(motion) -> float:
    """Keys per second of a BakedMotion (its scene rate over the frames between keys)."""
    gap = float(np.median(np.diff(motion.frames))) if len(motion.frames) > 1 else 1.0
    return motion.fps / max(gap, 1.0)


def _between(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Shortest-arc rotations taking directions a to b, (F, 4)."""
    a, b = normalize(a), normalize(b)
    q = np.concatenate([1 + np.sum(a * b, -1, keepdims=True), np.cross(a, b)], axis=-1)
    return normalize(q)


def _rotate(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    return np.einsum("fij,fj->fi", to_matrix(q), v)


def _frame_turn(x0, n0, x1, n1) -> np.ndarray:
    """(F, 4) rotations taking the frame (x0, n0) onto (x1, n1) (n ⟂ x in both; x need not be unit)."""
    def frame(x, n):
        x = normalize(x)
        return np.stack([x, n, np.cross(x, n)], axis=-1)
    return normalize(from_matrix(frame(x1, n1) @ np.swapaxes(frame(x0, n0), -1, -2)))


def _mul(a, b):
    return mul(np.broadcast_to(a, np.broadcast_shapes(a.shape, b.shape)),
               np.broadcast_to(b, np.broadcast_shapes(a.shape, b.shape)))


def _slide(pos, mask, up) -> np.ndarray:
    """Horizontal distance (m) of each contact frame's position from its contact's mean place."""
    out = []
    for a, b in intervals(mask):
        p = pos[a:b + 1]
        d = p - p.mean(axis=0)
        d -= np.outer(d @ up, up)
        out.append(np.linalg.norm(d, axis=-1))
    return np.concatenate(out) if out else np.zeros(0)


def _stats_cm(x: np.ndarray) -> tuple[float, float]:
    return (float(np.median(x) * 100), float(np.percentile(x, 95) * 100)) if x.size else (0.0, 0.0)


class FootLock:
    """Feet for one bake: `apply(motion, mode, rate)` edits a BakedMotion's leg keys (quats and the desired
    armature-space rotations in motion.extras) in place and returns a FeetReport."""

    def __init__(self, retargeter):
        self.rt = retargeter
        self.rig = retargeter.rig
        self.up = self.rig.object_rotation.T @ np.array([0.0, 0.0, 1.0])
        rest = self.rig.rest
        self.floor = float(min((rest[:, :3, 3] @ self.up).min(), (self.rig.tails @ self.up).min()))
        by_joint = {m.tail_name: m for m in retargeter.mapped}
        self.shift = 0.0  # the last apply's vertical shift of the body (m)
        self.legs = {}
        for side in ("Left", "Right"):
            thigh, shin, foot = (by_joint.get(j + side) for j in ("Knee", "Ankle", "Foot"))
            if thigh is not None and shin is not None:
                self.legs[side] = (thigh, shin, foot)
        self.tips = {side: tip_bones(self.rig, foot.index) for side, (_, _, foot) in self.legs.items() if foot}
        self.across = {side: rest_pitch_axis(self.rig, foot.index, self.up)
                       for side, (_, _, foot) in self.legs.items() if foot}

    def _local(self, motion, desired: np.ndarray, name: str) -> np.ndarray:
        """Pose-bone quaternions of bone `name` from the desired armature-space rotations (the solver's eq. 12)."""
        k = self.rt.bone_names.index(name)
        static = self.rt.static_q[k]
        if self.rt.has_anchor[k]:
            anchor = motion.bone_names.index(self.rt.bone_names[self.rt.anchor[k]])
            frame = _mul(desired[:, anchor], static)
        else:
            frame = np.broadcast_to(static, desired[:, 0].shape)
        return mul(conjugate(frame), desired[:, motion.bone_names.index(name)])

    def apply(self, motion, mode: str, rate: float) -> FeetReport:
        if mode not in FEET_MODES:
            raise ValueError(f"feet mode must be one of {', '.join(FEET_MODES)}, got {mode!r}")
        report = FeetReport(mode)
        if mode == "off":
            return report
        desired = motion.extras["desired"]
        idx = np.array([self.rig.index(b) for b in motion.bone_names])
        root = self.rig.index(motion.root_bone) if motion.root_bone else None
        posed = evaluate_pose(self.rig, idx, motion.quats, root, motion.root_location)
        self.shift = self._stand(motion, posed, root, rate)
        report.height_shift_cm = 100 * self.shift
        done = []
        for side, (thigh, shin, foot) in self.legs.items():
            if thigh.bone not in motion.bone_names or shin.bone not in motion.bone_names:
                continue
            if foot is not None and foot.bone not in motion.bone_names:
                foot = None
            leg, contact = self._leg(motion, desired, posed, side, thigh, shin, foot, mode, rate)
            report.legs.append(leg)
            done.append((leg, contact, shin, foot))
        motion.quats = make_continuous(motion.quats, axis=0)
        if any(foot is not None for *_, foot in done):
            legged = evaluate_pose(self.rig, idx, motion.quats, root, motion.root_location)
            for leg, _, _, foot in done:
                if foot is not None:
                    self._toes(motion, desired, legged, leg, foot, rate)
            motion.quats = make_continuous(motion.quats, axis=0)
        after = evaluate_pose(self.rig, idx, motion.quats, root, motion.root_location)  # measured, not assumed
        for leg, contact, shin, foot in done:
            ankle, toe, limit = self._ankle(after, shin, foot)
            leg.slide_after_cm = _stats_cm(_slide(ankle, contact, self.up))
            leg.below_floor_after_cm = 100 * self._below(ankle, toe, limit)
            if foot is not None:
                leg.toe_below_after_cm = 100 * self._toe_below(after, leg.side)
        return report

    def _toe_below(self, posed, side, shift: float = 0.0) -> float:
        """Deepest tip of the foot or its toes below the floor (m), 0 when none is; `shift` is taken off the
        heights (the body's vertical shift, to measure the bake as it was before it)."""
        return float(max(0.0, (self.floor + shift - tips(self.rig, posed, self.tips[side]) @ self.up).max()))

    def _toes(self, motion, desired, posed, leg, foot, rate) -> None:
        """Pitch the foot up about its ankle where its tip or toes would be under the floor (eased)."""
        m = posed[:, foot.index]
        axis = pitch_axes(m, self.across[leg.side], self.up)
        shape = (m[:, :3, 3], tips(self.rig, posed, self.tips[leg.side]), axis, self.up, self.floor)
        need = needed_pitch(*shape)
        if not need.any():
            return
        # eased in and out, but never past where a toe that was up would sink (a foot whipping round in the take)
        angle = np.maximum(np.minimum(eased(need, max(2, int(round(RAMP_S * rate)))), pitch_room(*shape, need)), need)
        f = np.flatnonzero(angle > 0)
        j = motion.bone_names.index(foot.bone)
        turn = axis_angle_quats(axis[f], angle[f])
        desired[f, j] = mul(turn, desired[f, j])
        # the same turn on the keyed pose as it is (a resampled bake's desired rotations only approximate it):
        # world' = turn . world  <=>  local' = local . (world^-1 . turn . world)
        world = from_matrix(m[f, :3, :3])
        motion.quats[f, j] = mul(motion.quats[f, j], mul(conjugate(world), mul(turn, world)))
        leg.changed[f] = True
        leg.frames_changed = int(leg.changed.sum())
        leg.pitched, leg.toe_frames = angle > 0, len(f)

    def _place(self, path: np.ndarray) -> np.ndarray:
        """Where a planted ankle is pinned: its mean place over the contact, at a high percentile of its heights
        there (a straight standing leg under a swaying hip can reach a slightly raised pin, not a low one)."""
        place = path.mean(axis=0)
        return place + (np.percentile(path @ self.up, PIN_HEIGHT_PERCENTILE) - place @ self.up) * self.up

    def _stand(self, motion, posed, root, rate) -> float:
        """Raise (or lower) the whole body so planted feet stand on the floor: ankles at their rest height
        over it, and toes not under it (a foot planted pointing down, as Kinect's are, stands on its toes, not
        on an ankle at the rig's rest height). One vertical shift of the hips for the take (the median depth
        over both feet's contacts), which turns no bone. The rig's legs, in the performer's stance, may reach
        lower than in its own rest pose (MakeHuman's hip bones turned to a Kinect hip line). Returns the shift
        (m); posed is shifted in place."""
        if root is None or not len(motion.frames):
            return 0.0
        depths = []
        for side, (thigh, shin, foot) in self.legs.items():
            if thigh.bone in motion.bone_names and shin.bone in motion.bone_names:
                foot = foot if foot is not None and foot.bone in motion.bone_names else None
                ankle, _, limit = self._ankle(posed, shin, foot)
                contact = detect_contacts(ankle, self.up, self._leg_length(thigh, shin, foot), rate)
                depth = limit - ankle[contact] @ self.up
                if foot is not None:
                    toes = tips(self.rig, posed[contact], self.tips[side]) @ self.up
                    depth = np.maximum(depth, self.floor - toes.min(axis=1, initial=np.inf))
                depths.append(depth)
        depth = np.concatenate(depths) if depths else np.zeros(0)
        if not depth.size:
            return 0.0
        shift = float(np.median(depth))
        motion.root_location = motion.root_location + self.rig.rest[root, :3, :3].T @ (shift * self.up)
        posed[:, :, :3, 3] += shift * self.up
        return shift

    def _leg_length(self, thigh, shin, foot) -> float:
        rig = self.rig
        ankle = rig.rest[foot.index, :3, 3] if foot is not None else rig.tails[shin.index]
        return float(np.linalg.norm(rig.heads[shin.index] - rig.heads[thigh.index]) +
                     np.linalg.norm(ankle - rig.heads[shin.index]))

    def _ankle(self, posed, shin, foot) -> tuple[np.ndarray, np.ndarray, float]:
        """Ankle and toe paths (F, 3) and the ankle's lowest allowed height (its rest height over the floor)."""
        rig = self.rig
        if foot is None:
            ankle = posed[:, shin.index, :3, 3] + posed[:, shin.index, :3, 1] * rig.lengths[shin.index]
            return ankle, ankle, float(rig.tails[shin.index] @ self.up)
        ankle = posed[:, foot.index, :3, 3]
        toe = ankle + posed[:, foot.index, :3, 1] * rig.lengths[foot.index]
        return ankle, toe, float(rig.rest[foot.index, :3, 3] @ self.up)

    def _below(self, ankle, toe, limit) -> float:
        """Deepest ankle below its rest height over the floor (m), 0 when none is (the toes: _toe_below)."""
        return float(max(0.0, (limit - ankle @ self.up).max()))

    def _leg(self, motion, desired, posed, side, thigh, shin, foot, mode, rate) -> tuple[LegReport, np.ndarray]:
        up = self.up
        hip, knee = posed[:, thigh.index, :3, 3], posed[:, shin.index, :3, 3]
        ankle, toe, limit = self._ankle(posed, shin, foot)
        contact = detect_contacts(ankle, up, self._leg_length(thigh, shin, foot), rate)
        target = ankle.copy()
        if mode == "lock":
            w, which = pin_weights(contact, rate)
            places = [self._place(ankle[a:b + 1]) for a, b in intervals(contact)]
            pinned = which >= 0
            pins = np.array([places[c] for c in which[pinned]]).reshape(-1, 3)
            target[pinned] += w[pinned, None] * (pins - ankle[pinned])
        lift = np.maximum(0.0, limit - target @ up)
        target += lift[:, None] * up
        change = np.linalg.norm(target - ankle, axis=-1) > 1e-9
        self._ik(motion, desired, posed, thigh, shin, foot, hip, knee, ankle, target, change)
        report = LegReport(side, len(intervals(contact)), int(contact.sum()), _stats_cm(_slide(ankle, contact, up)),
                           (0.0, 0.0), 100 * self._below(ankle - self.shift * up, toe, limit), 0.0,
                           int(change.sum()), change, contact)
        if foot is not None:  # as baked, before the body's shift
            report.toe_below_before_cm = 100 * self._toe_below(posed, side, self.shift)
        return report, contact

    def _ik(self, motion, desired, posed, thigh, shin, foot, hip, knee, ankle, target, change) -> None:
        if not change.any():
            return
        f = np.flatnonzero(change)
        h, k, a, t = hip[f], knee[f], ankle[f], target[f]
        l1, l2 = np.linalg.norm(k - h, axis=-1), np.linalg.norm(a - k, axis=-1)
        # the bend plane's normal: from the bent knee, else the thigh bone's X (hinge) axis
        n0 = np.cross(k - h, a - k)
        flat = np.linalg.norm(n0, axis=-1) < 1e-6 * l1 * l2
        n0[flat] = posed[f[flat], thigh.index, :3, 0]
        u = normalize(a - h)
        n0 = normalize(n0 - np.sum(n0 * u, -1, keepdims=True) * u)
        # the hip-ankle line turns the shortest way onto the target; the bend plane turns with it (no twist
        # about the leg), and the knee takes the angle that fits the new hip-ankle distance in that plane
        d = np.clip(np.linalg.norm(t - h, axis=-1), np.abs(l1 - l2) * 1.001, (l1 + l2) * REACH)
        v = normalize(t - h)
        n1 = _rotate(_between(u, v), n0)
        side = np.sign(np.sum(np.cross(n0, u) * (k - h), -1, keepdims=True))   # the knee's side of the line
        cos_hip = np.clip((l1 ** 2 + d ** 2 - l2 ** 2) / (2 * l1 * d), -1, 1)[:, None]
        k1 = h + l1[:, None] * (cos_hip * v + np.sqrt(1 - cos_hip ** 2) * side * np.cross(n1, v))
        a1 = h + d[:, None] * v
        turn_thigh = _frame_turn(k - h, n0, k1 - h, n1)
        turn_shin = _frame_turn(a - k, n0, a1 - k1, n1)
        names = motion.bone_names
        ti, si = names.index(thigh.bone), names.index(shin.bone)
        desired[f, ti] = mul(turn_thigh, desired[f, ti])
        desired[f, si] = mul(turn_shin, desired[f, si])
        for m in (thigh, shin) + ((foot,) if foot is not None else ()):  # the foot keeps its armature rotation
            j = names.index(m.bone)
            motion.quats[f, j] = self._local(motion, desired[f], m.bone)
