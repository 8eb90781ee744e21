"""Writers for take formats we have no real file of (NTU RGB+D, MSRC-12, UTKinect-Action3D).

They write a real take (the Microsoft LabanotationSuite Kinect v2 recordings, MIT) in each data set's exact
text layout, so the readers are tested on the layout with real motion. Files made here are CONVERTED data,
not data-set files. `PYTHONPATH=. python tests/takes/format_fixtures.py` regenerates tests/takes/fixtures/ (deterministic).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from kinect_retarget.core.conventions import kinect_to_depth_pixel
from kinect_retarget.core.skeletons import KINECT_V1, KINECT_V2, NOT_TRACKED, V1_FROM_V2
from kinect_retarget.core.take import Take

FIXTURES = Path(__file__).resolve().parent / "fixtures"
# Pinhole fits to the Kinectron recording (data/README.md): depth and colour cameras, pixels.
DEPTH_CAMERA = (366.0, 255.0, 207.0)
COLOR_CAMERA = (1062.0, 995.0, 541.0)


def v1_from_v2(take: Take) -> Take:
    """Kinect v2 take -> Kinect v1 joint set (v2 is a superset)."""
    idx = [KINECT_V2.index(V1_FROM_V2[name]) for name in KINECT_V1.joints]
    return Take(KINECT_V1, take.positions[:, idx], take.states[:, idx], take.times, take.rate,
                take.source_format, dict(take.metadata))


def _lines(rows: np.ndarray, fmt: str) -> str:
    return "".join(fmt % tuple(r) + "\n" for r in rows)


def write_ntu(take: Take, path: Path, second_body: slice = slice(0, 0), second: Take | None = None) -> None:
    """NTU .skeleton; frames where nothing is tracked get 0 bodies; `second_body` frames get a second
    person listed after the first: `second`'s frames (as many as `take`'s) 1 m along X, else the first
    shifted 1 m."""
    f, nj = take.states.shape
    table = _ntu_table(take)
    other_table = table if second is None else _ntu_table(second)
    joint_fmt = "%.7g %.7g %.7g %.7g %.7g %.7g %.7g %.7g %.7g %.7g %.7g %d"
    present = np.zeros(f, dtype=bool)
    present[second_body] = True
    out = [f"{f}\n"]
    for i in range(f):
        bodies = []
        if np.any(take.states[i] != NOT_TRACKED):
            bodies.append(("72057594037931101", table[i]))
            if present[i]:
                other = other_table[i].copy()
                other[:, 0] += 1.0
                bodies.append(("72057594037931117", other))
        out.append(f"{len(bodies)}\n")
        for body_id, rows in bodies:
            out.append(f"{body_id} 0 1 1 1 1 0 0.01237284 -0.04561102 2\n{nj}\n")
            out.append(_lines(rows, joint_fmt))
    path.write_text("".join(out))


def _ntu_table(take: Take) -> np.ndarray:
    """(F, J, 12) NTU joint lines: position, depth and colour pixels, orientation, state."""
    f, nj = take.states.shape
    pos = np.nan_to_num(take.positions)
    safe = np.where(pos[..., 2:] > 0, pos, [0, 0, 1])
    # NTU stores the Kinect SDK's pixel coordinates, whose images are mirrored: u = W - 1 - u(camera view).
    depth = kinect_to_depth_pixel(safe, *DEPTH_CAMERA) * [-1, 1] + [511, 0]
    color = kinect_to_depth_pixel(safe, *COLOR_CAMERA) * [-1, 1] + [1919, 0]
    orient = np.zeros((f, nj, 4))
    return np.concatenate([pos, depth, color, orient, take.states[..., None]], axis=2)


def write_msrc12(take: Take, path: Path, time_offset: float = 0.0) -> None:
    """MSRC-12: `t x y z w` x 20 per line; untracked joints are written as zeros, tracked ones with w = 1."""
    f, nj = take.states.shape
    tracked = take.states != NOT_TRACKED
    block = np.zeros((f, nj, 4))
    block[tracked, :3] = take.positions[tracked]
    block[tracked, 3] = 1.0
    rows = np.concatenate([(take.times + time_offset)[:, None], block.reshape(f, -1)], axis=1)
    path.write_text(_lines(rows, " ".join(["%.6f"] + ["%.6g"] * (4 * nj))))


def write_utkinect(take: Take, path: Path, first_frame: int = 248) -> None:
    """UTKinect: `frame x y z` x 20 per line; frame numbers from the timestamps at 30 fps."""
    f, nj = take.states.shape
    numbers = first_frame + np.round(take.times * 30.0).astype(np.int64)
    pos = np.where((take.states != NOT_TRACKED)[..., None], np.nan_to_num(take.positions), 0.0)
    rows = np.concatenate([numbers[:, None], pos.reshape(f, -1)], axis=1)
    path.write_text(_lines(rows, " ".join(["%d"] + ["%.6g"] * (3 * nj))))


def make_all(data_dir: Path, out: Path = FIXTURES) -> dict[str, Path]:
    """The committed fixtures: small, converted from real Kinect v2 recordings."""
    from kinect_retarget.takes import kinect_v2_csv
    out.mkdir(exist_ok=True)
    ges = kinect_v2_csv.read(data_dir / "kinect_v2" / "Ges01_wavehand.csv").slice(slice(0, 40))
    joints = kinect_v2_csv.read(data_dir / "kinect_v2" / "joints.csv").slice(slice(0, 60))
    # Give the NTU file frames with no body: blank out the first three frames.
    ges.states[:3] = NOT_TRACKED
    ges.positions[:3] = np.nan
    paths = {"ntu": out / "S001C001P001R001A001_converted_Ges01.skeleton",
             "msrc12": out / "P1_1_1_converted_joints.csv",
             "utkinect": out / "joints_s01_e01_converted_joints.txt"}
    write_ntu(ges, paths["ntu"], second_body=slice(10, 20))
    write_msrc12(v1_from_v2(joints), paths["msrc12"], time_offset=0.033333)
    gaps = np.ones(joints.frame_count, dtype=bool)
    gaps[[7, 8, 30]] = False  # UTKinect files skip video frames
    write_utkinect(v1_from_v2(joints.slice(gaps)), paths["utkinect"])
    return paths


if __name__ == "__main__":
    import tempfile

    from tests.repo_data import materialize
    with tempfile.TemporaryDirectory() as tmp:
        for name, p in make_all(materialize(Path(tmp) / "data")).items():
            print(name, p, p.stat().st_size)
