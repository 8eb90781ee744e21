"""Fixtures in the shape real files come in, from a take shipped in the repository (nothing outside the
repository is needed).

MSRC-12's own files stamp frames with a microsecond-like counter (642926216, ~33,150 per frame, jittered)
and start with about 20 rows of zeros before the skeleton is found; columns are space-separated. This
writes the real Kinect recording `sample_takes/kinect_v2_ges01_wavehand.krtake` (LabanotationSuite, MIT) in
that layout. `PYTHONPATH=. .venv/bin/python tests/takes/real_layout_fixtures.py` regenerates it
(deterministic; a test checks the committed file is current).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from kinect_retarget.core.skeletons import NOT_TRACKED
from kinect_retarget.takes import krtake
from tests.takes.format_fixtures import FIXTURES, v1_from_v2

REPO = Path(__file__).resolve().parents[2]
SOURCE = REPO / "sample_takes" / "kinect_v2_ges01_wavehand.krtake"
MSRC12_REAL = FIXTURES / "msrc12_real_layout_converted_ges01.csv"
FIRST_STAMP = 642926216
STAMP_STEP = 33150          # counter units per frame, as in the data set's files
LEADING_EMPTY = 20
FRAMES = 60


def write_msrc12_real(path: Path = MSRC12_REAL) -> Path:
    take = v1_from_v2(krtake.read(SOURCE).slice(slice(0, FRAMES)))
    f, nj = take.states.shape
    n = LEADING_EMPTY + f
    jitter = np.random.default_rng(12).integers(-40, 41, size=n)  # real counters wobble by tens of units
    jitter[0] = 0
    stamps = FIRST_STAMP + np.arange(n) * STAMP_STEP + jitter
    block = np.zeros((n, nj, 4))
    tracked = take.states != NOT_TRACKED
    body = block[LEADING_EMPTY:]
    body[tracked, :3] = take.positions[tracked]
    body[tracked, 3] = 1.0
    rows = np.concatenate([stamps[:, None], block.reshape(n, -1)], axis=1)
    fmt = " ".join(["%d"] + ["%.6g"] * (4 * nj))
    path.write_text("".join(fmt % tuple(r) + "\n" for r in rows))
    return path


if __name__ == "__main__":
    p = write_msrc12_real()
    print(p, p.stat().st_size)
