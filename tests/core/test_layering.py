"""Nothing outside kinect_retarget/blender/ imports Blender modules; the package imports bpy lazily."""
import ast
from pathlib import Path

BLENDER_MODULES = {"bpy", "mathutils", "bpy_extras", "bmesh", "addon_utils", "bl_math", "gpu"}
PACKAGE = Path(__file__).resolve().parents[2] / "kinect_retarget"


def _imports(path: Path, top_level_only: bool):
    tree = ast.parse(path.read_text(encoding="utf-8"))
    nodes = tree.body if top_level_only else ast.walk(tree)
    for node in nodes:
        if isinstance(node, ast.Import):
            yield from (a.name.split(".")[0] for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            yield node.module.split(".")[0]


def test_no_blender_imports_outside_blender_package():
    offenders = []
    for path in PACKAGE.rglob("*.py"):
        rel = path.relative_to(PACKAGE)
        if rel.parts[0] == "blender":
            continue
        # the package __init__ may import inside register(); everything else not at all
        found = set(_imports(path, top_level_only=rel.name == "__init__.py" and len(rel.parts) == 1))
        if found & BLENDER_MODULES:
            offenders.append(f"{rel}: {sorted(found & BLENDER_MODULES)}")
    assert not offenders, "Blender imports outside kinect_retarget/blender/: " + "; ".join(offenders)


PURE_PACKAGES = ("core", "takes", "device", "sources", "live", "depth", "autorig", "lift", "sim")


def _relative_targets(path: Path):
    """Absolute module names of a file's relative imports (`from ..blender import x` -> kinect_retarget.blender)."""
    rel = path.relative_to(PACKAGE.parent).with_suffix("")
    package = list(rel.parts[:-1])
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and node.level > 0:
            base = package[: len(package) - node.level + 1]
            yield ".".join(base + ([node.module] if node.module else []))


def test_pure_packages_never_reach_the_blender_package():
    offenders = []
    for pkg in PURE_PACKAGES:
        for path in (PACKAGE / pkg).rglob("*.py"):
            bad = [t for t in _relative_targets(path) if t.startswith("kinect_retarget.blender")]
            if bad:
                offenders.append(f"{path.relative_to(PACKAGE)}: {bad}")
    assert not offenders, "bpy-free packages importing kinect_retarget.blender: " + "; ".join(offenders)


def _all_targets(path: Path):
    """Absolute names of every import in a file, relative or absolute, at any depth; `from X import y` gives
    X and X.y (y may be a module)."""
    package = list(path.relative_to(PACKAGE.parent).with_suffix("").parts[:-1])
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            yield from (a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = package[: len(package) - node.level + 1] if node.level else []
            module = ".".join(base + ([node.module] if node.module else []))
            yield module
            yield from (f"{module}.{a.name}" for a in node.names)


# the simulated Kinect is a product feature reached through this one module; nothing else ships sim/ code paths
SIM_ENTRY_POINT = Path("sources/simulated_kinect.py")


def test_only_sim_and_the_simulated_device_entry_point_import_sim():
    offenders = []
    for path in PACKAGE.rglob("*.py"):
        rel = path.relative_to(PACKAGE)
        if rel.parts[0] == "sim" or rel == SIM_ENTRY_POINT:
            continue
        bad = [t for t in _all_targets(path) if t == "kinect_retarget.sim" or t.startswith("kinect_retarget.sim.")]
        if bad:
            offenders.append(f"{rel}: {bad}")
    assert not offenders, "modules outside sim/ importing sim/: " + "; ".join(offenders)


def test_core_imports_without_bpy():
    import subprocess
    import sys
    code = ("import sys, kinect_retarget, kinect_retarget.core.pipeline, kinect_retarget.takes;"
            "assert 'bpy' not in sys.modules and 'mathutils' not in sys.modules")
    subprocess.run([sys.executable, "-c", code], check=True, cwd=PACKAGE.parent)


# Downward only (docs/architecture.md): which other top-level packages each bpy-free package may import.
# assets/ is data with its paths (no imports of its own), so any layer may find its files through it.
# (sources/ reaches sim/ only through the simulated-device entry point, checked above.)
ALLOWED = {"core": {"assets"}, "takes": {"core"}, "device": {"core"}, "depth": {"core", "device", "assets"},
           "lift": {"core", "takes"}, "autorig": {"core", "takes"},
           "sources": {"core", "takes", "device", "depth", "assets", "sim"},
           "live": {"core", "takes", "sources"},
           "sim": {"core", "takes", "device", "depth", "lift", "autorig", "assets"}}


def test_packages_import_only_the_layers_below_them():
    offenders = []
    for pkg, allowed in ALLOWED.items():
        for path in (PACKAGE / pkg).rglob("*.py"):
            for target in _all_targets(path):
                parts = target.split(".")
                if parts[0] != "kinect_retarget" or len(parts) < 2:
                    continue
                other = parts[1]
                if other != pkg and (PACKAGE / other).is_dir() and other not in allowed:
                    offenders.append(f"{path.relative_to(PACKAGE)} imports {target}")
    assert not offenders, "imports against the layer order: " + "; ".join(sorted(set(offenders)))


def test_no_imports_from_name_strings():
    """The checks above read import statements: a module imported from a name string (importlib, __import__)
    would slip past them, and a missing one can be skipped silently. Imports are static everywhere."""
    offenders = []
    for path in PACKAGE.rglob("*.py"):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            dynamic = (isinstance(node, ast.Import) and any(a.name.split(".")[0] == "importlib" for a in node.names)
                       or isinstance(node, ast.ImportFrom) and (node.module or "").split(".")[0] == "importlib"
                       or isinstance(node, ast.Call) and isinstance(node.func, ast.Name)
                       and node.func.id == "__import__")
            if dynamic:
                offenders.append(f"{path.relative_to(PACKAGE)}:{node.lineno}")
    assert not offenders, "imports from name strings: " + ", ".join(offenders)
