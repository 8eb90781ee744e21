"""One undo step for the bake that runs when a recording stops: live's operators push none (live must not
fill the undo stack with poses), so without this the baked Action and its assignment would merge into
whatever the user did next, and Ctrl+Z right after would take back more than the bake."""
from __future__ import annotations

import bpy

from .window_context import in_window

BAKE_STEP = "Bake Kinect Recording"


def push_undo_step(message: str = BAKE_STEP) -> bool:
    """Push the current state as an undo step named `message` (from timers too, which have no window in their
    context). False when Blender has no undo stack to push to (e.g. while a file loads)."""
    try:
        in_window(lambda: bpy.ops.ed.undo_push(message=message))
    except RuntimeError:
        return False
    return True
