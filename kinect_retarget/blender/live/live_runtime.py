"""The one running live controller: start, pump, stop, status. Sources run on threads; everything here runs on
the main thread.

A `bpy.app.timers` callback pumps the controller (drain, filter, retarget, record, pose the rig). Headless code
(the `live` command, tests) calls `pump_live()` itself, since timers do not fire while a script blocks.
`start_live(context, source, settings, overrides)` takes everything it needs as arguments; the sidebar's
operators build those from the scene with `source_from_scene` and `settings_from_scene`.
"""
from __future__ import annotations

import os

import bpy
from bpy.app.handlers import persistent

from ...core.pipeline import RetargetSettings
from ...sources import SourceError, TakePlayback, open_source
from ...sources.body_fanout import BodyFanout, BodySource
from ..ui.mapping_table import table_overrides
from ..ui.performers import other_performers
from ..ui.preferences import get_preferences
from ..ui.properties import ensure_defaults, target_armature
from .live_controller import LiveController, LiveSettings
from .osc_access import osc_host

TIMER_INTERVAL = 1 / 120  # pump often: latency is arrival -> applied, and an empty pump costs microseconds

_controller: LiveController | None = None
_last_status: dict = {"state": "idle", "message": "", "error": None, "stats": None}


def redraw_3d_views() -> None:
    """Tag every 3D viewport for a redraw (live and the USB panel's depth preview)."""
    wm = getattr(bpy.context, "window_manager", None)
    if wm is None:
        return
    for window in wm.windows:
        for area in window.screen.areas:
            if area.type == "VIEW_3D":
                area.tag_redraw()


def _timer():
    c = _controller
    if c is None:
        return None
    try:
        alive = c.pump()
    except Exception as exc:  # never let a timer die with live half-running
        c.session.stop(f"unexpected {type(exc).__name__}: {exc}")
        c.finish()
        alive = False
    if not alive:
        return None
    redraw_3d_views()
    return TIMER_INTERVAL


def _finished(c: LiveController) -> None:
    """Every stop path ends here (LiveController.finish calls it): status, the running slot, the timer."""
    global _controller
    session = c.session
    _last_status.update(state="error" if session.error else "idle", message=c.message,
                        error=session.error or c.last_error or _last_status.get("error"),
                        stats=session.statistics())
    if _controller is c:
        _controller = None
    if bpy.app.timers.is_registered(_timer):
        bpy.app.timers.unregister(_timer)
    redraw_3d_views()


# -- the sidebar's choices ------------------------------------------------------------------------------------
def performers_from_scene(context) -> tuple[int, list[tuple]]:
    """(the target's body, [(armature, body)] of the sidebar's other performers that name an armature)."""
    return context.scene.kinect_retarget.body, other_performers(context.scene)


def source_from_scene(context) -> tuple:
    """The source the sidebar names, not started, and its label for messages."""
    s = context.scene.kinect_retarget
    if s.source == "TAKE":
        if not s.take_path:
            raise SourceError("choose a take file to play")
        body, others = performers_from_scene(context)
        return open_source(f"take:{bpy.path.abspath(s.take_path)}", speed=s.speed, loop=s.loop,
                           bodies=tuple({body, *(b for _, b in others)})), f"take {os.path.basename(s.take_path)}"
    if s.source == "OSC":
        host, refused = osc_host(get_preferences(context))
        return open_source(f"osc:{s.osc_port}", host=host), \
            f"OSC port {s.osc_port}" + (" (this computer only: online access is off)" if refused else "")
    from .usb_service import live_usb_source   # frees the device from the panel's preview; simulated if chosen
    return live_usb_source(context)


def settings_from_scene(context) -> tuple[LiveSettings, dict | None]:
    """The sidebar's live settings and its mapping table (as overrides)."""
    s = context.scene.kinect_retarget
    prefs = get_preferences(context)
    settings = LiveSettings(preset=s.preset,
                            retarget=RetargetSettings(filter=s.filter, root_mode=s.root, mirror=s.mirror),
                            exact_constrained=bool(s.exact_constrained), bake_on_stop=None, hands=s.hands,
                            lost_tracking_timeout=prefs.lost_tracking_timeout if prefs is not None else 2.0)
    return settings, table_overrides(s)


