"""A two-person take for tests: NTU layout, body 0 the LabanotationSuite wave (Ges01), body 1 the
come-here gesture (Ges04) standing 1 m along X, both real Kinect v2 recordings (MIT), 60 frames."""
from __future__ import annotations

from pathlib import Path

from kinect_retarget.takes import kinect_v2_csv
from tests.takes import format_fixtures as fx

FRAMES = 60


def performers(data_dir: Path):
    """(body 0, body 1) as read from their CSV files, 60 frames each."""
    return tuple(kinect_v2_csv.read(data_dir / "kinect_v2" / name).slice(slice(10, 10 + FRAMES))
                 for name in ("Ges01_wavehand.csv", "Ges04_comehere.csv"))


def write_two_person_ntu(data_dir: Path, path: Path) -> Path:
    first, second = performers(data_dir)
    fx.write_ntu(first, path, second_body=slice(0, FRAMES), second=second)
    return path
