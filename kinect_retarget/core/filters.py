"""Jitter filters on joint positions (paper 000 names jitter filtering as future work), applied before the
rotations are computed.

Both filters are causal and stateful: `step()` filters one frame (live), `run()` steps through a whole take
(bake), so a live pose equals the baked pose for the same frame. Work is vectorised over joints; the loop over
frames is inherent to a recursive filter.

Untracked joints (state 0) hold their last filtered position and restart their history when they come back;
inferred joints (state 1) are filtered like tracked ones.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .skeletons import NOT_TRACKED


def _step_each(filt, positions: np.ndarray, states: np.ndarray) -> np.ndarray:
    """A whole take through `filt.step`, frame by frame."""
    positions = np.asarray(positions, dtype=np.float64)
    out = np.empty_like(positions)
    for i in range(positions.shape[0]):
        out[i] = filt.step(positions[i], states[i])
    return out


@dataclass
class DoubleExponentialFilter:
    """The Kinect SDK's joint filter (Holt double exponential smoothing with a jitter radius and a maximum
    deviation from the raw data), with the SDK's default parameters."""

    smoothing: float = 0.5
    correction: float = 0.5
    prediction: float = 0.5
    jitter_radius: float = 0.05
    max_deviation: float = 0.04

    def __post_init__(self) -> None:
        self.reset()

    def reset(self) -> None:
        self._filtered = self._trend = self._raw = self._out = None
        self._count = None

    def step(self, x: np.ndarray, states: np.ndarray, t: float | None = None) -> np.ndarray:
        x = np.asarray(x, dtype=np.float64)
        valid = (np.asarray(states) != NOT_TRACKED)[:, None]
        if self._filtered is None:
            n = x.shape[0]
            self._filtered, self._trend = x.copy(), np.zeros_like(x)
            self._raw, self._out = x.copy(), x.copy()
            self._count = np.zeros((n, 1))
        count = self._count
        prev_f, prev_t, raw, out = self._filtered, self._trend, self._raw, self._out
        assert raw is not None and out is not None   # set together with _filtered
        first = count == 0
        second = count == 1
        # jitter radius: small moves are pulled toward the last estimate in proportion to their size
        diff = x - prev_f
        dist = np.sqrt(np.sum(diff * diff, axis=1, keepdims=True))
        w = np.minimum(dist / self.jitter_radius, 1.0)
        damped = prev_f + diff * w
        filtered = damped * (1 - self.smoothing) + (prev_f + prev_t) * self.smoothing
        filtered = np.where(second, (x + raw) * 0.5, filtered)
        filtered = np.where(first, x, filtered)
        trend = (filtered - prev_f) * self.correction + prev_t * (1 - self.correction)
        trend = np.where(first, 0.0, trend)
        predicted = filtered + trend * self.prediction
        dev = predicted - x
        dlen = np.sqrt(np.sum(dev * dev, axis=1, keepdims=True))
        over = dlen > self.max_deviation
        predicted = np.where(over, x + dev * (self.max_deviation / np.maximum(dlen, 1e-12)), predicted)
        self._filtered = np.where(valid, filtered, prev_f)
        self._trend = np.where(valid, trend, 0.0)
        self._raw = np.where(valid, x, raw)
        self._out = np.where(valid, predicted, out)
        self._count = np.where(valid, count + 1, 0.0)
        return self._out.copy()

    def run(self, positions: np.ndarray, states: np.ndarray, times: np.ndarray | None = None) -> np.ndarray:
        return _step_each(self, positions, states)