# -- the functions operators, the CLI and tests call ----------------------------------------------------------
def start_live(context, source=None, settings: LiveSettings | None = None, overrides=None, *, armature=None,
               use_timer: bool = True, body: int | None = None, followers=None) -> LiveController:
    """Start live on `armature` (default: the sidebar's target) from `source` with `settings` and mapping
    `overrides`; a None source or settings is taken from the sidebar. `body` (default: the sidebar's) is the
    performer this rig follows; `followers` [(armature, body)] (default: the sidebar's other performers when
    the source is the sidebar's) drive more rigs from the same source, one body each, with the same settings
    and their preset's mapping. Raises SourceError/ValueError with a user sentence, with the rigs left as
    they were."""
    global _controller
    if _controller is not None:
        raise SourceError("live is already running")
    scene = context.scene
    obj = armature if armature is not None else target_armature(context)
    if obj is None:
        raise ValueError("pick a target armature (or make one active) first")
    if settings is None or source is None:
        ensure_defaults(scene, context)
    if settings is None:
        settings, overrides = settings_from_scene(context)
    label = source.describe() if source is not None else ""
    if body is None or (followers is None and source is None):
        ensure_defaults(scene, context)
        scene_body, scene_followers = performers_from_scene(context)
        body = scene_body if body is None else body
        followers = scene_followers if followers is None and source is None else followers
    followers = list(followers or [])
    if len({body, *(b for _, b in followers)}) != 1 + len(followers):
        raise ValueError("each performer drives one rig: give every target its own body")
    if len({obj.name, *(o.name for o, _ in followers)}) != 1 + len(followers):
        raise ValueError("each rig follows one performer: pick a different armature for every target")
    if source is None:
        source, label = source_from_scene(context)
    follower_controllers: list[LiveController] = []
    if followers or body:  # one source, several bodies: each rig's session sees its own body's frames
        fanout = BodyFanout(source)
        source = fanout.body(body)
        follower_controllers = [LiveController(scene, o, fanout.body(b), settings, None, f"{label} body {b}")
                                for o, b in followers]
    controller = LiveController(scene, obj, source, settings, overrides, label, on_finish=_finished)
    controller.followers = follower_controllers
    controller.start()
    _controller = controller
    _last_status.update(state="running", message=controller.message, error=None, stats=None)
    if use_timer and not bpy.app.timers.is_registered(_timer):
        bpy.app.timers.register(_timer, first_interval=0.0)
    return controller


def pump_live() -> bool:
    """One main-thread step, for loops that block (the timer does the same)."""
    c = _controller
    return c.pump() if c is not None else False


def stop_live(bake: bool | None = None, context=None) -> None:
    """Stop live; `bake` None follows the live settings (by default the scene's Bake on Stop)."""
    if _controller is not None:
        _controller.finish(bake=bake, context=context)


def controller() -> LiveController | None:
    return _controller


def status() -> dict:
    """For the panel: state, message, error, fps, tracked joints, statistics."""
    c = _controller
    if c is None:
        return dict(_last_status)
    src = c.session.source
    return {"state": "recording" if c.recording else "running", "message": c.message,
            "error": src.error, "warning": src.warning, "stats": c.session.statistics(),
            "tracked": c.session.last_tracked_joints, "joints": len(src.skeleton),
            "calibrating": c.session.calibrating, "device": getattr(src, "device_status", None),
            "progress": (src.position + 1, src.take.frame_count) if isinstance(_shared(src), TakePlayback) else None,
            "recording": c.recording["path"] if c.recording else None,
            "performers": [(c.obj_name, c.body)] + [(f.obj_name, f.body) for f in c.followers if not f.finished]}


def _shared(src):
    """The source itself, also behind one body's view of it."""
    return src.fanout.source if isinstance(src, BodySource) else src


def set_error_status(message: str) -> None:
    """A start that failed before live ran: the panel shows why."""
    _last_status.update(state="error", error=message, message=message)


@persistent
def _on_save_pre(*_args) -> None:
    # the armature copy of Exact on Constrained Rigs must not be saved: it comes back on the next frame
    if _controller is not None:
        _controller.release_evaluator()


@persistent
def _on_load_pre(*_args) -> None:
    # the scene is about to be replaced: end the thread, keep the recording file, bake nothing
    stop_live(bake=False)


def register_extra() -> None:
    if _on_load_pre not in bpy.app.handlers.load_pre:
        bpy.app.handlers.load_pre.append(_on_load_pre)
    if _on_save_pre not in bpy.app.handlers.save_pre:
        bpy.app.handlers.save_pre.append(_on_save_pre)


def unregister_extra() -> None:
    stop_live(bake=False)
    if _on_load_pre in bpy.app.handlers.load_pre:
        bpy.app.handlers.load_pre.remove(_on_load_pre)
    if _on_save_pre in bpy.app.handlers.save_pre:
        bpy.app.handlers.save_pre.remove(_on_save_pre)
    if bpy.app.timers.is_registered(_timer):
        bpy.app.timers.unregister(_timer)
