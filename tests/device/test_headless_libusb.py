"""The headless environment (.venv from requirements-dev.txt) finds libusb like the extension does: the
system's, else the libusb-package wheel's. With no system libusb and no Kinect, `devices` answers, exit 0."""
from __future__ import annotations

import re
import subprocess
import sys

from tests.conftest import REPO

# Runs the CLI in a fresh process (pyusb caches the library it loaded) with the system lookup failing:
# ctypes.util.find_library is how pyusb finds the system libusb; libusb_package ships its own file.
NO_SYSTEM_LIBUSB = """
import ctypes.util, sys
ctypes.util.find_library = lambda name: None
if sys.argv[1] == "no-wheel":
    sys.modules["libusb_package"] = None   # import fails: as if the wheel were not installed
from kinect_retarget.cli import main
sys.exit(main(["devices"]))
"""


def _devices(mode: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", NO_SYSTEM_LIBUSB, mode], cwd=REPO, capture_output=True,
                          text=True, timeout=60)


def test_devices_without_system_libusb_uses_the_wheel():
    r = _devices("wheel")
    assert r.returncode == 0, r.stdout + r.stderr
    # no Kinect on a test machine: the answer, not an error (a plugged-in Kinect would be listed instead)
    assert r.stdout.startswith("no Kinect found") or "Kinect" in r.stdout
    assert "could not be loaded" not in r.stdout + r.stderr


def test_the_simulated_lookup_failure_is_real():
    """Control: with the same failing system lookup and no wheel, libusb is missing (exit 1, advice)."""
    r = _devices("no-wheel")
    assert r.returncode == 1 and "libusb-1.0 could not be loaded" in r.stderr


def test_requirements_pin_the_extension_wheels():
    """requirements-dev.txt pins the same libusb-package (and its importlib_resources) as the zip bundles."""
    manifest = (REPO / "blender_manifest.toml").read_text()
    reqs = (REPO / "requirements-dev.txt").read_text()
    for dist in ("pyusb", "libusb_package", "importlib_resources"):
        bundled = set(re.findall(rf"wheels/{dist}-([\d.]+)-", manifest))
        pinned = re.findall(rf"^{dist.replace('_', '[-_]')}==([\d.]+)$", reqs, flags=re.M)
        assert len(bundled) == 1 and pinned == sorted(bundled), (dist, bundled, pinned)
