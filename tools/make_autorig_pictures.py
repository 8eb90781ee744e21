"""Regenerate the pictures of docs/autorig.md (Workbench, headless):

    .venv/bin/python tools/make_autorig_pictures.py

1. skeleton.png: MakeHuman's base mesh (CC0), see-through, with the extracted Kinect joints and bones (red)
   and the paper's skeleton points (blue); 2. take_f*.png: the auto-rigged mesh driven by a real Kinect v2
   recording (Kinectron, MIT; sample_takes/kinect_v2_kinectron_recorded_skeleton.krtake).
"""
from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
HERE = REPO / "docs" / "autorig"
sys.path.insert(0, str(REPO))
SAMPLE_TAKES = REPO / "sample_takes"

import bpy  # noqa: E402

from kinect_retarget.assets import MAKEHUMAN_DIR  # noqa: E402
from kinect_retarget.autorig import Mesh, autorig, load_mesh  # noqa: E402
from kinect_retarget.autorig.orient import upright_transform  # noqa: E402
from kinect_retarget.blender.mesh_autorig import autorig_to_file, new_mesh_object  # noqa: E402
from kinect_retarget.blender.io.workbench_render import render_still, stage  # noqa: E402
from kinect_retarget.takes import load_take  # noqa: E402


def material(name, rgba):
    m = bpy.data.materials.new(name)
    m.diffuse_color = rgba
    return m


def markers(points, radius, mat, name):
    """One mesh of small octahedra at the points (cheap spheres for Workbench)."""
    base = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], float) * radius
    tri = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])
    verts = (points[:, None, :] + base[None]).reshape(-1, 3)
    faces = (tri[None] + 6 * np.arange(len(points))[:, None, None]).reshape(-1, 3)
    obj = new_mesh_object(name, verts, faces, bpy.context.scene.collection)
    obj.data.materials.append(mat)
    return obj


def sticks(a, b, radius, mat, name):
    """Thin square prisms from a to b (bones)."""
    verts, faces = [], []
    for p, q in zip(a, b):
        d = q - p
        n = np.cross(d, [0, 0, 1.0]) if abs(d[2]) < 0.9 * np.linalg.norm(d) else np.cross(d, [1.0, 0, 0])
        n = n / np.linalg.norm(n) * radius
        m = np.cross(d / np.linalg.norm(d), n)
        ring = [n, m, -n, -m]
        k = len(verts)
        verts += [p + r for r in ring] + [q + r for r in ring]
        faces += [[k + i, k + (i + 1) % 4, k + 4 + i] for i in range(4)]
        faces += [[k + (i + 1) % 4, k + 4 + (i + 1) % 4, k + 4 + i] for i in range(4)]
    obj = new_mesh_object(name, np.array(verts), np.array(faces), bpy.context.scene.collection)
    obj.data.materials.append(mat)
    return obj


def transformed(points: np.ndarray, m: np.ndarray) -> np.ndarray:
    """(N, 3) points through the 4x4 transform m."""
    return points @ m[:3, :3].T + m[:3, 3]


def skeleton_picture(mesh: Mesh, rig, m: np.ndarray) -> None:
    """rig: autorig(mesh); m: its upright transform (4x4)."""
    to_world = lambda p: transformed(p, m)  # noqa: E731
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    body = new_mesh_object("Body", to_world(mesh.vertices), mesh.faces, scene.collection)
    body.data.materials.append(material("skin", (0.85, 0.82, 0.78, 1.0)))
    joints = to_world(rig.joints)
    red, blue = material("joints", (0.85, 0.1, 0.1, 1.0)), material("paper", (0.1, 0.3, 0.9, 1.0))
    markers(joints, 0.018, red, "Joints")
    parents = np.array(rig.skeleton.parents)
    kids = np.flatnonzero(parents >= 0)
    sticks(joints[parents[kids]], joints[kids], 0.006, red, "Bones")
    paper_pts = to_world(rig.paper.points)
    markers(paper_pts, 0.011, blue, "PaperPoints")
    shading = scene.display.shading
    stage(scene, [body], [1], note="auto-rig: Kinect joints (red), paper 003 skeleton points (blue)")
    shading.show_xray = True
    shading.xray_alpha = 0.35
    render_still(scene, str(HERE / "skeleton.png"), 1)


def main() -> None:
    mesh = load_mesh(MAKEHUMAN_DIR / "base.obj", group="body")
    rig = autorig(mesh)
    m = upright_transform(mesh.vertices, np.asarray(rig.features.up), np.asarray(rig.features.front),
                          rig.height, rig.joints[0])
    skeleton_picture(mesh, rig, m)
    take = load_take(SAMPLE_TAKES / "kinect_v2_kinectron_recorded_skeleton.krtake")  # the Kinectron recording
    take.metadata.setdefault("name", "recorded_skeleton")
    out = autorig_to_file(Mesh(transformed(mesh.vertices, m), mesh.faces, "MakeHuman"),
                          "/tmp/autorig_demo.blend", take=take, render_dir=str(HERE), frames=4)
    for i, path in enumerate(out["renders"]):
        os.replace(path, HERE / f"take_{i + 1}.png")
    print(out["summary"])


if __name__ == "__main__":
    main()
