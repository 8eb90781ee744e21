"""Where every Kinect panel sits. Its own module, importing nothing, so that any ui module (the takes list, the
USB panel, which live/ imports) can use it without importing panels.py and, through it, live/."""


class KinectSidebarPanel:
    """The 3D View sidebar's Kinect tab (mixed into each Panel class)."""
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "Kinect"
