"""Data the product reads at run time, shipped inside the package (and so in the extension zip): the
MakeHuman body and the CMU motion the simulated Kinect renders. Sources and licences: CREDITS.md here;
tools/vendor_data.py copies them from the workshop data."""
from __future__ import annotations

from pathlib import Path

ASSETS_DIR = Path(__file__).resolve().parent
MAKEHUMAN_DIR = ASSETS_DIR / "makehuman"      # base.obj, default.mhskel, default_weights.mhw (CC0)
MOTION_DIR = ASSETS_DIR / "motion"            # CMU BVH clips, trimmed to the frames the simulator renders


def motion_clip(name: str) -> Path:
    """The shipped CMU clip `name` (e.g. "131_03")."""
    return MOTION_DIR / f"{name}.bvh"
