"""Learn how a rig's constraint-driven parents move (issue 15), evaluating the armature alone.

Blender evaluates a copy of the armature object (same bones, its own pose) in a temporary scene that holds
nothing else, so neither the user's meshes and modifiers nor their rig are evaluated or touched, and the
cost does not grow with the character. The probe poses the copy at random a dozen times; core/parent_fit.py
turns the evaluated rotations into relations numpy evaluates for every frame at once. Bones no relation
explains are evaluated per frame on the copy (`solve_frames`), the only per-frame evaluations left.
"""
from __future__ import annotations

import bpy
import numpy as np
from bpy.utils import escape_identifier
from bpy_extras import anim_utils

from ...core.parent_fit import learn, relative_to_parent
from ...core.parent_model import ParentModel
from ...core.quat import angle_between, from_axis_angle, from_matrix, make_continuous, normalize
from ...core.target_rig import TargetRig
from .pose_apply import set_rotations

FIT_POSES = 4
VERIFY_POSES = 10
MAX_ANGLE = np.radians(60)   # probe poses turn each bone up to this much (the root bone: any rotation)
MAX_PASSES = 8               # fallback: evaluations per frame at most
CONVERGED = 1e-7             # radians: a fallback bone that moved less than this between passes has settled

_fallback_seen: dict[str, tuple[str, ...]] = {}  # armature name -> its fallback bones at the last probe


def fallback_bones(armature_name: str) -> tuple[str, ...]:
    """The bones the last probe of this armature could not learn (the sidebar shows the Exact option then)."""
    return _fallback_seen.get(armature_name, ())


def _uses(ref, obj) -> bool:
    return ref is not None and ref == obj


def read_rotations(pose_bones, index, flat: np.ndarray, prop: str = "matrix") -> np.ndarray:
    """(len(index), 4) rotations of the pose bones at `index` (armature space for "matrix"), as Blender last
    evaluated them: one bulk read into `flat`, a float32 buffer of 16 per pose bone; pose scale dropped."""
    pose_bones.foreach_get(prop, flat)
    # foreach_get flattens each 4x4 column by column
    m = flat.reshape(-1, 4, 4)[index, :3, :3].transpose(0, 2, 1).astype(np.float64)
    m /= np.linalg.norm(m, axis=-2, keepdims=True)
    return normalize(from_matrix(m))


