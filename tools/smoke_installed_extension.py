"""Install the extension zip into a fresh bpy extension repository, enable it, and stream its simulated Kinect
from the installed copy (what .ci/run checks after `make extension`):

    .venv/bin/python tools/smoke_installed_extension.py dist/kinect_retarget-<version>.zip [--seconds 3]

1. In a child process with its own BLENDER_USER_RESOURCES and depth cache (temporary folders; the user's
   Blender configuration is never touched): install with bpy.ops.extensions.package_install_files, enable,
   and run the sidebar's Simulated Kinect: it renders the package's own MakeHuman body and CMU motion (no
   fallback to the synthetic figure allowed), and live drives a generated rig for --seconds.
2. `python -m kinect_retarget live --source usb --simulate` run from the installed folder.
Prints one line per step; exit 0 when frames arrived in both, 1 otherwise.
"""
from __future__ import annotations

import argparse
import importlib
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

EXT = "bl_ext.user_default.kinect_retarget"
RENDER_WAIT_S = 600   # the first render of 90 frames takes about a minute on one core


def _sidebar_child(zip_path: str, seconds: float) -> dict:
    import bpy  # first: addon_utils only imports after bpy
    import addon_utils

    bpy.ops.extensions.package_install_files(filepath=zip_path, repo="user_default", enable_on_install=True)
    root = Path(bpy.utils.user_resource("EXTENSIONS")) / "user_default" / "kinect_retarget"
    out = {"installed": str(root), "enabled": EXT in bpy.context.preferences.addons}
    assets = importlib.import_module(EXT + ".assets")
    out["assets_in_installed_copy"] = Path(assets.ASSETS_DIR).resolve().is_relative_to(root.resolve())
    usb_panel = importlib.import_module(EXT + ".blender.live.usb_service")
    live = importlib.import_module(EXT + ".blender.live.live_runtime")
    kinect_rig = importlib.import_module(EXT + ".blender.io.kinect_rig")
    layout = importlib.import_module(EXT + ".core.kinect_rig_layout")
    skeletons = importlib.import_module(EXT + ".core.skeletons")

    scene = bpy.context.scene
    scene.kinect_retarget.source = "USB"
    t0 = time.perf_counter()
    scene.kinect_retarget_usb.simulate = True           # prepares the emulated Kinect on a thread
    backend = usb_panel.simulated_backend(wait=RENDER_WAIT_S)
    out["prepare_s"] = round(time.perf_counter() - t0, 1)
    out["simulated"] = usb_panel._rt.sim_label or usb_panel._rt.sim_error
    if backend is None:
        return out
    obj = kinect_rig.build_kinect_rig(scene, skeletons.KINECT_V1,
                                      layout.typical_segment_lengths(skeletons.KINECT_V1), "KinectRig")
    bpy.context.view_layer.objects.active = obj
    s = scene.kinect_retarget
    s.initialised, s.armature, s.preset, s.play_on_record = True, obj, "kinect", False
    c = live.start_live(bpy.context, use_timer=False)
    end = time.perf_counter() + seconds
    while time.perf_counter() < end and live.pump_live():   # timers do not run while a script blocks
        time.sleep(0.005)
    out["stats"] = c.session.statistics()
    out["error"] = c.session.error
    live.stop_live(bake=False)
    addon_utils.disable(EXT, default_set=True)
    return out


def _run(cmd, env, cwd=None) -> tuple[int, str, str]:
    proc = subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=cwd, timeout=RENDER_WAIT_S + 300)
    return proc.returncode, proc.stdout, proc.stderr


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("zip", type=Path)
    ap.add_argument("--seconds", type=float, default=3.0)
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="kr_smoke_") as tmp:
        env = dict(os.environ, BLENDER_USER_RESOURCES=str(Path(tmp) / "blender_user"),
                   KR_DEPTH_CACHE=str(Path(tmp) / "depth_cache"))   # render afresh from the installed assets
        code, out, err = _run([sys.executable, __file__, "--child", str(args.zip.resolve()), str(args.seconds)],
                              env, cwd=tmp)
        lines = [l for l in out.splitlines() if l.startswith("RESULT ")]
        if code != 0 or not lines:
            print(f"sidebar: the child failed (exit {code}):\n{out[-3000:]}\n{err[-3000:]}", file=sys.stderr)
            return 1
        side = json.loads(lines[-1][7:])
        print("sidebar:", json.dumps(side))
        ok = (side["enabled"] and side["assets_in_installed_copy"] and side.get("error") is None
              and str(side["simulated"]).startswith("rendered") and side.get("stats", {}).get("applied", 0) > 0)
        # the headless command from the installed folder (the depth cache is warm now)
        cli_env = dict(env, PYTHONPATH=str(Path(side["installed"]).parent))
        code, where, _ = _run([sys.executable, "-c", "import kinect_retarget; print(kinect_retarget.__file__)"],
                              cli_env, cwd=tmp)
        print("live --source usb --simulate runs", where.strip())
        ok = ok and code == 0 and Path(where.strip()).resolve().is_relative_to(Path(side["installed"]).resolve())
        code, out, err = _run([sys.executable, "-m", "kinect_retarget", "live", "--source", "usb", "--simulate",
                               "--seconds", str(args.seconds)], cli_env, cwd=tmp)
        stats = json.loads(out.strip().splitlines()[-1]) if code == 0 and out.strip() else {}
        print(f"live --source usb --simulate: exit {code}", json.dumps(stats) if stats else err[-2000:])
        ok = ok and code == 0 and stats.get("applied", 0) > 0
    print("installed extension's simulated Kinect:", "streams" if ok else "FAILED")
    return 0 if ok else 1


if __name__ == "__main__":
    if len(sys.argv) == 4 and sys.argv[1] == "--child":
        print("RESULT " + json.dumps(_sidebar_child(sys.argv[2], float(sys.argv[3]))))
    else:
        sys.exit(main())
