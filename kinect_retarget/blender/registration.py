"""One ordered class list; unregister undoes everything in mirror order. Feature modules under blender/
expose their own CLASSES and optional register_extra()/unregister_extra() hooks (timers, handlers)."""
from __future__ import annotations

from importlib import import_module

import bpy

# Modules in registration order (property groups before the classes that point at them).
MODULES = ("operators",)
OPTIONAL_MODULES = ("preferences", "properties", "live", "mapping_ui", "panels", "usb_panel", "autorig_op", "lift_op")

_registered: list = []
_hooks: list = []


def _modules():
    mods = [import_module(f".{m}", __package__) for m in MODULES]
    for name in OPTIONAL_MODULES:
        try:
            mods.append(import_module(f".{name}", __package__))
        except ModuleNotFoundError as exc:
            if exc.name != f"{__package__}.{name}":  # a real import error inside the module
                raise
    return mods


def register() -> None:
    for mod in _modules():
        for cls in getattr(mod, "CLASSES", ()):
            bpy.utils.register_class(cls)
            _registered.append(cls)
        hook = getattr(mod, "register_extra", None)
        if hook:
            hook()
            _hooks.append(mod)


def unregister() -> None:
    while _hooks:
        _hooks.pop().unregister_extra()
    while _registered:
        bpy.utils.unregister_class(_registered.pop())
