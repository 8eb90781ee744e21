"""What a bake does beyond the retarget: which part of the take, how often to key, key reduction, where the
keys go (new or current Action, NLA strip) and whether the scene's rate and range may change. One value shared
by the operator, the sidebar and the CLI; the scene is the user's, so every option that changes it is off."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .foot_lock import FEET_MODES
from .take import Take, TakeError

RANGE_UNITS = ("seconds", "frames")
HAND_MODES = ("auto", "on", "off")  # auto: on for takes with Kinect v2's hand joints, off otherwise


@dataclass(frozen=True)
class BakeOptions:
    range_start: float | None = None   # part of the take to bake, in range_unit; None = from its start
    range_end: float | None = None     # ... None = to its end (inclusive)
    range_unit: str = "seconds"        # seconds from the take's start, or take frames counted from 0
    step: int = 1                      # key every `step` scene frames
    reduce: bool = False               # drop keys that linear interpolation reproduces within tolerance
    tolerance_deg: float = 0.5
    tolerance_mm: float = 1.0
    into_current: bool = False         # key into the rig's current Action instead of a new one
    push_nla: bool = False             # push the baked Action to the NLA as a strip named after the take
    set_scene_fps: bool = False        # run the scene at the bake's rate
    extend_scene_range: bool = False   # grow the scene's frame range to hold the keys (never shrinks it)
    hands: str = "auto"                # thumb roll, hand-tip bend, hand-state curls on rigs with fingers
    feet: str = "lock"                 # lock: planted feet pinned and kept above the floor; floor: only the
                                       # floor; off (core/foot_lock.py)
    root_motion: bool = False          # the performer's horizontal travel on the rig's root bone (game engines)
    root_motion_facing: bool = False   # ... and their heading about the up axis
    root_bone: str | None = None       # the bone to carry it; None = the top ancestor of the hips bone
    keys_on_samples: bool = False      # key each sample at its nearest frame, no resampling (live's recording:
                                       # the baked keys equal the poses live showed)

    def __post_init__(self) -> None:
        if self.range_unit not in RANGE_UNITS:
            raise ValueError(f"unknown range unit {self.range_unit!r} (choose from {', '.join(RANGE_UNITS)})")
        if self.hands not in HAND_MODES:
            raise ValueError(f"unknown hands mode {self.hands!r} (choose from {', '.join(HAND_MODES)})")
        if self.feet not in FEET_MODES:
            raise ValueError(f"unknown feet mode {self.feet!r} (choose from {', '.join(FEET_MODES)})")
        if self.step < 1:
            raise ValueError(f"key step must be at least 1 frame, got {self.step}")
        if self.reduce and not (self.tolerance_deg > 0 and self.tolerance_mm > 0):
            raise ValueError("key reduction needs positive tolerances in degrees and millimetres")
        if self.into_current and self.push_nla:
            raise ValueError("choose one: key into the current Action or push a new one to the NLA")
        if self.range_start is not None and self.range_end is not None and self.range_end < self.range_start:
            raise ValueError(f"take range ends ({self.range_end}) before it starts ({self.range_start})")


def take_range(take: Take, options: BakeOptions) -> tuple[Take, str]:
    """The part of `take` the options ask for, and a short description of it ("" for the whole take).
    Raises TakeError when the range holds no sample."""
    if options.range_start is None and options.range_end is None:
        return take, ""
    n = take.frame_count
    if options.range_unit == "frames":
        lo = 0 if options.range_start is None else int(np.ceil(options.range_start))
        hi = n - 1 if options.range_end is None else int(np.floor(options.range_end))
        keep = np.arange(max(lo, 0), min(hi, n - 1) + 1)
        label = f"take frames {lo}-{hi}"
    else:
        t = take.times - take.times[0]
        lo = -np.inf if options.range_start is None else options.range_start
        hi = np.inf if options.range_end is None else options.range_end
        keep = np.flatnonzero((t >= lo - 1e-9) & (t <= hi + 1e-9))
        label = f"take {max(lo, 0):g}-{min(hi, float(t[-1])):g} s"
    if keep.size == 0:
        raise TakeError(f"the range ({label}) holds no sample of the take "
                        f"({n} frames, {take.duration:.2f} s)")
    return take.slice(keep), label
