"""The simulated Kinect, a product feature: the emulated USB Kinect (sim/) streaming depth rendered from real
mocap, a libfreenect recording, or the driver's synthetic figure. This is the one module outside sim/ that
imports sim/ (tests/core/test_layering.py checks it); the CLI's --simulate, the live USB source and the
sidebar's simulated toggle all come through here, and import it lazily."""
from __future__ import annotations

import os
import tempfile
from pathlib import Path

import numpy as np

from ..sim.depth_sequences import load_fakenect_dir, synthetic_depth_frames
from ..sim.emulated_kinect import EmulatedKinect

SIM_CLIP = "131_03"


def simulated_frames(frames: int = 90, clip: str = SIM_CLIP) -> list[np.ndarray]:
    """Raw 11-bit frames of a real motion (a CMU clip the package ships) rendered on the MakeHuman body, for the
    emulated Kinect; cached on disk (rendering takes about half a second per frame the first time)."""
    from ..assets import MAKEHUMAN_DIR, motion_clip
    from ..sim.synthetic_depth import Scenario, render_sequence
    bvh = motion_clip(clip)
    if not bvh.is_file():
        raise FileNotFoundError(f"{bvh}: the simulated Kinect's motion is missing from the package")
    cache = Path(os.environ.get("KR_DEPTH_CACHE", Path(tempfile.gettempdir()) / "kinect_retarget_depth_cache"))
    cache.mkdir(parents=True, exist_ok=True)
    path = cache / f"simulate_{clip}_{frames}.npy"
    if path.exists():
        return list(np.load(path))
    seq = render_sequence(str(bvh), str(MAKEHUMAN_DIR), Scenario(seed=11), frames=frames)
    if len(seq.raw) < frames:
        raise ValueError(f"{bvh} holds {len(seq.raw)} frames at 30 fps, {frames} asked")
    np.save(path, seq.raw)
    return list(seq.raw)


def simulated_images(frames: int = 90) -> tuple[list[np.ndarray], str]:
    """Raw depth frames for the emulated Kinect and a label: real motion rendered from the package's assets
    (cached after the first render), else (assets missing) the driver's synthetic figure."""
    try:
        return simulated_frames(frames), f"rendered CMU mocap {SIM_CLIP}"
    except (ImportError, FileNotFoundError):
        return synthetic_depth_frames(), "synthetic figure (the package's mocap assets are missing)"


def emulated_kinect(images: list[np.ndarray] | None = None, fakenect_dir: str | None = None) -> EmulatedKinect:
    """An emulated Kinect (a pyusb backend) looping `images`, a fakenect recording, or the synthetic figure."""
    if images is None:
        images = load_fakenect_dir(fakenect_dir) if fakenect_dir else synthetic_depth_frames()
    return EmulatedKinect(images)
