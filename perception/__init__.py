"""Perception (issue 6, not built yet): synthetic LiDAR, Open3D registration, mass and inertia
estimation from the debris motion and the net collision. Nothing here yet."""
