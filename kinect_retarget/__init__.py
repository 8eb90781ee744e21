"""kinect_retarget: Kinect (live or recorded) motion onto any humanoid rig in Blender.

Importing the package never imports bpy, so the core, the take readers and the device code work in plain
Python. Blender calls register()/unregister(), which load the bpy side lazily.
"""

__version__ = "0.1.0"


def register() -> None:
    from .blender import registration
    registration.register()


def unregister() -> None:
    from .blender import registration
    registration.unregister()
