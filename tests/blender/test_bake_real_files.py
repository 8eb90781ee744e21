"""Real files as they come, through Blender: the MSRC-12-shaped file (microsecond counter, 20 leading empty
rows) bakes; a take with a few NaN joints bakes with a warning from the CLI and the Bake Take operator."""
from __future__ import annotations

import json
import subprocess
import sys


from kinect_retarget.takes import load_take
from tests.takes import real_layout_fixtures as real


def _broken_copy(tmp_path):
    """The MSRC-12 fixture with two bad joint values on line 31 (NaN and inf)."""
    lines = real.MSRC12_REAL.read_text().splitlines(keepends=True)
    fields = lines[30].split(" ")
    fields[1], fields[9] = "nan", "inf"
    lines[30] = " ".join(fields)
    path = tmp_path / "P1_1_1_broken.csv"
    path.write_text("".join(lines))
    return path


def _bake(take, out):
    return subprocess.run([sys.executable, "-m", "kinect_retarget", "bake", str(take), "--out", str(out)],
                          capture_output=True, text=True)


def test_cli_bakes_msrc12_real_layout(tmp_path):
    r = _bake(real.MSRC12_REAL, tmp_path / "msrc.blend")
    assert r.returncode == 0, r.stderr
    result = json.loads(r.stdout.strip().splitlines()[-1])
    # 60 frames with a body, keyed from scene frame 21: the 20 empty rows before them keep their time
    assert result["frames"] == 60 and result["frame_range"] == [21, 80] and result["dropped_joint_samples"] == 0
    assert (tmp_path / "msrc.blend").is_file() and "warning" not in r.stderr


def test_cli_bakes_take_with_nan_joints_with_a_warning(tmp_path):
    path = _broken_copy(tmp_path)
    r = _bake(path, tmp_path / "broken.blend")
    assert r.returncode == 0, r.stderr
    assert f"warning: {path}:31: 2 joint samples in 1 frame were NaN, infinite or farther than 20 m" in r.stderr
    result = json.loads(r.stdout.strip().splitlines()[-1])
    assert result["frames"] == 60 and result["dropped_joint_samples"] == 2
    info = subprocess.run([sys.executable, "-m", "kinect_retarget", "info", str(path), "--json"],
                          capture_output=True, text=True, check=True)
    summary = json.loads(info.stdout)
    assert summary["dropped_joint_samples"] == 2 and summary["first_dropped"] == "line 31"
    assert summary["time_unit"] == "µs" and "first at line 31" in summary["warnings"][0]


def test_operator_reports_dropped_samples(registered, tmp_path, capfd):
    from kinect_retarget.blender.bake_take import new_generated_rig
    bpy = registered
    path = _broken_copy(tmp_path)
    obj = new_generated_rig(bpy.context.scene, load_take(path))
    bpy.context.view_layer.objects.active = obj
    capfd.readouterr()
    assert bpy.ops.kinect_retarget.bake_take(filepath=str(path), preset="kinect",
                                             set_scene_fps=True) == {"FINISHED"}
    out = capfd.readouterr()
    assert "2 joint samples in 1 frame were NaN" in out.out + out.err and "first at line 31" in out.out + out.err
    assert obj.animation_data.action is not None
    # keys at the take's rate from its first frame with a body; the scene's range is left as it was
    assert tuple(obj.animation_data.action.frame_range) == (21, 80)
    assert (bpy.context.scene.frame_start, bpy.context.scene.frame_end) == (1, 250)


def test_bake_take_reports_reader_warnings(bpy_empty, tmp_path):
    """The function behind the operator hands the reader's warnings to its report callback."""
    from kinect_retarget.blender.bake_take import bake_take, new_generated_rig
    take = load_take(_broken_copy(tmp_path))
    obj = new_generated_rig(bpy_empty.context.scene, take)
    reports = []
    bake_take(obj, take, preset="kinect", report=lambda level, msg: reports.append((sorted(level), msg)))
    warnings = [m for level, m in reports if level == ["WARNING"]]
    assert len(warnings) == 1 and "first at line 31" in warnings[0]
