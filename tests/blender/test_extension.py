"""The installable extension: build the zip, install it into the bpy module's extension repository, enable,
bake a sample take through the operator, disable; and registration cycles leave nothing behind.

Installing runs in a child process with its own BLENDER_USER_RESOURCES, so the user's real Blender
configuration is never touched and the package can be imported under its extension name.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import threading
import zipfile
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
SAMPLE = REPO / "sample_takes" / "kinect_v2_ges01_wavehand.krtake"
EXT = "bl_ext.user_default.kinect_retarget"


@pytest.fixture(scope="module")
def extension_zip(tmp_path_factory):
    sys.path.insert(0, str(REPO / "tools"))
    try:
        import build_extension
    finally:
        sys.path.pop(0)
    # a fresh wheel cache: the test proves the download works and never writes to ~/.cache
    saved = os.environ.get("KINECT_RETARGET_WHEEL_CACHE")
    os.environ["KINECT_RETARGET_WHEEL_CACHE"] = str(tmp_path_factory.mktemp("wheel_cache"))
    try:
        return build_extension.build(tmp_path_factory.mktemp("dist"))
    except build_extension.BuildError as exc:
        pytest.fail(f"extension build failed: {exc}")
    finally:
        if saved is None:
            del os.environ["KINECT_RETARGET_WHEEL_CACHE"]
        else:
            os.environ["KINECT_RETARGET_WHEEL_CACHE"] = saved


def test_zip_has_manifest_package_and_every_platforms_wheels(extension_zip):
    import tomllib
    with zipfile.ZipFile(extension_zip) as zf:
        names = set(zf.namelist())
        manifest = tomllib.loads(zf.read("blender_manifest.toml").decode())
    assert extension_zip.name == f"kinect_retarget-{manifest['version']}.zip"
    assert {"__init__.py", "blender/registration.py", "live/session.py", "sources/osc_receiver.py"} <= names
    package = Path(__file__).resolve().parents[2] / "kinect_retarget"
    subpackages = {str(f.relative_to(package)) for f in package.rglob("__init__.py")}
    assert subpackages <= names, sorted(subpackages - names)   # every subpackage ships
    # the simulated Kinect's body and motion travel in the zip, with their credits and licences
    assert {"assets/__init__.py", "assets/CREDITS.md", "assets/makehuman/base.obj", "assets/makehuman/default.mhskel",
            "assets/makehuman/default_weights.mhw", "assets/makehuman/LICENSE.ASSETS.md", "assets/motion/131_03.bvh",
            "assets/motion/LICENSE.bvh11.txt"} <= names
    assert extension_zip.stat().st_size < 20 * 1024 * 1024   # the README states its size (a few MB)
    assert not any("__pycache__" in n for n in names)
    listed = {w.removeprefix("./") for w in manifest["wheels"]}
    assert listed == {n for n in names if n.startswith("wheels/")}
    assert any(w.startswith("wheels/pyusb-") for w in listed)
    for plat in ("win_amd64", "macosx_11_0_arm64", "macosx_10_9_x86_64", "manylinux2014_x86_64"):
        assert any(w.startswith("wheels/libusb_package-") and plat in w for w in listed), plat
    assert manifest["id"] == "kinect_retarget" and manifest["blender_version_min"] == "5.0.0"
    assert set(manifest["permissions"]) >= {"files", "network"}


def test_install_enable_bake_disable_in_the_bpy_extension_repository(extension_zip, tmp_path):
    assert SAMPLE.is_file(), f"sample take missing: {SAMPLE}"
    real_install = Path.home() / ".config" / "blender" / "5.0" / "extensions" / "user_default" / "kinect_retarget"
    before = real_install.exists()
    env = dict(os.environ, BLENDER_USER_RESOURCES=str(tmp_path / "blender_user"))
    proc = subprocess.run([sys.executable, __file__, "--child", str(extension_zip), str(SAMPLE)],
                          capture_output=True, text=True, env=env, timeout=300)
    lines = [l for l in proc.stdout.splitlines() if l.startswith("RESULT ")]
    assert proc.returncode == 0 and lines, f"child failed:\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}"
    result = json.loads(lines[-1][7:])
    assert result["installed"] and result["enabled"]
    assert result["prefs"] == [7000, False, "TAKE"]  # add-on preferences registered under the extension id
    assert result["bake"] == ["FINISHED"] and result["keys"] > 100
    assert result["after_disable"] == {"classes": [], "timers": False, "handlers": [], "threads": []}
    assert result["after_cycles"] == {"classes": [], "timers": False, "handlers": [], "threads": []}
    assert real_install.exists() == before, "the test installed into the user's real Blender configuration"
    assert (tmp_path / "blender_user").is_dir()  # it went to the child's own BLENDER_USER_RESOURCES


def test_register_unregister_three_times_leaves_nothing(data_dir, tmp_path):
    """In process, the plain package: cycles with live running in between."""
    import bpy
    import kinect_retarget
    from kinect_retarget.blender.live import live_runtime as live
    from kinect_retarget.blender.io.kinect_rig import build_kinect_rig
    from kinect_retarget.core.kinect_rig_layout import median_segment_lengths
    from kinect_retarget.takes import load_take

    take = load_take(SAMPLE)
    for _ in range(3):
        kinect_retarget.register()
        bpy.ops.wm.read_factory_settings(use_empty=True)
        obj = build_kinect_rig(bpy.context.scene, take.skeleton, median_segment_lengths(take), "Rig")
        bpy.context.view_layer.objects.active = obj
        s = bpy.context.scene.kinect_retarget
        s.source, s.take_path, s.loop, s.initialised = "TAKE", str(SAMPLE), True, True
        live.start_live(bpy.context, use_timer=True)
        live.pump_live()
        assert bpy.app.timers.is_registered(live._timer) and leftovers(bpy)["threads"]
        kinect_retarget.unregister()  # add-on disable while live: must stop everything
        assert leftovers(bpy) == {"classes": [], "timers": False, "handlers": [], "threads": []}


def leftovers(bpy, timer_fns=()) -> dict:
    """What the add-on could leave behind: registered classes, the live timer, app handlers, threads."""
    classes = [name for name in dir(bpy.types) if name.startswith(("KINECT_RETARGET_", "KinectRetarget"))]
    handlers = [f.__module__ for name in dir(bpy.app.handlers) if not name.startswith("_")
                for f in (getattr(bpy.app.handlers, name) if isinstance(getattr(bpy.app.handlers, name), list)
                          else []) if "kinect_retarget" in getattr(f, "__module__", "")]
    fns = list(timer_fns) + [sys.modules[n]._timer for n in list(sys.modules)
                             if n.endswith("kinect_retarget.blender.live.live_runtime")]
    timers = any(bpy.app.timers.is_registered(f) for f in fns)
    threads = [t.name for t in threading.enumerate() if t.name.startswith("kinect_retarget") and t.is_alive()]
    return {"classes": classes, "timers": timers, "handlers": handlers, "threads": threads}


def _child(zip_path: str, take_path: str) -> None:
    import importlib

    import bpy  # first: addon_utils only imports after bpy
    import addon_utils

    out = {}
    bpy.ops.extensions.package_install_files(filepath=zip_path, repo="user_default", enable_on_install=True)
    out["installed"] = os.path.isfile(os.path.join(bpy.utils.user_resource("EXTENSIONS"), "user_default",
                                                   "kinect_retarget", "blender_manifest.toml"))
    out["enabled"] = EXT in bpy.context.preferences.addons
    prefs = bpy.context.preferences.addons[EXT].preferences
    out["prefs"] = [prefs.osc_port, prefs.osc_listen_all, prefs.default_source]
    pkg = importlib.import_module(EXT)
    rig_mod = importlib.import_module(EXT + ".blender.io.kinect_rig")
    layout = importlib.import_module(EXT + ".core.kinect_rig_layout")
    take = importlib.import_module(EXT + ".takes").load_take(take_path)
    obj = rig_mod.build_kinect_rig(bpy.context.scene, take.skeleton, layout.median_segment_lengths(take), "Rig")
    bpy.context.view_layer.objects.active = obj
    out["bake"] = sorted(bpy.ops.kinect_retarget.bake_take(filepath=take_path))
    ad = obj.animation_data
    cb = ad.action.layers[0].strips[0].channelbag(ad.action_slot)
    out["keys"] = sum(len(fc.keyframe_points) for fc in cb.fcurves)
    # live through the installed package, then disable while it runs
    s = bpy.context.scene.kinect_retarget
    s.source, s.take_path, s.loop, s.initialised = "TAKE", take_path, True, True
    live = importlib.import_module(EXT + ".blender.live.live_runtime")
    live.start_live(bpy.context, use_timer=True)
    live.pump_live()
    timer = live._timer
    assert bpy.app.timers.is_registered(timer) and live.controller() is not None
    assert any(t.name.startswith("kinect_retarget") for t in threading.enumerate())
    addon_utils.disable(EXT, default_set=True)
    out["after_disable"] = leftovers(bpy, [timer])
    for _ in range(3):
        addon_utils.enable(EXT, default_set=True)
        addon_utils.disable(EXT, default_set=True)
    out["after_cycles"] = leftovers(bpy, [timer])
    del pkg
    print("RESULT " + json.dumps(out))


if __name__ == "__main__" and len(sys.argv) == 4 and sys.argv[1] == "--child":
    _child(sys.argv[2], sys.argv[3])
