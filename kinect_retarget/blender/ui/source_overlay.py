"""The source skeleton in the 3D View, beside each character at the sidebar's offset: while live, each
performer's newest frame; otherwise the sidebar's take (when the source is a take) at the scene's frame. So a
user sees at once whether a glitch is the sensor's or the retarget's.

The geometry is core/skeleton_overlay.py's (pure numpy); this module gathers the frames (`overlay_geometries`,
which headless tests call) and draws them with Blender's `gpu` module from one POST_VIEW draw handler,
added in register_extra() and removed in unregister_extra(). Drawing never raises into the viewport.
"""
from __future__ import annotations

import os

import bpy
import numpy as np

from ...core.skeleton_overlay import OverlayGeometry, OverlayPlacement, skeleton_overlay
from ...core.take import TakeError
from ...takes import load_take
from ..live import live_runtime
from .performers import other_performers
from .properties import target_armature

LINE_WIDTH = 3.0
POINT_SIZE = 9.0

_handle = None
_placements: dict[int, OverlayPlacement] = {}   # per live session: where its performer stands
_takes: dict = {}                              # (path, mtime, body) -> (take, placement) or the load error


def overlay_geometries(context) -> list[OverlayGeometry]:
    """What the draw handler draws now (empty when the sidebar's toggle is off or there is nothing to show)."""
    scene = context.scene
    s = getattr(scene, "kinect_retarget", None)
    if s is None or not s.show_source:
        return []
    offset = np.asarray(s.source_offset, dtype=np.float64)
    c = live_runtime.controller()
    if c is not None:
        return _live_geometries(c, offset)
    _placements.clear()
    if s.source != "TAKE" or not s.take_path:
        return []
    path = bpy.path.abspath(s.take_path)
    target = target_armature(context)
    fps = scene.render.fps / scene.render.fps_base
    seconds = (scene.frame_current - scene.frame_start) / fps  # the take starts at the scene's start
    out = []
    for obj, body in ([(target, s.body)] if target is not None else []) + other_performers(scene):
        loaded = loaded_take(path, body)
        if isinstance(loaded, str):
            continue
        take, placement = loaded
        i = int(np.clip(np.searchsorted(take.times, take.times[0] + seconds - 0.5 / take.rate), 0,
                        take.frame_count - 1))
        out.append(skeleton_overlay(take.skeleton, take.positions[i], take.states[i], _origin(obj) + offset,
                                    placement))
    return out


def _live_geometries(c, offset: np.ndarray) -> list[OverlayGeometry]:
    out = []
    for ctrl in (c, *c.followers):
        frame, obj = ctrl.session.last_frame, ctrl.obj()
        if ctrl.finished or frame is None or obj is None:
            continue
        placement = _placements.setdefault(id(ctrl.session), OverlayPlacement())
        out.append(skeleton_overlay(ctrl.session.source.skeleton, frame.positions, frame.states,
                                    _origin(obj) + offset, placement))
    return out


def loaded_take(path: str, body: int):
    """(take, placement) of body `body` of the take file, cached while the file is unchanged; or the reason
    it cannot be shown (a sentence)."""
    try:
        key = (path, os.path.getmtime(path), body)
    except OSError:
        return f"take file {path} does not exist"
    if key not in _takes:
        if len(_takes) > 8:
            _takes.clear()
        try:
            take = load_take(path, body=body)
            _takes[key] = (take, OverlayPlacement.for_take(take.skeleton, take.positions, take.states))
        except (TakeError, OSError) as exc:
            _takes[key] = str(exc)
    return _takes[key]


def _origin(obj) -> np.ndarray:
    return np.array(obj.matrix_world.translation, dtype=np.float64)


def _draw() -> None:
    try:
        geometries = [g for g in overlay_geometries(bpy.context) if not g.empty]
        if geometries:
            _draw_gpu(geometries)
    except Exception as exc:  # a draw callback must never break the viewport; say it once per message
        if getattr(_draw, "last_error", None) != str(exc):
            _draw.last_error = str(exc)  # type: ignore[attr-defined]
            print(f"kinect_retarget: source skeleton not drawn: {exc}")


def _draw_gpu(geometries: list[OverlayGeometry]) -> None:
    """Lines with POLYLINE_FLAT_COLOR (uniforms viewportSize, lineWidth) and joints with POINT_FLAT_COLOR (uniform
    size), Blender 5.0's builtin names (gpu_py_shader.cc). The point shader's `size` only counts with program
    point size on (as Blender's own point drawing does); every state changed here is put back afterwards."""
    import gpu
    from gpu_extras.batch import batch_for_shader
    region = bpy.context.region
    viewport = (region.width, region.height) if region is not None else tuple(gpu.state.viewport_get()[2:])
    lines = gpu.shader.from_builtin("POLYLINE_FLAT_COLOR")
    points = gpu.shader.from_builtin("POINT_FLAT_COLOR")
    blend, depth, width = gpu.state.blend_get(), gpu.state.depth_test_get(), gpu.state.line_width_get()
    gpu.state.blend_set("ALPHA")
    gpu.state.depth_test_set("NONE")  # in front of the character, like an armature's In Front
    gpu.state.program_point_size_set(True)
    try:
        for g in geometries:
            if len(g.lines):
                lines.bind()
                lines.uniform_float("viewportSize", viewport)
                lines.uniform_float("lineWidth", LINE_WIDTH)
                batch_for_shader(lines, "LINES", {"pos": _f32(g.lines), "color": _f32(g.line_colors)}).draw(lines)
            points.bind()
            points.uniform_float("size", POINT_SIZE)
            batch_for_shader(points, "POINTS", {"pos": _f32(g.points), "color": _f32(g.point_colors)}).draw(points)
    finally:
        gpu.state.program_point_size_set(False)
        gpu.state.line_width_set(width)
        gpu.state.depth_test_set(depth)
        gpu.state.blend_set(blend)


def _f32(a: np.ndarray) -> np.ndarray:
    """A vertex buffer fills from an array's raw bytes (no conversion): float32, contiguous."""
    return np.ascontiguousarray(a, dtype=np.float32)


def draw_settings(layout, s) -> None:
    """The sidebar's toggle and offset."""
    row = layout.row(align=True)
    row.prop(s, "show_source", icon="OUTLINER_DATA_ARMATURE")
    if s.show_source:
        layout.prop(s, "source_offset", text="Offset")


def handler_registered() -> bool:
    return _handle is not None


def register_extra() -> None:
    global _handle
    if _handle is None:
        _handle = bpy.types.SpaceView3D.draw_handler_add(_draw, (), "WINDOW", "POST_VIEW")


def unregister_extra() -> None:
    global _handle
    if _handle is not None:
        bpy.types.SpaceView3D.draw_handler_remove(_handle, "WINDOW")
        _handle = None
    _placements.clear()
    _takes.clear()