@dataclass
class OneEuroFilter:
    """One-Euro filter (Casiez et al. 2012): a low-pass whose cutoff rises with speed, per coordinate.
    `max_deviation` (metres) bounds how far a joint may trail its raw position, as the Kinect SDK's own filter
    bounds its output: no lag beyond it, however fast the move."""

    min_cutoff: float = 1.0   # Hz
    beta: float = 2.0         # cutoff increase per m/s
    d_cutoff: float = 1.0     # Hz, for the speed estimate
    rate: float = 30.0        # used for the first step only
    max_deviation: float = math.inf

    def __post_init__(self) -> None:
        self.reset()

    def reset(self) -> None:
        self._x = self._dx = self._t = None

    @staticmethod
    def _alpha(cutoff, dt):
        tau = 1.0 / (2 * math.pi * cutoff)
        return 1.0 / (1.0 + tau / dt)

    def _next_dt(self, t: float | None) -> float:
        """Seconds since the previous frame (1/rate when either time is unknown or t does not rise); t
        becomes the previous frame's time."""
        dt = 1.0 / self.rate if t is None or self._t is None or t <= self._t else t - self._t
        self._t = t
        return dt

    def step(self, x: np.ndarray, states: np.ndarray, t: float | None = None) -> np.ndarray:
        x = np.asarray(x, dtype=np.float64)
        valid = (np.asarray(states) != NOT_TRACKED)[:, None]
        if self._x is None:
            self._x, self._dx = x.copy(), np.zeros_like(x)
            self._seen = valid.copy()
            self._t = t
            return x.copy()
        dt = self._next_dt(t)
        self._advance(x, valid, dt, bool(valid.all() and self._seen.all()))
        return self._x.copy()

    def _advance(self, x: np.ndarray, valid: np.ndarray, dt: float, all_valid: bool) -> None:
        """One filter step."""
        diff = x - self._x
        speed = diff * (1.0 / dt)
        dx_hat = self._dx + self._alpha(self.d_cutoff, dt) * (speed - self._dx)
        gain = np.abs(dx_hat)                          # cutoff = min_cutoff + beta·|speed|, then
        gain *= self.beta * 2 * math.pi * dt           # gain = 2π·dt·cutoff / (1 + 2π·dt·cutoff)
        gain += self.min_cutoff * 2 * math.pi * dt
        gain = gain / (gain + 1.0)
        diff *= gain
        if math.isfinite(self.max_deviation):
            diff = self._bounded(x, self._x + diff) - self._x
        if all_valid:  # the common case skips the bookkeeping below; same numbers
            self._x = self._x + diff
            self._dx = dx_hat
            return
        x_prev = self._x
        assert x_prev is not None   # set by the first step
        x_hat = x_prev + diff
        restart = valid & ~self._seen  # a joint coming back starts from its raw position
        x_hat = np.where(restart, x, x_hat)
        self._x = np.where(valid, x_hat, x_prev)
        self._dx = np.where(valid & ~restart, dx_hat, 0.0)
        self._seen = valid

    def _bounded(self, raw: np.ndarray, filtered: np.ndarray) -> np.ndarray:
        """`filtered` moved toward `raw` where a joint (a row) trails it by more than max_deviation."""
        lag = filtered - raw
        dist = np.sqrt(np.sum(lag * lag, axis=-1, keepdims=True))
        return raw + lag * np.minimum(1.0, self.max_deviation / np.maximum(dist, 1e-12))

    def run(self, positions: np.ndarray, states: np.ndarray, times: np.ndarray | None = None) -> np.ndarray:
        positions = np.asarray(positions, dtype=np.float64)
        out = np.empty_like(positions)
        if out.shape[0] == 0:
            return out
        valid = np.asarray(states) != NOT_TRACKED
        all_valid = valid.all(axis=1)
        start = 0
        if self._x is None:
            out[0] = self.step(positions[0], states[0], None if times is None else float(times[0]))
            start = 1
        if all_valid[start:].all() and self._seen.all() and not math.isfinite(self.max_deviation):
            return self._run_all_tracked(positions, out, start, times)
        for i in range(start, out.shape[0]):
            dt = self._next_dt(None if times is None else float(times[i]))
            self._advance(positions[i], valid[i][:, None], dt, bool(all_valid[i] and self._seen.all()))
            out[i] = self._x
        return out


    def _run_all_tracked(self, positions: np.ndarray, out: np.ndarray, start: int,
                         times: np.ndarray | None) -> np.ndarray:
        """The same recursion as step()/_advance, with every joint tracked: per-frame constants computed up
        front and locals only, which roughly halves the per-frame cost of the bake's longest loop."""
        n = out.shape[0]
        dts = np.full(n, 1.0 / self.rate)
        if times is not None:
            t = np.asarray(times, dtype=np.float64)
            prev = np.concatenate([[np.nan if self._t is None else self._t], t[:-1]])
            step = t - prev
            dts = np.where(np.isfinite(step) & (step > 0), step, dts)
            self._t = float(t[-1])
        ads = self._alpha(self.d_cutoff, dts)
        k_beta, k_min = self.beta * 2 * math.pi * dts, self.min_cutoff * 2 * math.pi * dts
        inv_dt = 1.0 / dts
        xp, dxh = self._x, self._dx
        sub, mul, absolute = np.subtract, np.multiply, np.abs
        for i in range(start, n):
            diff = sub(positions[i], xp)
            dxh = dxh + ads[i] * (mul(diff, inv_dt[i]) - dxh)
            gain = absolute(dxh) * k_beta[i] + k_min[i]
            xp = xp + diff * (gain / (gain + 1.0))
            out[i] = xp
        self._x, self._dx = xp, dxh
        return out


