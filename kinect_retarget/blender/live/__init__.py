"""Live in Blender (main thread only): the controller, its timer and handlers, and the USB device service."""
