"""docs/images/depth_body_parts_real.png: real Kinect v1 depth with the classified body parts and the fitted
skeleton drawn over it (the shipped forest and tracker, on redistributable frames: Skeltrack's test frames,
LGPL, and the OpenISS fakenect recording, Apache 2.0, as copied into tests/data/depth_real).

    .venv/bin/python tools/make_body_part_picture.py [--out docs/images/depth_body_parts_real.png]
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from kinect_retarget.depth import part_proposals  # noqa: E402
from kinect_retarget.depth.body_parts import PARTS  # noqa: E402
from kinect_retarget.depth.skeleton_tracker import SkeletonTracker  # noqa: E402
from kinect_retarget.depth.tracking_preview import preview_rgba  # noqa: E402
from kinect_retarget.lift.image_sequence import write_png  # noqa: E402


def palette() -> np.ndarray:
    """A fixed colour per part: hue around the wheel, left parts brighter than right ones."""
    hues = np.linspace(0, 1, len(PARTS), endpoint=False)
    rgb = np.abs(((hues[:, None] * 6 + [0, 4, 2]) % 6) - 3) - 1
    return np.clip(rgb, 0, 1) * np.where([p.endswith("_right") for p in PARTS], 0.65, 1.0)[:, None]


def picture(frames: list[np.ndarray], times: list[float] | None = None) -> np.ndarray:
    """Track the frames in order (at `times`, seconds; default 30 frames/s); the last one's preview with every
    classified cell coloured by its part."""
    part_proposals.MAX_CELLS = 10 ** 6   # every cell coloured (the tracker subsamples large silhouettes)
    tracker = SkeletonTracker()
    for i, mm in enumerate(frames):
        pos, st = tracker.update(mm, i / 30 if times is None else times[i])
    img = preview_rgba(frames[-1], None, pos, st, tracker.camera, scale=1)[::-1].copy()
    props, step = tracker.last_proposals, tracker.last_grid.step
    if props is not None:
        rows, cols = props.cells
        colours = palette()[np.argmax(props.probs, axis=1)]
        for dr in range(step):
            for dc in range(step):
                img[rows * step + dr, cols * step + dc, :3] = colours
        over = preview_rgba(np.zeros_like(frames[-1]), None, pos, st, tracker.camera, scale=1)[::-1]   # skeleton
        for dr in (-1, 0, 1):   # drawn 3 pixels wide, to be seen over the parts
            for dc in (-1, 0, 1):
                shifted = np.roll(over, (dr, dc), axis=(0, 1))
                drawn = np.any(shifted[..., :3] > 0, axis=-1)
                img[drawn] = shifted[drawn]
    return img[..., :3]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default=str(REPO / "docs" / "images" / "depth_body_parts_real.png"))
    args = ap.parse_args()
    import tempfile
    sys.path.insert(0, str(REPO / "tests"))
    from repo_data import materialize   # tests/data with its gzipped files decompressed
    from kinect_retarget.device.disparity_calibration import Calibration
    from kinect_retarget.device.protocol import TIMESTAMP_HZ, ticks_between
    from kinect_retarget.sim.depth_sequences import load_fakenect_dir
    with tempfile.TemporaryDirectory() as tmp:
        data = materialize(Path(tmp)) / "depth_real"
        skel = sorted((data / "skeltrack" / "tests" / "resources").glob("depth-data-*"))[:6]
        # Skeltrack's frames are named by their device timestamps: 3-5 frames of a recording apart, so tracked
        # at 30 frames/s their arms would seem to move 3-5 times as fast as they did (and be held: step 13)
        ticks = [int(f.name.split("-")[-1].split(".")[0]) for f in skel]
        a = picture([np.fromfile(f, "<u2").reshape(480, 640) for f in skel],
                    [ticks_between(ticks[0], t) / TIMESTAMP_HZ for t in ticks])
        cal = Calibration()
        b = picture([cal.to_mm(r) for r in load_fakenect_dir(data / "fakenect_openiss" / "fakenect-record")])
    write_png(args.out, np.concatenate([a, b], axis=1))
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
