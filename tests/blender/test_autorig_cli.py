"""`python -m kinect_retarget autorig` end to end (in-process: the CLI imports bpy itself)."""
import json

import pytest

from kinect_retarget.cli import main


def test_autorig_cli_bakes_and_renders(data_dir, tmp_path, capsys):
    out = tmp_path / "mh.blend"
    code = main(["autorig", str(data_dir / "meshes" / "makehuman" / "base.obj"), "--group", "body",
                 "--out", str(out), "--take", str(data_dir / "kinect_v2" / "Ges04_comehere.csv"),
                 "--render", str(tmp_path / "png"), "--frames", "2"])
    assert code == 0
    summary = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert out.is_file() and summary["frames"] == 172
    assert abs(summary["height_m"] - 1.666) < 0.01  # decimetres became metres
    assert len(summary["renders"]) == 2 and all((tmp_path / "png" / p.split("/")[-1]).is_file()
                                                for p in summary["renders"])
    import bpy
    bpy.ops.wm.open_mainfile(filepath=str(out))
    arm = bpy.data.objects[summary["armature"]]
    assert arm.animation_data.action.name == summary["action"]
    bpy.ops.wm.read_factory_settings(use_empty=True)


@pytest.mark.parametrize("content, message", [(b"v 0 0 0\nv 1 0 0\nv 0 1 0\n", "no faces"),
                                              (b"just text\n", "not a mesh file")])
def test_autorig_cli_bad_input(tmp_path, capsys, content, message):
    src = tmp_path / "thing.obj"
    src.write_bytes(content)
    assert main(["autorig", str(src), "--out", str(tmp_path / "o.blend")]) == 2
    err = capsys.readouterr().err
    assert message in err and "thing.obj" in err and "Traceback" not in err
    assert not (tmp_path / "o.blend").exists()


@pytest.mark.parametrize("fmt", ["glb", "ply"])
def test_blender_exported_files_rig_like_the_source(bpy_empty, data_dir, tmp_path, fmt):
    """GLB (Y-up by the glTF spec) and PLY (Z-up) written by Blender itself load and rig to the same joints."""
    import numpy as np

    from kinect_retarget.autorig import autorig, load_mesh
    from kinect_retarget.blender.mesh_autorig import new_mesh_object
    bpy = bpy_empty
    src = load_mesh(data_dir / "meshes" / "makehuman" / "base.obj", group="body")
    z_up = src.vertices @ np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]], float).T * 0.1
    obj = new_mesh_object("Body", z_up, src.faces, bpy.context.scene.collection)
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj
    path = tmp_path / f"body.{fmt}"
    if fmt == "glb":
        bpy.ops.export_scene.gltf(filepath=str(path), export_format="GLB", use_selection=True)
        expected = src.vertices * 0.1  # glTF is Y-up: back to the OBJ's axes, in metres
    else:
        bpy.ops.wm.ply_export(filepath=str(path), export_selected_objects=True, ascii_format=False)
        expected = z_up
    rig = autorig(load_mesh(path))
    ref = autorig(type(src)(expected, src.faces, "ref"))
    np.testing.assert_allclose(rig.joints, ref.joints, atol=2e-4)


def test_autorig_cli_refuses_levels_that_change_nothing(data_dir, tmp_path, capsys):
    """--levels moves nothing under the fractions rule: refused unless the paper's points are used."""
    out = tmp_path / "o.blend"
    mesh = str(data_dir / "meshes" / "makehuman" / "base.obj")
    assert main(["autorig", mesh, "--group", "body", "--out", str(out), "--levels", "3"]) == 2
    assert "--levels" in capsys.readouterr().err and not out.exists()
    assert main(["autorig", mesh, "--group", "body", "--out", str(out), "--joints", "paper", "--levels", "3",
                 "--paper-skeleton"]) == 0
    summary = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert summary["joint_rule"] == "paper" and summary["paper_skeleton"].endswith("_PaperSkeleton")
    assert len(summary["points_per_level"]) == 3
