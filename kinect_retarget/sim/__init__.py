"""Simulation and ground truth (pure numpy): the emulated Kinect v1 (a pyusb backend), synthetic depth of
real mocap on the MakeHuman body, test imagery for the 2D tracker, and the scores the tests and benchmarks
measure against. The simulated Kinect is a product feature, so this ships; but only sim/ itself and the
simulated-device entry point (sources/simulated_kinect.py) import it (tests/core/test_layering.py)."""
