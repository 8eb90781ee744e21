"""2D joint tracks on the Kinect v1 joint set: what every 2D reader returns and the lifter consumes.

Pixels follow image conventions: u grows to the right, v grows downward, origin at the top-left corner.
A joint with no measurement in a frame has confidence 0 and NaN pixels.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..core.skeletons import KINECT_V1, Skeleton


class LiftError(ValueError):
    """Bad 2D input or settings: names the file (and frame) and what is wrong."""


@dataclass
class Tracks2D:
    """uv (F, J, 2) pixels; confidence (F, J) in [0, 1]; inferred (F, J) True where a joint was not
    measured but synthesised (from other keypoints, or by interpolation); times (F,) seconds.

    image_size: (width, height) in pixels when known. problems: human-readable notes on bad input that was
    skipped (each names the file and frame), so a caller can report them without losing the rest.
    """

    uv: np.ndarray
    confidence: np.ndarray
    times: np.ndarray
    image_size: tuple[float, float] | None = None
    source: str = ""
    inferred: np.ndarray | None = None
    problems: list[str] = field(default_factory=list)
    skeleton: Skeleton = KINECT_V1
    frame_numbers: np.ndarray | None = None  # source frame numbers (image / clip frames), for messages

    def __post_init__(self) -> None:
        self.uv = np.asarray(self.uv, dtype=np.float64)
        self.confidence = np.asarray(self.confidence, dtype=np.float64)
        self.times = np.asarray(self.times, dtype=np.float64)
        f, j = self.confidence.shape
        if self.uv.shape != (f, j, 2) or j != len(self.skeleton):
            raise LiftError(f"2D tracks disagree: uv {self.uv.shape}, confidence {self.confidence.shape}, "
                            f"skeleton {self.skeleton.name} has {len(self.skeleton)} joints")
        if self.times.shape != (f,):
            raise LiftError(f"2D tracks have {f} frames but {self.times.shape[0]} timestamps")
        if self.inferred is None:
            self.inferred = np.zeros((f, j), dtype=bool)
        if self.frame_numbers is None:
            self.frame_numbers = np.arange(f)
        bad = ~np.isfinite(self.uv).all(axis=-1)
        self.confidence[bad] = 0.0
        self.uv[self.confidence <= 0] = np.nan

    @property
    def frame_count(self) -> int:
        return int(self.times.shape[0])

    @property
    def present(self) -> np.ndarray:
        """(F, J) True where the joint has a usable 2D position."""
        return self.confidence > 0

    def frame_label(self, i: int) -> str:
        return f"frame {int(self.frame_numbers[i])}"


def combine(uv: np.ndarray, conf: np.ndarray, recipe: dict[str, list[tuple[int, float]]],
            skeleton: Skeleton = KINECT_V1, synthetic: frozenset[str] = frozenset()):
    """Map source keypoints (F, K, 2) / (F, K) onto the skeleton's joints with weighted recipes.

    recipe[joint] lists alternatives tried in order; each alternative is [(keypoint index, weight), ...]
    (weights sum to 1). A joint takes the first alternative whose keypoints are all present; its
    confidence is the minimum of theirs. Joints in `synthetic` are marked inferred (not measured directly).
    Returns uv (F, J, 2), confidence (F, J), inferred (F, J).
    """
    f = uv.shape[0]
    out_uv = np.full((f, len(skeleton), 2), np.nan)
    out_c = np.zeros((f, len(skeleton)))
    inferred = np.zeros((f, len(skeleton)), dtype=bool)
    for name, alternatives in recipe.items():
        j = skeleton.index(name)
        todo = np.ones(f, dtype=bool)
        for alt in alternatives:
            idx = np.array([k for k, _ in alt])
            w = np.array([wt for _, wt in alt])
            ok = todo & np.all(conf[:, idx] > 0, axis=1)
            out_uv[ok, j] = np.einsum("fkc,k->fc", uv[ok][:, idx], w)
            out_c[ok, j] = conf[ok][:, idx].min(axis=1)
            inferred[ok, j] = name in synthetic or alt is not alternatives[0]
            todo &= ~ok
    return out_uv, out_c, inferred
