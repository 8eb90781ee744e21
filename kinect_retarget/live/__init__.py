"""Live puppeteering without bpy: the session (the pump), statistics and recording. The frames it
pumps come from sources/; the solver maths (including calibration) is in core/."""
