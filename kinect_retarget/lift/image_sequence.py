"""Image sequences for the 2D tracker, without an imaging library: binary PPM/PGM (8 or 16 bit) and .npy.
Other formats (PNG, JPEG, ...) are loaded through Blender's image loader by the CLI (blender/clip_lift.py)."""
from __future__ import annotations

import os
import re

import numpy as np

from .keypoints import natural_key
from .tracks2d import LiftError

NATIVE = (".ppm", ".pgm", ".pnm", ".npy")
ANY = NATIVE + (".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".exr", ".webp")


def list_frames(folder: str) -> list[str]:
    if not os.path.isdir(folder):
        raise LiftError(f"{folder}: not a folder of frames")
    names = [n for n in os.listdir(folder) if n.lower().endswith(ANY)]
    if not names:
        raise LiftError(f"{folder}: no image frames ({', '.join(ANY)})")
    return [os.path.join(folder, n) for n in sorted(names, key=natural_key)]


def load_frame(path: str) -> np.ndarray:
    """(H, W, 3) float32 RGB in [0, 1]."""
    if path.lower().endswith(".npy"):
        a = np.load(path)
        if a.ndim == 2:
            a = np.repeat(a[..., None], 3, axis=2)
        if a.ndim != 3 or a.shape[2] < 3:
            raise LiftError(f"{path}: expected an (H, W, 3) image array, got {a.shape}")
        a = a[..., :3].astype(np.float32)
        return a / 255.0 if a.max() > 1.0 else a
    with open(path, "rb") as fh:
        data = fh.read()
    m = re.match(rb"(P[56])\s+(?:#[^\n]*\n\s*)*(\d+)\s+(\d+)\s+(\d+)\s", data)
    if not m:
        raise LiftError(f"{path}: not a binary PPM/PGM (P6/P5) image")
    kind, w, h, maxval = m.group(1), int(m.group(2)), int(m.group(3)), int(m.group(4))
    ch = 3 if kind == b"P6" else 1
    dtype = ">u2" if maxval > 255 else "u1"
    count = w * h * ch
    if len(data) < m.end() + count * np.dtype(dtype).itemsize:
        raise LiftError(f"{path}: image data truncated ({w}x{h})")
    pix = np.frombuffer(data, dtype=dtype, count=count, offset=m.end())
    img = pix.reshape(h, w, ch).astype(np.float32) / maxval
    return np.repeat(img, 3, axis=2) if ch == 1 else img


def write_ppm(path: str, rgb: np.ndarray) -> None:
    img = np.clip(np.round(np.asarray(rgb) * 255), 0, 255).astype(np.uint8)
    h, w = img.shape[:2]
    with open(path, "wb") as fh:
        fh.write(b"P6\n%d %d\n255\n" % (w, h))
        fh.write(img.tobytes())


def write_png(path: str, rgb: np.ndarray) -> None:
    """8-bit RGB PNG (no filtering), for test sequences that Blender's clip loader can read."""
    import struct
    import zlib
    img = np.clip(np.round(np.asarray(rgb)[..., :3] * 255), 0, 255).astype(np.uint8)
    h, w = img.shape[:2]
    raw = np.concatenate([np.zeros((h, 1), np.uint8), img.reshape(h, -1)], axis=1).tobytes()

    def chunk(tag: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)
    with open(path, "wb") as fh:
        fh.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
                 + chunk(b"IDAT", zlib.compress(raw, 6)) + chunk(b"IEND", b""))