class ArmatureEvaluator:
    """A temporary scene holding a copy of `obj` (object and Armature data) and nothing else; removed by
    close() (a context manager). switches: pose bone -> value for its 'IK_FK' property on the copy (what the
    bake keys); keyed: (bones, root bone) a bake into the rig's current Action keys (see _play_the_rest)."""

    def __init__(self, obj: bpy.types.Object, bone_order, switches: dict[str, float] | None = None,
                 keyed: tuple[tuple[str, ...], str | None] | None = None):
        self.source_name = obj.name
        self.action = None
        self.scene = bpy.data.scenes.new(f"kinect_retarget_probe_{obj.name}")
        self.copy = obj.copy()  # a pose of its own
        # the bones too: the Armature's own drivers (Rigify's B-Bone eases) read the object, and through
        # them the user's rig would be evaluated (and written back) with the copy
        self.copy.data = obj.data.copy()
        try:
            self._prepare(obj, bone_order, switches, keyed)
        except BaseException:  # no temporary scene, object, armature or Action left behind
            self.close()
            raise

    def _prepare(self, obj, bone_order, switches, keyed) -> None:
        if self.copy.animation_data is not None:
            self.copy.animation_data.action = None  # keys would overwrite the poses set here; drivers stay
            if keyed is not None:
                self._play_the_rest(obj, keyed, switches or {})
        self._retarget(obj)
        for name, value in (switches or {}).items():
            self.copy.pose.bones[name]["IK_FK"] = value
        self.scene.collection.objects.link(self.copy)
        self.view_layer = self.scene.view_layers[0]
        self.view_layer.update()
        self.depsgraph = self.view_layer.depsgraph
        pose_names = self.copy.pose.bones.keys()
        where = {n: i for i, n in enumerate(pose_names)}
        self.index = np.array([where[n] for n in bone_order])   # rig order -> pose bone order
        self.flat = np.empty(len(pose_names) * 16, dtype=np.float32)

    def _play_the_rest(self, obj, keyed, switches) -> None:
        """A bake into the Action the rig plays keeps its other channels (a follow property keyed over the
        take, say): the copy plays a copy of it without the channels the bake keys."""
        ad = obj.animation_data
        if ad.action is None or ad.action_slot is None:
            return
        self.action = ad.action.copy()
        slot = next(sl for sl in self.action.slots if sl.identifier == ad.action_slot.identifier)
        channelbag = anim_utils.action_get_channelbag_for_slot(self.action, slot)
        names, root = keyed
        owned = {f'pose.bones["{escape_identifier(b)}"]' for b in names}
        switched = {f'pose.bones["{escape_identifier(b)}"]["IK_FK"]' for b in switches}
        root_path = f'pose.bones["{escape_identifier(root)}"].location' if root else None
        for fc in list(channelbag.fcurves) if channelbag is not None else ():
            bone, _, prop = fc.data_path.rpartition(".")
            if fc.data_path in switched or fc.data_path == root_path or \
                    (bone in owned and prop.startswith("rotation_")):
                channelbag.fcurves.remove(fc)
        self.copy.animation_data.action = self.action
        self.copy.animation_data.action_slot = slot

    def _retarget(self, obj) -> None:
        """Constraints and drivers of the copy that read the original read the copy instead."""
        for pb in self.copy.pose.bones:
            for con in pb.constraints:
                if _uses(getattr(con, "target", None), obj):
                    con.target = self.copy
                for t in getattr(con, "targets", ()):
                    if _uses(getattr(t, "target", None), obj):
                        t.target = self.copy
        for ad in (self.copy.animation_data, self.copy.data.animation_data):
            for fc in ad.drivers if ad is not None else ():
                for var in fc.driver.variables:
                    for t in var.targets:
                        if _uses(t.id, obj):
                            t.id = self.copy

    def close(self) -> None:
        if self.copy is not None:
            data = self.copy.data
            bpy.data.objects.remove(self.copy)
            bpy.data.armatures.remove(data)
            if self.action is not None:
                bpy.data.actions.remove(self.action)
            bpy.data.scenes.remove(self.scene)
            self.copy = self.scene = None

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def basis(self) -> np.ndarray:
        """(B, 4): every bone's pose rotation on the copy (the user's, as they left it), rig order."""
        return read_rotations(self.copy.pose.bones, self.index, self.flat, "matrix_basis")

    def evaluate(self, bone_names, quats: np.ndarray, root_bone: str | None = None,
                 root_location: np.ndarray | None = None, frame: int | None = None) -> np.ndarray:
        """Pose the copy's bones `bone_names` with `quats` (M, 4) (and the root bone's location), evaluate at
        `frame` (None: where the scene is), return every bone's armature-space rotation (B, 4), rig order."""
        pose_bones = self.copy.pose.bones
        set_rotations(pose_bones, bone_names, quats)
        if root_bone is not None and root_location is not None:
            pose_bones[root_bone].location = root_location.tolist()
        if frame is not None and frame != self.scene.frame_current:
            self.scene.frame_set(int(frame))  # drivers and other animation at this frame
        else:
            self.copy.update_tag()
            self.depsgraph.update()
        return read_rotations(self.copy.evaluated_get(self.depsgraph).pose.bones, self.index, self.flat)


def constraint_targets(obj: bpy.types.Object, rig: TargetRig) -> dict[int, list[int]]:
    """Bones with constraints or drivers (rig index) -> the bones of this armature their constraints and
    driver variables name (candidates for what they follow)."""
    out: dict[int, list[int]] = {}

    def add(bone: str, target: str | None = None) -> None:
        if not rig.has(bone):
            return
        found = out.setdefault(rig.index(bone), [])
        if target and rig.has(target) and rig.index(target) not in found and target != bone:
            found.append(rig.index(target))

    for pb in obj.pose.bones:
        for con in pb.constraints:
            add(pb.name)
            if _uses(getattr(con, "target", None), obj):
                add(pb.name, getattr(con, "subtarget", None))
            for t in getattr(con, "targets", ()):
                if _uses(getattr(t, "target", None), obj):
                    add(pb.name, getattr(t, "subtarget", None))
    ad = obj.animation_data
    for fc in ad.drivers if ad is not None else ():
        if fc.data_path.startswith('pose.bones["'):
            bone = fc.data_path.split('"')[1]
            add(bone)
            for var in fc.driver.variables:
                for t in var.targets:
                    if _uses(t.id, obj):
                        add(bone, t.bone_target)
    return out


