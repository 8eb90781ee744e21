"""Skeletons from Kinect v1 depth without Microsoft's SDK (pure numpy): the depth tracker.

* `SkeletonTracker().update(depth_mm (480, 640) uint16, timestamp) -> (positions (20, 3), states (20,))`
  (Kinect v1 joints, Kinect camera space metres, states 0/1/2) is the live API; `track_depth_frames`
  turns a whole capture into a Take, cleaned with its future frames as only a recording allows
  (take_smoothing.py).
* Synthetic depth to test it (CMU mocap on the MakeHuman body, with ground truth) is in sim/synthetic_depth.py.

No bpy here: this package is used from threads and headless tools.
"""
from __future__ import annotations

__all__ = ["SkeletonTracker", "track_depth_frames"]


def __getattr__(name):  # keep `import kinect_retarget.depth` cheap: load the tracker on first use
    if name in __all__:
        from . import skeleton_tracker
        return getattr(skeleton_tracker, name)
    raise AttributeError(name)
