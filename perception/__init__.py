"""Perception: synthetic LiDAR scans, Open3D registration of the debris and tracking of the net,
and the debris' centre of mass, inertia ratios, mass and principal moments estimated from its free
motion and the momentum balance of the net collision (Tang et al. 2023)."""
from multibody.jit_cache import use_source_keyed_cache

use_source_keyed_cache()  # before any kernel is defined: a stale compiled kernel never loads
