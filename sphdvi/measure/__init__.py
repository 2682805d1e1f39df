"""Measurement: kernel interpolation at points, free-surface elevation, forces on
boundaries, body motion, and run-time gauges (the MeasureTool, ComputeForces and
FloatingInfo of DualSPHysics)."""
