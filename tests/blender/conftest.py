"""Fixtures for tests that use the real bpy 5.0.1 wheel. bpy is imported inside fixtures only."""
from __future__ import annotations

import pytest


@pytest.fixture
def bpy_empty():
    """A fresh empty scene (factory settings) for each test."""
    import bpy
    bpy.ops.wm.read_factory_settings(use_empty=True)
    yield bpy
    bpy.ops.wm.read_factory_settings(use_empty=True)


@pytest.fixture
def registered(bpy_empty):
    """The add-on registered from the working tree, unregistered afterwards."""
    import kinect_retarget
    kinect_retarget.register()
    yield bpy_empty
    kinect_retarget.unregister()


@pytest.fixture(scope="session")
def rigify_rig_path(tmp_path_factory):
    """A Rigify rig generated headless from Blender's human metarig, saved once per session."""
    import bpy  # noqa: I001 (addon_utils is importable only after bpy)
    import addon_utils
    bpy.ops.wm.read_factory_settings(use_empty=True)
    addon_utils.enable("rigify", default_set=True)  # after the factory reset, which would disable it
    bpy.ops.object.armature_human_metarig_add()
    bpy.ops.pose.rigify_generate()
    path = tmp_path_factory.mktemp("rigs") / "rigify.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.read_factory_settings(use_empty=True)
    return path
