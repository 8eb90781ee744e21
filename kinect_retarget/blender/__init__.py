"""Everything that touches bpy. Nothing outside this package imports bpy or mathutils."""
