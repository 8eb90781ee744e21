"""Pure numpy core: no bpy, no mathutils. Importable and testable without Blender."""
