"""What the keypoint readers share: reading a JSON file, sorting names, picking a person, and the last step:
drop impossible points (naming them) and map onto Kinect v1."""
from __future__ import annotations

import json
import re

import numpy as np

from .schemes import SYNTHETIC_V1
from .tracks2d import Tracks2D, combine

MAX_NOTES = 12  # problems listed one by one before they are summarised


def natural_key(name) -> list:
    """Sort key putting frame_2 before frame_10: digit runs compare as numbers."""
    return [int(t) if t.isdigit() else t for t in re.split(r"(\d+)", str(name))]


def read_json(path: str):
    """(data, None) for a readable JSON file, else (None, why): unreadable, empty or malformed."""
    try:
        with open(path, "r", encoding="utf-8") as fh:
            text = fh.read()
    except (OSError, UnicodeDecodeError) as exc:
        return None, f"cannot read ({exc})"
    if not text.strip():
        return None, "file is empty"
    try:
        return json.loads(text), None
    except json.JSONDecodeError as exc:
        return None, f"malformed JSON at line {exc.lineno} column {exc.colno} ({exc.msg})"


def nearest_person(people: list[np.ndarray], prev: np.ndarray) -> np.ndarray:
    """The person (K, 3: x, y, confidence) whose keypoints seen in both are, in median, nearest prev's."""
    def distance(p):
        both = (p[:, 2] > 0) & (prev[:, 2] > 0)
        return float(np.median(np.linalg.norm(p[both, :2] - prev[both, :2], axis=1))) if both.any() else np.inf
    return min(people, key=distance)


def outside_image(uv: np.ndarray, conf: np.ndarray, size, names, source: str, labels) -> tuple[np.ndarray, list[str]]:
    """Zero the confidence of keypoints outside the image (a small margin allowed) and describe them."""
    if size is None:
        return conf, []
    w, h = size
    margin = 0.02 * max(w, h)
    bad = (conf > 0) & ((uv[..., 0] < -margin) | (uv[..., 0] > w + margin) |
                        (uv[..., 1] < -margin) | (uv[..., 1] > h + margin))
    notes = []
    for f, k in zip(*np.nonzero(bad)):
        if len(notes) == MAX_NOTES:
            notes.append(f"{source}: ... {int(bad.sum()) - MAX_NOTES} more keypoints outside the image ignored")
            break
        notes.append(f"{source}: {labels[f]}: {names[k]} at ({uv[f, k, 0]:.0f}, {uv[f, k, 1]:.0f}) px is "
                     f"outside the {w:.0f}x{h:.0f} image; ignored")
    return np.where(bad, 0.0, conf), notes


def to_tracks(uv, conf, recipe, times, size, source, problems, frame_numbers) -> Tracks2D:
    out_uv, out_c, inferred = combine(uv, conf, recipe, synthetic=SYNTHETIC_V1)
    return Tracks2D(out_uv, out_c, times, size, source, inferred, problems, frame_numbers=frame_numbers)


def summarise(notes: list[str], source: str, what: str) -> list[str]:
    """Keep the first MAX_NOTES notes of one kind and count the rest."""
    if len(notes) <= MAX_NOTES:
        return notes
    return notes[:MAX_NOTES] + [f"{source}: ... and {len(notes) - MAX_NOTES} more {what}"]
