"""Exudyn models of the net capture: net, contact, joints, orbit and the coupled impact system."""
from multibody.jit_cache import use_source_keyed_cache

use_source_keyed_cache()  # before any kernel is defined: a stale compiled kernel never loads
