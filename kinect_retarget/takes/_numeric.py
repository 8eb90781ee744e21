"""Fast parsing of numeric text tables (one record per line) that still names the bad line when it fails.

The fast path counts fields per line on the raw bytes (numpy, no Python loop) and parses every number in one
`np.fromstring` call; only when something is wrong does a slow per-line pass run, to say which line and why.
"""
from __future__ import annotations

import io
import warnings

import numpy as np

from ..core.take import TakeError

_SPACE = b" "
_WS = np.zeros(256, dtype=bool)
_WS[[9, 10, 11, 12, 13, 32]] = True


def normalise(data: bytes, delimiters: bytes = b"") -> bytes:
    """Delimiters and carriage returns become spaces, so every line is whitespace-separated."""
    table = bytes.maketrans(delimiters + b"\r", _SPACE * (len(delimiters) + 1))
    return data.translate(table)


def numeric_first_row(head: bytes, ncol: int, delimiters: bytes = b"") -> list[bytes] | None:
    """The first line's fields when it holds exactly `ncol` numbers, else None (format detection)."""
    fields = normalise(head.split(b"\n", 1)[0], delimiters).split()
    if len(fields) != ncol:
        return None
    try:
        [float(v) for v in fields]
    except ValueError:
        return None
    return fields


def at(path: str, label: str, where: int) -> str:
    """Where a message points: `file:line` for line numbers, `file: record N` for other labels."""
    return f"{path}:{int(where)}" if label == "line" else f"{path}: {label} {int(where)}"


def field_counts(data: bytes) -> np.ndarray:
    """Number of whitespace-separated fields on each line of `data` (lines split at b'\\n')."""
    buf = np.frombuffer(data, dtype=np.uint8)
    if buf.size == 0:
        return np.zeros(0, dtype=np.int64)
    ws = _WS[buf]
    starts = np.flatnonzero(~ws[1:] & ws[:-1]) + 1
    if not ws[0]:
        starts = np.concatenate([[0], starts])
    newlines = np.flatnonzero(buf == 10)
    n_lines = newlines.size + (0 if buf[-1] == 10 else 1)
    return np.bincount(np.searchsorted(newlines, starts), minlength=n_lines)


def parse_table(path: str, data: bytes, ncol: int | None, *, first_line: int = 1,
                delimiters: bytes = b"", what: str = "line") -> tuple[np.ndarray, np.ndarray]:
    """Parse numeric lines into an (N, ncol) float64 array; blank lines are skipped.

    Returns (values, line_numbers) where line_numbers are the 1-based file lines of the rows. `ncol` None
    takes the width of the first non-blank line. Raises TakeError naming the file line for a wrong field
    count or a non-numeric field. NaN and infinite values are returned as they are: a bad joint sample is
    not structural damage (the readers pass their joints through _screening.screen_joints).
    """
    text = normalise(data, delimiters)
    fast = _fast_table(text, ncol)
    if fast is not None:
        return fast, np.arange(fast.shape[0]) + first_line
    counts = field_counts(text)
    rows = np.flatnonzero(counts)
    if rows.size == 0:
        raise TakeError(f"{path}: no data lines")
    if ncol is None:
        ncol = int(counts[rows[0]])
    bad = rows[counts[rows] != ncol]
    if bad.size:
        i = int(bad[0])
        raise TakeError(f"{path}:{i + first_line}: expected {ncol} values, found {int(counts[i])} "
                        f"(truncated or corrupt {what})")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # fromstring warns, then stops, at the first non-numeric token
        flat = np.fromstring(text.decode("latin-1"), dtype=np.float64, sep=" ")
    if flat.size != rows.size * ncol:
        _raise_non_numeric(path, text, rows, first_line, what)
    return flat.reshape(rows.size, ncol), rows + first_line


def _fast_table(text: bytes, ncol: int | None) -> np.ndarray | None:
    """numpy's C text parser (about twice np.fromstring's speed) for the common case: no blank lines,
    every line complete and numeric. Returns None whenever anything is off; the careful path then names it."""
    body = text.rstrip()
    if not body or b"\n\n" in body or _WS[body[0]]:
        return None
    try:
        values = np.loadtxt(io.BytesIO(body), dtype=np.float64, comments=None, ndmin=2)
    except ValueError:
        return None
    if (ncol is not None and values.shape[1] != ncol) or values.shape[0] != body.count(b"\n") + 1:
        return None
    return values


def _raise_non_numeric(path: str, text: bytes, rows: np.ndarray, first_line: int, what: str) -> None:
    lines = text.split(b"\n")
    for i in rows:
        for token in lines[i].split():
            try:
                float(token)
            except ValueError:
                shown = token[:20].decode("latin-1")
                raise TakeError(f"{path}:{int(i) + first_line}: non-numeric value {shown!r} in {what}") from None
    raise TakeError(f"{path}: could not parse numbers")  # unreachable in practice; never fail silently


def read_bytes(path: str) -> bytes:
    try:
        with open(path, "rb") as fh:
            data = fh.read()
    except OSError as exc:
        raise TakeError(f"{path}: cannot read file ({exc.strerror})") from None
    if not data.strip():
        raise TakeError(f"{path}: file is empty")
    return data
