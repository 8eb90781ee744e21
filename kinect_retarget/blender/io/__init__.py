"""Between numpy and Blender data: read a rig, write keys in bulk, set a pose, solve on evaluated parents,
build the generated rig, render stills."""
