"""COCO-17 person keypoints: a COCO annotation file ({"images", "annotations", "categories"}) or a results
list ([{"image_id", "keypoints", "score"}, ...]). `keypoints` is 17 x (x, y, v): v = 0 not labelled,
1 labelled but occluded (kept, marked inferred), 2 visible; detector results put a confidence there.

Frames are the images in file-name order (annotation files) or image_id order (results lists). COCO has no
feet or hands: the lifter infers them. Several people in one image: the one nearest the previous pick.
"""
from __future__ import annotations

import os

import numpy as np

from .keypoints import natural_key, nearest_person, outside_image, read_json, summarise, to_tracks
from .schemes import COCO_17, COCO_17_TO_V1
from .tracks2d import LiftError, Tracks2D

K = len(COCO_17)


def read(path: str | os.PathLike, fps: float = 30.0, image_size=None) -> Tracks2D:
    path = os.fspath(path)
    if not (fps > 0):
        raise LiftError(f"frame rate must be positive, got {fps}")
    data = _load(path)
    images, anns = _images_and_annotations(path, data)
    if not images:
        raise LiftError(f"{path}: no images and no annotations with keypoints")
    if all(images[i].get("file_name") for i in images):
        order = sorted(images, key=lambda i: natural_key(images[i]["file_name"]))
    else:
        order = sorted(images, key=lambda i: (str(type(i)), i))
    size = image_size or _common_size(images, order)
    uv = np.full((len(order), K, 2), np.nan)
    conf = np.zeros((len(order), K))
    occluded = np.zeros((len(order), K), dtype=bool)
    problems: list[str] = []
    prev = None
    for f, image_id in enumerate(order):
        label = _label(images, image_id)
        people = []
        for n, ann in anns.get(image_id, []):
            arr, err = _keypoints(ann)
            if err:
                problems.append(f"{path}: annotation {n} ({label}): {err}; skipped")
            elif arr is not None:
                people.append(arr)
        pick = _choose(people, prev)
        if pick is None:
            problems.append(f"{path}: {label}: no person with keypoints; frame left without a body")
            continue
        uv[f] = pick[:, :2]
        vis = pick[:, 2]
        conf[f] = np.where(vis > 0, np.where(vis == 1, 0.5, np.minimum(vis, 1.0)), 0.0)
        occluded[f] = vis == 1
        prev = pick
    if np.all(conf == 0):
        raise LiftError(f"{path}: no person keypoints in any of its {len(order)} images")
    labels = [_label(images, i) for i in order]
    conf, notes = outside_image(uv, conf, size, COCO_17, path, labels)
    problems = summarise(problems, path, "images without a person") + notes
    tracks = to_tracks(uv, conf, COCO_17_TO_V1, np.arange(len(order)) / fps, size, path, problems,
                       np.arange(len(order)))
    # an occluded (v = 1) keypoint is a guess by the annotator: the joints built from it are inferred
    tracks.inferred |= _joints_touched(occluded)
    return tracks


def _load(path: str):
    data, err = read_json(path)
    if err is not None:
        raise LiftError(f"{path}: {err}")
    return data


def _images_and_annotations(path: str, data):
    if isinstance(data, list):  # detector results
        anns_list, images = data, {}
    elif isinstance(data, dict) and "annotations" in data:
        anns_list = data["annotations"]
        images = {im["id"]: im for im in data.get("images", []) if isinstance(im, dict) and "id" in im}
    else:
        raise LiftError(f"{path}: not COCO keypoints (expected an object with 'annotations' or a results list)")
    if not isinstance(anns_list, list):
        raise LiftError(f"{path}: 'annotations' is not a list")
    anns: dict = {}
    for n, ann in enumerate(anns_list):
        if not isinstance(ann, dict) or "image_id" not in ann:
            raise LiftError(f"{path}: annotation {n} has no image_id")
        anns.setdefault(ann["image_id"], []).append((n, ann))
        images.setdefault(ann["image_id"], {"id": ann["image_id"]})
    return images, anns


def _keypoints(ann: dict):
    kp = ann.get("keypoints")
    if kp is None:
        return None, None  # a non-person annotation
    try:
        arr = np.asarray(kp, dtype=np.float64)
    except (TypeError, ValueError):
        return None, "keypoints are not numbers"
    if arr.shape != (3 * K,):
        return None, f"{arr.size} keypoint values, COCO-17 has {3 * K}"
    arr = arr.reshape(K, 3)
    arr[~np.isfinite(arr).all(axis=1)] = 0.0
    return (arr if np.any(arr[:, 2] > 0) else None), None


def _choose(people, prev):
    if not people:
        return None
    if prev is None or len(people) == 1:
        return max(people, key=lambda p: float(np.sum(p[:, 2] > 0)))
    return nearest_person(people, prev)


def _common_size(images, order):
    sizes = {(im.get("width"), im.get("height")) for im in (images[i] for i in order)}
    if len(sizes) == 1:
        w, h = sizes.pop()
        if isinstance(w, (int, float)) and isinstance(h, (int, float)) and w > 0 and h > 0:
            return (float(w), float(h))
    return None


def _label(images, image_id) -> str:
    name = images.get(image_id, {}).get("file_name")
    return f"image {image_id}" + (f" ({name})" if name else "")


def _joints_touched(occluded: np.ndarray) -> np.ndarray:
    """(F, J) Kinect v1 joints whose recipe reads an occluded keypoint."""
    from ..core.skeletons import KINECT_V1
    out = np.zeros((occluded.shape[0], len(KINECT_V1)), dtype=bool)
    for name, alts in COCO_17_TO_V1.items():
        idx = sorted({k for alt in alts for k, _ in alt})
        out[:, KINECT_V1.index(name)] = occluded[:, idx].any(axis=1)
    return out
