"""Live puppeteering without bpy: queue, pump, statistics, recording and calibration maths."""
