"""Where users find the add-on (File > Import, Object > Animation > Kinect Retarget: the menus F3 searches),
what the manifest declares, and OSC reaching other machines only with Blender's online access."""
from __future__ import annotations

import tomllib
from pathlib import Path
from types import SimpleNamespace

import pytest

REPO = Path(__file__).resolve().parents[2]


class _Layout:
    """Records what a menu's draw() puts in it."""
    def __init__(self):
        self.items = []

    def operator(self, idname, text="", icon="NONE"):
        self.items.append(("operator", idname, text))

    def menu(self, idname, text="", icon="NONE"):
        self.items.append(("menu", idname, text))

    def separator(self):
        pass


def _draw(func):
    layout = _Layout()
    func(SimpleNamespace(layout=layout), None)
    return layout.items


def _appended(menu):
    import bpy
    return getattr(getattr(bpy.types, menu).draw, "_draw_funcs", [])


def test_menus_hold_every_operator_and_go_away_on_unregister(registered):
    bpy = registered
    from kinect_retarget.blender.ui import menus
    anim = [f for f in _appended("VIEW3D_MT_object_animation") if f.__module__ == menus.__name__]
    imp = [f for f in _appended("TOPBAR_MT_file_import") if f.__module__ == menus.__name__]
    assert len(anim) == 1 and len(imp) == 1
    assert _draw(anim[0]) == [("menu", "KINECT_RETARGET_MT_animation", "")]
    assert _draw(imp[0]) == [("operator", "kinect_retarget.bake_take", "Kinect Take (bake onto a rig)")]
    items = _draw(bpy.types.KINECT_RETARGET_MT_animation.draw)
    ops = [i[1] for i in items]
    assert ops == ["kinect_retarget.live_start", "kinect_retarget.live_stop", "kinect_retarget.record",
                   "kinect_retarget.calibrate", "kinect_retarget.bake_take", "kinect_retarget.autorig_mesh"]
    for op in ops:  # each entry is a registered operator
        group, name = op.split(".")
        assert getattr(getattr(bpy.ops, group), name).get_rna_type().identifier.startswith("KINECT_RETARGET")
    import kinect_retarget
    kinect_retarget.unregister()
    try:
        assert not [f for f in _appended("VIEW3D_MT_object_animation") if f.__module__ == menus.__name__]
        assert not [f for f in _appended("TOPBAR_MT_file_import") if f.__module__ == menus.__name__]
    finally:
        kinect_retarget.register()  # the fixture unregisters


def test_manifest_declares_contact_website_copyright_and_camera():
    manifest = tomllib.loads((REPO / "blender_manifest.toml").read_text())
    assert "<" in manifest["maintainer"] and "@" in manifest["maintainer"]
    assert manifest["website"].startswith("https://")
    assert manifest["copyright"] and all(c[:4].isdigit() for c in manifest["copyright"])
    perms = manifest["permissions"]
    assert {"files", "network", "camera"} <= set(perms)
    for reason in perms.values():  # Blender's rules: short, no trailing period
        assert len(reason) <= 64 and not reason.endswith(".")


@pytest.mark.parametrize("listen_all, online, host, refused", [
    (False, True, "127.0.0.1", False), (True, False, "127.0.0.1", True), (True, True, "0.0.0.0", False)])
def test_osc_other_machines_only_with_online_access(bpy_empty, listen_all, online, host, refused):
    from kinect_retarget.blender.live.osc_access import osc_host
    got, reason = osc_host(SimpleNamespace(osc_listen_all=listen_all), online=online)
    assert got == host and (reason is not None) == refused
    if refused:
        assert "Allow Online Access" in reason
    assert osc_host(None, online=True) == ("127.0.0.1", None)


def test_osc_source_binds_loopback_while_online_access_is_off(bpy_empty, monkeypatch):
    bpy = bpy_empty
    from kinect_retarget.blender.live import live_runtime
    assert bpy.app.online_access is False  # headless bpy: no online access
    monkeypatch.setattr(live_runtime, "get_preferences", lambda context: SimpleNamespace(osc_listen_all=True))
    context = SimpleNamespace(scene=SimpleNamespace(kinect_retarget=SimpleNamespace(source="OSC", osc_port=7123)))
    source, label = live_runtime.source_from_scene(context)
    assert source.host == "127.0.0.1" and "this computer only" in label
