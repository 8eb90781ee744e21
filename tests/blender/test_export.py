"""`bake --out take.fbx | take.glb | take.bvh`: each file is imported back with Blender's own importer and its
limb directions (parent joint -> joint, world space) are compared with the baked rig's and the take's."""
import subprocess
import sys

import numpy as np
import pytest

from kinect_retarget.core.bake_options import BakeOptions
from kinect_retarget.core.conventions import kinect_to_blender
from kinect_retarget.core.pipeline import RetargetSettings
from kinect_retarget.takes import load_take

TAKE = "sample_takes/kinect_v2_ges06_chickenwing.krtake"
FRAMES = 40  # the take's first 40 frames: enough motion, quick to export and import


def _limbs(obj):
    """(bone, child) pairs whose heads give each limb's direction: the generated rig's bone J runs from J's
    parent joint to joint J, where its children start (the root's stub bone has no length of its own)."""
    pairs = []
    for bone in obj.data.bones:
        if bone.children and (bone.children[0].head_local - bone.head_local).length > 0.01:
            pairs.append((bone.name, bone.children[0].name))
    return pairs


def _directions(bpy, obj, pairs, frames):
    scene = bpy.context.scene
    out = np.empty((len(frames), len(pairs), 3))
    for i, f in enumerate(frames):
        scene.frame_set(int(f))
        mw = obj.matrix_world
        for k, (a, b) in enumerate(pairs):
            d = np.array(mw @ obj.pose.bones[b].head) - np.array(mw @ obj.pose.bones[a].head)
            out[i, k] = d / np.linalg.norm(d)
    return out


def _angle(a, b):
    return np.degrees(np.arccos(np.clip(np.sum(a * b, -1), -1, 1)))


def _import(bpy, path, fps):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.fps, scene.render.fps_base = fps, 1.0  # the importers place keys by the scene's rate
    ext = path.suffix
    if ext == ".fbx":
        # the FBX holds the keys at their scene times; the importer's default anim_offset (1) would shift them
        bpy.ops.import_scene.fbx(filepath=str(path), anim_offset=0.0)
    elif ext == ".glb":
        bpy.ops.import_scene.gltf(filepath=str(path))
    else:
        # Blender's BVH exporter writes its own Z-up axes (docs/export.md): read them back as such
        bpy.ops.import_anim.bvh(filepath=str(path), update_scene_fps=False, update_scene_duration=True,
                                axis_forward="Y", axis_up="Z")
    return next(o for o in scene.objects if o.type == "ARMATURE")


@pytest.fixture(scope="module")
def baked(tmp_path_factory):
    """The take baked onto the generated rig by the CLI's bake_to_file, saved as .blend."""
    import bpy
    from kinect_retarget.blender.headless import bake_to_file
    take = load_take(TAKE).slice(slice(0, FRAMES))
    take.metadata["name"] = "chickenwing"
    out = tmp_path_factory.mktemp("export")
    summary = bake_to_file(take, str(out / "take.blend"), settings=RetargetSettings(filter="none"),
                           options=BakeOptions(feet="off"))  # the take's own limb directions
    obj = bpy.data.objects[summary["armature"]]
    frames = np.arange(summary["frame_range"][0], summary["frame_range"][1] + 1)
    pairs = _limbs(obj)
    ref = _directions(bpy, obj, pairs, frames)
    # the take's own limbs at the same frames (at the take's rate every sample keys its frame)
    sk = take.skeleton
    p = kinect_to_blender(take.positions)
    src = np.stack([p[:, sk.index(a)] - p[:, sk.parents[sk.index(a)]] for a, _ in pairs], 1)
    src /= np.linalg.norm(src, axis=-1, keepdims=True)
    yield {"take": take, "dir": out, "frames": frames, "pairs": pairs, "ref": ref, "src": src,
           "fps": bpy.context.scene.render.fps, "summary": summary}
    bpy.ops.wm.read_factory_settings(use_empty=True)


@pytest.mark.parametrize("ext", [".fbx", ".glb", ".bvh"])
def test_exported_file_reimports_with_the_takes_limb_directions(baked, ext):
    import bpy
    from kinect_retarget.blender.headless import bake_to_file
    path = baked["dir"] / f"take{ext}"
    summary = bake_to_file(baked["take"], str(path), settings=RetargetSettings(filter="none"),
                           options=BakeOptions(feet="off"))  # the take's own limb directions
    assert path.is_file() and summary["frame_range"] == baked["summary"]["frame_range"]
    obj = _import(bpy, path, baked["fps"])
    names = {b.name for b in obj.data.bones}
    pairs = baked["pairs"]
    assert {a for a, _ in pairs} <= names, sorted({a for a, _ in pairs} - names)
    frames = baked["frames"]
    if ext == ".glb":  # glTF animations start at frame 0 on import unless the file says otherwise
        frames = frames - frames[0] + int(obj.animation_data.action.frame_range[0])
    got = _directions(bpy, obj, pairs, frames)
    vs_rig = _angle(got, baked["ref"])
    vs_take = _angle(got, baked["src"])
    print(f"{ext}: limb direction vs baked rig max {vs_rig.max():.4f}°, vs take mean {vs_take.mean():.4f}° "
          f"max {vs_take.max():.4f}° ({len(pairs)} limbs x {len(frames)} frames)")
    assert vs_rig.max() <= 0.1
    assert vs_take.max() <= 0.1


def test_cli_exports_and_refuses_unknown_extensions(tmp_path):
    out = tmp_path / "take.fbx"
    r = subprocess.run([sys.executable, "-m", "kinect_retarget", "bake", TAKE, "--out", str(out),
                        "--take-end", "1.0"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert out.stat().st_size > 10_000 and '"frame_range": [1, 30]' in r.stdout  # 1 s of a 30 fps take
    r = subprocess.run([sys.executable, "-m", "kinect_retarget", "bake", TAKE, "--out", str(tmp_path / "t.obj")],
                       capture_output=True, text=True)
    assert r.returncode == 2 and "cannot write .obj" in r.stderr and "Traceback" not in r.stderr
