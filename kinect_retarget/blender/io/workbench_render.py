"""Headless stills with the Workbench engine: studio light, solid material colours, a floor, and a camera
in front of the character (at -Y, looking +Y, as the performer faced the sensor) framing where it goes.

Workbench needs no GPU compute and renders in bpy as a module, so the demo and the tests can look at
results without a display.
"""
from __future__ import annotations

import math
import os

import bpy
import numpy as np
from mathutils import Matrix

BACKGROUND = (0.93, 0.93, 0.95)
FLOOR_COLOUR = (0.72, 0.73, 0.75, 1.0)


def setup_workbench(scene: bpy.types.Scene, resolution: tuple[int, int] = (640, 480),
                    note: str | None = None) -> None:
    """Workbench, studio light, material colours, soft shadows and a light background; PNG output.

    note: text burnt into the image's bottom-left corner with the frame number (None: no stamp)."""
    render = scene.render
    render.engine = "BLENDER_WORKBENCH"
    render.resolution_x, render.resolution_y = resolution
    render.resolution_percentage = 100
    render.film_transparent = False
    settings = render.image_settings
    settings.file_format = "PNG"
    settings.color_mode = "RGB"
    settings.compression = 90  # small files for docs/; PNG stays lossless
    render.dither_intensity = 0.0  # dither noise would triple the PNG size for no visible gain
    scene.view_settings.view_transform = "Standard"  # keep the solid colours as chosen
    scene.display.render_aa = "8"
    shading = scene.display.shading
    shading.light = "STUDIO"
    shading.studio_light = "paint.sl"        # the brightest built-in studio set: clear solid colours
    shading.use_world_space_lighting = True  # light the floor from above, not from the camera
    shading.color_type = "MATERIAL"
    shading.show_shadows = True
    shading.shadow_intensity = 0.35
    shading.show_cavity = False  # cavity quadruples PNG size and doubles render time for little gain here
    scene.display.light_direction = (0.35, -0.45, 0.82)  # from above, in front, a little to the side
    world = scene.world or bpy.data.worlds.new("World")
    scene.world = world
    world.color = BACKGROUND
    render.use_stamp = note is not None
    if note is not None:
        for field in ("date", "time", "render_time", "camera", "lens", "scene", "filename", "memory",
                      "hostname", "frame_range", "marker", "sequencer_strip"):
            setattr(render, f"use_stamp_{field}", False)
        render.use_stamp_frame = True
        render.use_stamp_note = True
        render.stamp_note_text = note
        render.stamp_font_size = 14


def evaluated_bounds(objects, frames) -> tuple[np.ndarray, np.ndarray]:
    """World-space (min, max) corners of the evaluated (posed, deformed) meshes over the given frames."""
    scene = bpy.context.scene
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    for frame in frames:  # a handful of frames: the ones being rendered
        scene.frame_set(int(frame))
        depsgraph = bpy.context.evaluated_depsgraph_get()
        for obj in objects:
            ob_eval = obj.evaluated_get(depsgraph)
            mesh = ob_eval.to_mesh()
            try:
                co = np.empty(len(mesh.vertices) * 3, np.float32)
                mesh.vertices.foreach_get("co", co)
            finally:
                ob_eval.to_mesh_clear()
            if co.size == 0:
                continue
            world = np.array(ob_eval.matrix_world, dtype=np.float64)
            pts = co.reshape(-1, 3) @ world[:3, :3].T + world[:3, 3]
            lo, hi = np.minimum(lo, pts.min(axis=0)), np.maximum(hi, pts.max(axis=0))
    if not np.all(np.isfinite(lo)):
        raise ValueError("nothing to frame: the objects have no vertices")
    return lo, hi


def add_floor(scene: bpy.types.Scene, lo: np.ndarray, hi: np.ndarray, name: str = "Floor") -> bpy.types.Object:
    """A grey square under the character at its lowest point, reaching past the camera's view."""
    centre = (lo + hi) / 2
    half = max(20.0, 10.0 * float(np.max(hi - lo)))
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([(-half, -half, 0.0), (half, -half, 0.0), (half, half, 0.0), (-half, half, 0.0)],
                     [], [(0, 1, 2, 3)])
    mat = bpy.data.materials.get("KR_floor") or bpy.data.materials.new("KR_floor")
    mat.diffuse_color = FLOOR_COLOUR
    mesh.materials.append(mat)
    floor = bpy.data.objects.new(name, mesh)
    floor.location = (centre[0], centre[1], lo[2])
    scene.collection.objects.link(floor)
    return floor


def look_from(direction: np.ndarray, up=(0.0, 0.0, 1.0)) -> np.ndarray:
    """3x3 camera rotation whose view axis (local -Z) points along `direction`, local +Y as close to up."""
    f = np.asarray(direction, dtype=np.float64)
    f = f / np.linalg.norm(f)
    r = np.cross(f, up)
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    return np.stack([r, u, -f], axis=1)


