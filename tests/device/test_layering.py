"""The device layer is pure numpy/pyusb: no Blender modules anywhere in it."""
import ast
from pathlib import Path

import kinect_retarget

PACKAGE = Path(kinect_retarget.__file__).parent
FORBIDDEN = {"bpy", "mathutils", "bpy_extras", "bmesh"}


def test_device_code_imports_no_blender_module():
    files = sorted((PACKAGE / "device").glob("*.py")) + [PACKAGE / "cli_device.py"]
    assert len(files) > 10
    for path in files:
        for node in ast.walk(ast.parse(path.read_text(), str(path))):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else \
                [node.module or ""] if isinstance(node, ast.ImportFrom) and node.level == 0 else []
            for name in names:
                assert name.split(".")[0] not in FORBIDDEN, f"{path.name} imports {name}"