def random_rotations(rng: np.random.Generator, n: int, max_angle: float) -> np.ndarray:
    axis = normalize(rng.normal(size=(n, 3)))
    return from_axis_angle(axis, rng.uniform(0, max_angle, n))


def probe_parents(evaluator: ArmatureEvaluator, obj: bpy.types.Object, rig: TargetRig, bone_names,
                  root_bone: str | None = None, frames=None, seed: int = 0) -> ParentModel:
    """Pose the copy FIT_POSES + VERIFY_POSES times at random (the verifying poses at frames spread over
    `frames`, so relations that change with time do not verify), and learn the model."""
    rng = np.random.default_rng(seed)
    names = tuple(bone_names)
    n = FIT_POSES + VERIFY_POSES
    poses = np.stack([random_rotations(rng, len(names), MAX_ANGLE) for _ in range(n)])
    if root_bone in names:
        poses[:, names.index(root_bone)] = random_rotations(rng, n, np.pi)
    frames = np.asarray(frames if frames is not None and len(frames) else [bpy.context.scene.frame_current])
    at = np.concatenate([np.full(FIT_POSES, frames[0]),
                         frames[np.linspace(0, len(frames) - 1, VERIFY_POSES).round().astype(int)]])
    user_basis = evaluator.basis()
    evaluated = np.stack([evaluator.evaluate(names, poses[s], root_bone, rng.normal(0, 0.3, 3), int(at[s]))
                          for s in range(n)])
    mapped = [rig.index(b) for b in names]
    model = learn(rig, mapped, user_basis, constraint_targets(obj, rig), poses, evaluated, FIT_POSES)
    _fallback_seen[obj.name] = tuple(model.fallback_names)
    return model


def solve_frames(evaluator: ArmatureEvaluator | None, model: ParentModel, desired: np.ndarray,
                 root_bone: str | None = None, root_location: np.ndarray | None = None, frames=None,
                 progress=None) -> np.ndarray:
    """desired (F, M, 4) -> pose quaternions (F, M, 4), sign-continuous. Learned relations for all frames
    at once; fallback bones are read back from the evaluator frame by frame until they settle."""
    if not model.fallback:
        return make_continuous(model.solve(desired), axis=0)
    names = [model.rig.bone_names[b] for b in model.mapped]
    out = np.empty(desired.shape)
    held = None  # fallback bones' rotations relative to their parents, carried from frame to frame
    for f in range(desired.shape[0]):
        frame = None if frames is None else int(frames[f])
        for _ in range(MAX_PASSES):
            quats = model.solve(desired[f:f + 1], held)
            loc = None if root_location is None else root_location[f]
            evaluated = evaluator.evaluate(names, quats[0], root_bone, loc, frame)
            frame = None
            now = relative_to_parent(model.rig, model.fallback, evaluated[None])
            moved = 0.0 if held is None else max(float(angle_between(now[b], held[b]).max()) for b in now)
            settled = held is not None and moved < CONVERGED
            held = now
            if settled:
                break
        out[f] = model.solve(desired[f:f + 1], held)[0]
        if progress is not None:
            progress(f)
    return make_continuous(out, axis=0)


def solve_baked(obj: bpy.types.Object, rig: TargetRig, motion, switches: dict[str, float] | None = None,
                progress=None, into_current: bool = False) -> ParentModel:
    """The bake on a rig with constrained parents: probe, then motion.quats from motion.extras['desired']
    (the model also lands in motion.extras['parent_model']). The user's scene and rig stay as they were.
    into_current: the keys go into the Action the rig plays, whose other channels then still play."""
    keyed = (tuple(motion.bone_names), motion.root_bone) if into_current else None
    with ArmatureEvaluator(obj, rig.bone_names, switches, keyed) as evaluator:
        model = probe_parents(evaluator, obj, rig, motion.bone_names, motion.root_bone, motion.frames)
        motion.quats = solve_frames(evaluator, model, motion.extras["desired"], motion.root_bone,
                                    motion.root_location, motion.frames, progress)
    motion.extras["parent_model"] = model
    return model


def constrained_summary(model: ParentModel) -> str:
    """One line for the report: what was learned, and which bones Blender evaluates per frame."""
    text = (f"Constrained parents: {len(model.follows)} relations learned and evaluated in numpy "
            f"(worst {model.error_deg:.5f}° from Blender on the probe's poses)")
    if model.fallback:
        text += f"; evaluated by Blender per frame (no relation fits): {', '.join(model.fallback_names)}"
    return text
