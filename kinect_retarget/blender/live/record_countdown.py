"""A countdown before recording starts, for a performer who must walk from the keyboard into the sensor's
view: shown in the sidebar and the 3D View header, cancelled by Record (again) or by stopping live."""
from __future__ import annotations

import math
import time
from typing import Callable

import bpy

COUNTDOWN_ITEMS = [("0", "Off", "Record at once"), ("3", "3 s", "Count down 3 seconds before recording"),
                   ("5", "5 s", "Count down 5 seconds before recording"),
                   ("10", "10 s", "Count down 10 seconds before recording")]
TICK = 0.1  # seconds between timer ticks: the header's number changes on time

clock = time.monotonic  # tests replace it
_state: dict = {"end": None, "on_done": None}


def remaining() -> float | None:
    """Seconds left, or None when no countdown runs."""
    return None if _state["end"] is None else max(0.0, _state["end"] - clock())


def label() -> str:
    left = remaining()
    return "" if left is None else f"Recording in {math.ceil(left)}…"


def _redraw() -> None:
    wm = bpy.context.window_manager
    for window in (wm.windows if wm is not None else ()):
        for area in window.screen.areas:
            if area.type == "VIEW_3D":
                area.tag_redraw()


def tick() -> float | None:
    """One timer step: start the recording when time is up. Returns the next interval (None: done)."""
    if _state["end"] is None:
        return None
    _redraw()
    if clock() < _state["end"]:
        return TICK
    on_done = _state["on_done"]
    cancel()
    on_done()
    return None


def start(seconds: float, on_done: Callable[[], None], use_timer: bool = True) -> None:
    cancel()
    _state.update(end=clock() + float(seconds), on_done=on_done)
    if use_timer:
        bpy.app.timers.register(tick, first_interval=TICK)
    _redraw()


def cancel() -> bool:
    """Stop a running countdown (nothing is recorded). True when one ran."""
    running = _state["end"] is not None
    _state.update(end=None, on_done=None)
    if bpy.app.timers.is_registered(tick):
        bpy.app.timers.unregister(tick)
    if running:
        _redraw()
    return running


def draw_header(self, context) -> None:
    """3D View header: the countdown, big enough to read from across the room."""
    text = label()
    if text:
        row = self.layout.row()
        row.alert = True
        row.label(text=text, icon="REC")


def register_extra() -> None:
    bpy.types.VIEW3D_HT_header.append(draw_header)


def unregister_extra() -> None:
    cancel()
    bpy.types.VIEW3D_HT_header.remove(draw_header)
