"""OpenPose BODY_25 keypoint folders: one `<name>_<frame>_keypoints.json` per video frame.

Each file: {"version": 1.3, "people": [{"pose_keypoints_2d": [x0, y0, c0, ... x24, y24, c24], ...}]}.
Files that are empty, malformed or show nobody become frames without a body (named in `problems`); the
rest of the take is still read. With several people, the one nearest the previous frame's pick is kept.
"""
from __future__ import annotations

import json
import os
import re

import numpy as np

from .keypoints import natural_key, nearest_person, outside_image, read_json, summarise, to_tracks
from .schemes import BODY_25, BODY_25_TO_V1
from .tracks2d import LiftError, Tracks2D

K = len(BODY_25)


def keypoint_files(folder: str) -> list[str]:
    if not os.path.isdir(folder):
        raise LiftError(f"{folder}: not a folder of OpenPose *_keypoints.json files")
    names = [n for n in os.listdir(folder) if n.endswith("_keypoints.json")]
    if not names:
        raise LiftError(f"{folder}: no *_keypoints.json files (OpenPose writes <video>_<frame>_keypoints.json)")
    return sorted(names, key=natural_key)


def _frame_number(name: str, fallback: int) -> int:
    m = re.search(r"(\d+)_keypoints\.json$", name)
    return int(m.group(1)) if m else fallback


def read(folder: str | os.PathLike, fps: float = 30.0, image_size=None) -> Tracks2D:
    folder = os.fspath(folder)
    if not (fps > 0):
        raise LiftError(f"frame rate must be positive, got {fps}")
    files = keypoint_files(folder)
    uv = np.full((len(files), K, 2), np.nan)
    conf = np.zeros((len(files), K))
    problems: list[str] = []
    frames = np.array([_frame_number(n, i) for i, n in enumerate(files)])
    prev = None
    for i, name in enumerate(files):  # one JSON file per frame: parsing is inherently per file
        path = os.path.join(folder, name)
        people, err = _people(path)
        if err:
            problems.append(f"{path}: {err}; frame {frames[i]} left without a body")
            continue
        pick = _choose(people, prev)
        if pick is None:
            problems.append(f"{path}: no person detected; frame {frames[i]} left without a body")
            continue
        uv[i], conf[i] = pick[:, :2], pick[:, 2]
        prev = pick
    if np.all(conf == 0):
        raise LiftError(f"{folder}: no usable person in any of its {len(files)} keypoint files"
                        + (f" (first problem: {problems[0]})" if problems else ""))
    labels = [f"{files[i]} (frame {frames[i]})" for i in range(len(files))]
    conf, notes = outside_image(uv, conf, image_size, BODY_25, folder, labels)
    problems = summarise(problems, folder, "unreadable or empty frames") + notes
    times = (frames - frames[0]) / fps if np.all(np.diff(frames) > 0) else np.arange(len(files)) / fps
    return to_tracks(uv, conf, BODY_25_TO_V1, times, image_size, folder, problems, frames)


def _people(path: str):
    """The file's people as (P, 25, 3) arrays, or an error message."""
    data, err = read_json(path)
    if err is not None:
        return None, err
    if not isinstance(data, dict) or not isinstance(data.get("people"), list):
        return None, "no 'people' list (not an OpenPose keypoint file)"
    out = []
    for n, person in enumerate(data["people"]):
        kp = person.get("pose_keypoints_2d") if isinstance(person, dict) else None
        try:
            arr = np.asarray(kp, dtype=np.float64)
        except (TypeError, ValueError):
            return None, f"people[{n}].pose_keypoints_2d is not a list of numbers"
        if arr.size == 0:
            continue
        if arr.shape != (3 * K,):
            return None, (f"people[{n}].pose_keypoints_2d has {arr.size} values; BODY_25 has {3 * K} "
                          f"(x, y, confidence per keypoint). COCO-18 output? Re-run OpenPose with BODY_25")
        arr = arr.reshape(K, 3)
        arr[~np.isfinite(arr).all(axis=1)] = 0.0
        out.append(arr)
    return out, None


def _choose(people: list[np.ndarray], prev: np.ndarray | None):
    people = [p for p in people if np.any(p[:, 2] > 0)]
    if not people:
        return None
    if prev is None or len(people) == 1:
        return max(people, key=lambda p: float(p[:, 2].sum()))  # the most confidently seen person
    return nearest_person(people, prev)


def write_frame(path: str, uv: np.ndarray, conf: np.ndarray) -> None:
    """One OpenPose BODY_25 file: uv (25, 2) pixels, conf (25,) (0 where missing)."""
    kp = np.concatenate([np.nan_to_num(uv), conf[:, None]], axis=1)
    kp[conf <= 0] = 0.0
    person = {"person_id": [-1], "pose_keypoints_2d": [round(float(v), 3) for v in kp.ravel()],
              "face_keypoints_2d": [], "hand_left_keypoints_2d": [], "hand_right_keypoints_2d": []}
    data = {"version": 1.3, "people": [person]}
    with open(path, "w", encoding="utf-8") as fh:
        json.dump(data, fh)
