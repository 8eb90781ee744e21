"""Monocular video -> 3D takes (paper 004): 2D joint tracks in, a Kinect v1 take out. Pure numpy.

    tracks = read_2d("run1_json/", "openpose", image_size=(1920, 1080))
    result = lift(tracks, LiftSettings(focal_px=1500, height_m=1.75))
    result.take  # -> the engine, like any recorded take; result.problems lists skipped bad input
"""
from __future__ import annotations

import os

from .lifter import LiftResult, LiftSettings, lift
from .tracks2d import LiftError, Tracks2D

FORMATS = ("openpose", "coco", "clip")


def detect_2d_format(path: str) -> str:
    if os.path.isdir(path):
        return "openpose"
    low = path.lower()
    if low.endswith(".json"):
        return "coco"
    if low.endswith(".blend"):
        return "clip"
    raise LiftError(f"{path}: cannot tell the 2D format (a folder of OpenPose files, a COCO .json or a "
                    f".blend with a tracked Movie Clip); pass --format")


def read_2d(path: str | os.PathLike, fmt: str = "auto", fps: float = 30.0, image_size=None) -> Tracks2D:
    """Keypoint files -> Tracks2D on the Kinect v1 joints ("clip" needs Blender: blender/clip_lift.py)."""
    path = os.fspath(path)
    if not os.path.exists(path):
        raise LiftError(f"{path}: no such file or folder")
    fmt = detect_2d_format(path) if fmt == "auto" else fmt
    if fmt == "openpose":
        from . import openpose
        return openpose.read(path, fps, image_size)
    if fmt == "coco":
        from . import coco
        return coco.read(path, fps, image_size)
    raise LiftError(f"format {fmt!r} is not read here (known: openpose, coco; clip through Blender)")


__all__ = ["lift", "LiftSettings", "LiftResult", "LiftError", "Tracks2D", "read_2d", "FORMATS",
           "detect_2d_format"]