class HoldUntracked:
    """No smoothing: untracked joints hold their last position ('none' keeps even those as recorded)."""

    def __init__(self) -> None:
        self.reset()

    def reset(self) -> None:
        self._last = None

    def step(self, x, states, t=None):
        x = np.asarray(x, dtype=np.float64)
        valid = (np.asarray(states) != NOT_TRACKED)[:, None]
        self._last = x.copy() if self._last is None else np.where(valid, x, self._last)
        return self._last.copy()

    def run(self, positions, states, times=None):
        return _step_each(self, positions, states)


FILTERS = ("none", "default", "one_euro", "kinect_sdk", "hold")


def make_filter(name: str, rate: float = 30.0):
    """None for 'none' (every position honoured, whatever its state). 'default' is a One-Euro filter tuned on
    the real Kinect v2 takes (jitter cut to under half, lag under one frame; benchmarks/bench_filters.py);
    'kinect_sdk' is the SDK's double exponential filter with its default parameters; 'hold' only holds
    untracked joints."""
    if name == "none":
        return None
    if name in ("default", "one_euro"):
        return OneEuroFilter(min_cutoff=1.0, beta=4.0, rate=rate)
    if name == "kinect_sdk":
        return DoubleExponentialFilter()
    if name == "hold":
        return HoldUntracked()
    raise ValueError(f"unknown filter {name!r} (choose from {', '.join(FILTERS)})")


def jitter(positions: np.ndarray) -> float:
    """Mean frame-to-frame joint acceleration magnitude (m/frame²)."""
    acc = positions[2:] - 2 * positions[1:-1] + positions[:-2]
    return float(np.mean(np.linalg.norm(acc, axis=-1)))


def lag_frames(raw: np.ndarray, filtered: np.ndarray, max_lag: float = 5.0) -> float:
    """Delay of `filtered` behind `raw`, in frames (sub-frame), from the shift that best aligns them."""
    shifts = np.arange(0.0, max_lag + 1e-9, 0.05)
    n = raw.shape[0]
    t = np.arange(n, dtype=np.float64)
    errs = []
    for s in shifts:  # compare filtered(t) with raw(t - s), raw linearly interpolated
        ts = t[int(math.ceil(s)):] - s
        lo = np.floor(ts).astype(int)
        frac = (ts - lo)[:, None, None]
        hi = np.minimum(lo + 1, n - 1)
        shifted = raw[lo] * (1 - frac) + raw[hi] * frac
        errs.append(np.mean(np.sum((filtered[int(math.ceil(s)):] - shifted) ** 2, axis=-1)))
    return float(shifts[int(np.argmin(errs))])
