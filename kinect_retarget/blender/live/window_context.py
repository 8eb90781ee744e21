"""Timers run with no window in their context, but some operators (undo_push, timeline playback) want one:
run a function with the first window (and its screen) in the context when the context has none."""
from __future__ import annotations

from typing import Callable, TypeVar

import bpy

T = TypeVar("T")


def in_window(fn: Callable[[], T]) -> T:
    context = bpy.context
    wm = context.window_manager
    if context.window is not None or wm is None or not len(wm.windows):
        return fn()
    window = wm.windows[0]
    with context.temp_override(window=window, screen=window.screen):
        return fn()
