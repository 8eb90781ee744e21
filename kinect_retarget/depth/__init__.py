"""Skeletons from Kinect v1 depth without Microsoft's SDK (pure numpy), and a synthetic Kinect to test it.

* `SkeletonTracker().update(depth_mm (480, 640) uint16, timestamp) -> (positions (20, 3), states (20,))`
  (Kinect v1 joints, Kinect camera space metres, states 0/1/2) is the live API; `track_depth_frames`
  turns a whole capture into a Take.
* `synthetic.render_sequence` renders CMU mocap on the MakeHuman body as Kinect depth with ground truth.

No bpy here: this package is used from threads and headless tools.
"""
from __future__ import annotations

__all__ = ["SkeletonTracker", "track_depth_frames"]


def __getattr__(name):  # keep `import kinect_retarget.depth` cheap: load the tracker on first use
    if name in __all__:
        from . import tracker
        return getattr(tracker, name)
    raise AttributeError(name)
