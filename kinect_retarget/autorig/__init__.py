"""Auto-rigging of character meshes (paper 003), pure numpy: skeleton extraction, Kinect joint naming and
skin weights. Blender-side wrapping lives in kinect_retarget/blender/mesh_autorig.py."""
from .auto_rigger import AutoRig, autorig
from .mesh import Mesh, MeshError, load_mesh

__all__ = ["AutoRig", "autorig", "Mesh", "MeshError", "load_mesh"]