def frame_camera(scene: bpy.types.Scene, lo: np.ndarray, hi: np.ndarray, azimuth_deg: float = 0.0,
                 elevation_deg: float = 10.0, lens_mm: float = 50.0, margin: float = 1.12,
                 name: str = "DemoCamera") -> bpy.types.Object:
    """Put a camera in front of the character (at -Y, rotated by azimuth about Z, raised by elevation)
    at the distance where the whole box lo..hi fits the frame with `margin`; make it the scene camera."""
    az, el = math.radians(azimuth_deg), math.radians(elevation_deg)
    to_camera = np.array([math.sin(az) * math.cos(el), -math.cos(az) * math.cos(el), math.sin(el)])
    rot = look_from(-to_camera)
    centre = (lo + hi) / 2
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    rel = corners - centre
    x, y, depth = rel @ rot[:, 0], rel @ rot[:, 1], rel @ -rot[:, 2]
    aspect = scene.render.resolution_x / scene.render.resolution_y
    tan_x = 18.0 / lens_mm if aspect >= 1 else 18.0 / lens_mm * aspect  # 36 mm sensor fitted to the long side
    tan_y = tan_x / aspect
    distance = float(np.max(np.maximum(margin * np.abs(x) / tan_x, margin * np.abs(y) / tan_y) - depth))
    cam_data = bpy.data.cameras.get(name) or bpy.data.cameras.new(name)
    cam_data.lens = lens_mm
    cam_data.sensor_fit = "AUTO"
    cam_data.sensor_width = 36.0
    cam_data.clip_end = max(100.0, 4 * distance)
    cam = bpy.data.objects.get(name)
    if cam is None:
        cam = bpy.data.objects.new(name, cam_data)
        scene.collection.objects.link(cam)
    matrix = np.eye(4)
    matrix[:3, :3] = rot
    matrix[:3, 3] = centre + to_camera * distance
    cam.matrix_world = Matrix(matrix.tolist())
    scene.camera = cam
    return cam


def render_still(scene: bpy.types.Scene, filepath: str, frame: int | None = None) -> str:
    """Render one frame to a PNG (directories created); returns the absolute path."""
    if scene.camera is None:
        raise ValueError("the scene has no camera to render from")
    if frame is not None:
        scene.frame_set(int(frame))
    path = os.path.abspath(filepath)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True, scene=scene.name)
    return path


def stage(scene: bpy.types.Scene, meshes, frames, note: str | None = None,
          resolution: tuple[int, int] = (640, 480), azimuth_deg: float = 0.0) -> None:
    """Workbench settings, a floor, and a camera framing `meshes` over `frames`: ready to render."""
    setup_workbench(scene, resolution, note)
    lo, hi = evaluated_bounds(meshes, frames)
    add_floor(scene, lo, hi)
    frame_camera(scene, lo, hi, azimuth_deg=azimuth_deg)


def stage_and_render(scene: bpy.types.Scene, meshes, frames, directory: str, stem: str,
                     note: str | None = None, resolution: tuple[int, int] = (640, 480),
                     azimuth_deg: float = 0.0) -> list[str]:
    """stage(), then one PNG per frame named <stem>_f<frame>.png in `directory`. Returns the paths."""
    stage(scene, meshes, frames, note, resolution, azimuth_deg)
    return [render_still(scene, os.path.join(directory, f"{stem}_f{int(f):04d}.png"), f) for f in frames]


def _load_pixels(path: str) -> np.ndarray:
    """(H, W, 4) float pixels of a PNG, top row first."""
    image = bpy.data.images.load(path, check_existing=False)
    try:
        w, h = image.size
        pixels = np.empty(w * h * 4, np.float32)
        image.pixels.foreach_get(pixels)
    finally:
        bpy.data.images.remove(image)
    return pixels.reshape(h, w, 4)[::-1]


def contact_sheet(paths: list[str], out_path: str, step: int = 2) -> str:
    """The stills side by side in one PNG, each shrunk by `step` (every step-th pixel: flat colours keep
    their look), so a take's motion can be seen at a glance. Returns the absolute path."""
    tiles = [_load_pixels(p)[::step, ::step] for p in paths]
    height = min(t.shape[0] for t in tiles)
    sheet = np.concatenate([t[:height] for t in tiles], axis=1)
    h, w = sheet.shape[:2]
    image = bpy.data.images.new(os.path.basename(out_path), w, h, alpha=False)
    try:
        image.pixels.foreach_set(np.ascontiguousarray(sheet[::-1]).ravel())
        image.filepath_raw = os.path.abspath(out_path)
        image.file_format = "PNG"
        os.makedirs(os.path.dirname(image.filepath_raw), exist_ok=True)
        image.save()
    finally:
        bpy.data.images.remove(image)
    return os.path.abspath(out_path)
