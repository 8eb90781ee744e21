"""Build the installable extension: dist/kinect_retarget-<version>.zip (`make extension`).

The zip holds blender_manifest.toml and the package's files at its root, and wheels/ with the unmodified
PyPI wheels the manifest lists, so users install from disk with nothing to pip. Blender's own extension
builder (bl_pkg/cli/blender_ext.py, shipped in the bpy wheel) validates the manifest and writes the zip.

Wheels are downloaded once with pip into a cache (KINECT_RETARGET_WHEEL_CACHE, default
~/.cache/kinect_retarget/wheels); the manifest's file names pin name, version and platform.
"""
from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import tomllib
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
PACKAGE = REPO / "kinect_retarget"
MANIFEST = REPO / "blender_manifest.toml"
WHEEL_NAME = re.compile(r"^(?P<dist>[A-Za-z0-9_.]+)-(?P<ver>[^-]+)-(?P<py>[^-]+)-(?P<abi>[^-]+)-(?P<plat>[^-]+)\.whl$")


class BuildError(RuntimeError):
    pass


def package_version() -> str:
    text = (PACKAGE / "__init__.py").read_text(encoding="utf-8")
    m = re.search(r'^__version__\s*=\s*"([^"]+)"', text, re.M)
    if not m:
        raise BuildError("kinect_retarget/__init__.py has no __version__")
    return m.group(1)


def read_manifest() -> dict:
    with open(MANIFEST, "rb") as fh:
        manifest = tomllib.load(fh)
    if manifest.get("version") != package_version():
        raise BuildError(f"blender_manifest.toml version {manifest.get('version')!r} differs from "
                         f"kinect_retarget.__version__ {package_version()!r}")
    return manifest


def blender_ext_script() -> Path:
    import importlib.util
    spec = importlib.util.find_spec("bpy")
    if spec is None or not spec.submodule_search_locations:
        raise BuildError("the bpy module is needed for Blender's extension builder (use .venv/bin/python)")
    root = Path(list(spec.submodule_search_locations)[0])
    hits = sorted(root.glob("*/scripts/addons_core/bl_pkg/cli/blender_ext.py"))
    if not hits:
        raise BuildError(f"blender_ext.py not found under {root}")
    return hits[-1]


DOWNLOAD_TIMEOUT = 300  # seconds for one wheel


def wheel_cache() -> Path:
    return Path(os.environ.get("KINECT_RETARGET_WHEEL_CACHE", Path.home() / ".cache" / "kinect_retarget" / "wheels"))


def fetch_wheel(filename: str, cache: Path) -> Path:
    """The exact wheel file, from the cache or PyPI (pip download, binary only, no dependencies)."""
    target = cache / filename
    if target.is_file():
        return target
    m = WHEEL_NAME.match(filename)
    if not m:
        raise BuildError(f"manifest wheel {filename!r} is not a wheel file name")
    cache.mkdir(parents=True, exist_ok=True)
    cmd = [sys.executable, "-m", "pip", "download",
           "--timeout", "30", "--retries", "2",   # an unreachable index fails in minutes, never hangs
           "--quiet", "--no-deps", "--only-binary=:all:",
           "--python-version", "3.11", "--dest", str(cache), f"{m['dist']}=={m['ver']}"]
    if m["plat"] != "any":
        cmd += [arg for plat in m["plat"].split(".") for arg in ("--platform", plat)]
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=DOWNLOAD_TIMEOUT)
    except subprocess.TimeoutExpired:
        raise BuildError(f"could not download {filename} from PyPI: no answer in {DOWNLOAD_TIMEOUT} s") from None
    if proc.returncode != 0 or not target.is_file():
        raise BuildError(f"could not download {filename} from PyPI:\n{proc.stderr.strip()[-800:]}")
    return target


def package_files() -> list[Path]:
    """The package's files: those git tracks (no scratch files or caches), or the whole tree outside git."""
    try:
        proc = subprocess.run(["git", "ls-files", "-z", "--", PACKAGE.name], cwd=REPO, capture_output=True,
                              text=True, check=True)
        files = [REPO / f for f in proc.stdout.split("\0") if f]
    except (OSError, subprocess.CalledProcessError):
        files = []
    if not files:
        files = [p for p in PACKAGE.rglob("*") if p.is_file()]
    return [f for f in files if f.is_file() and "__pycache__" not in f.parts and not f.name.endswith(".pyc")
            and not f.name.startswith(".")]


def stage(manifest: dict, staging: Path) -> None:
    shutil.copy2(MANIFEST, staging / "blender_manifest.toml")
    for f in package_files():
        target = staging / f.relative_to(PACKAGE)
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(f, target)
    wheels = staging / "wheels"
    wheels.mkdir()
    cache = wheel_cache()
    for entry in manifest.get("wheels", []):
        name = Path(entry).name
        shutil.copy2(fetch_wheel(name, cache), wheels / name)


def build(out_dir: Path) -> Path:
    manifest = read_manifest()
    out_dir.mkdir(parents=True, exist_ok=True)
    out = out_dir / f"{manifest['id']}-{manifest['version']}.zip"
    with tempfile.TemporaryDirectory(prefix="kr_ext_") as tmp:
        staging = Path(tmp) / manifest["id"]
        staging.mkdir()
        stage(manifest, staging)
        script = str(blender_ext_script())
        for args in (["build", "--source-dir", str(staging), "--output-filepath", str(out)],
                     ["validate", str(out)]):
            proc = subprocess.run([sys.executable, script, *args], capture_output=True, text=True)
            if proc.returncode != 0:
                raise BuildError(f"blender_ext {args[0]} failed:\n{(proc.stdout + proc.stderr).strip()[-1500:]}")
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out-dir", type=Path, default=REPO / "dist")
    args = ap.parse_args(argv)
    try:
        out = build(args.out_dir)
    except BuildError as exc:
        print(f"build_extension: {exc}", file=sys.stderr)
        return 1
    print(out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
