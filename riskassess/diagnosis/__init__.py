"""Model diagnosis: residuals against measured data, a catalog of candidate effects, fit and selection."""
from multibody.jit_cache import use_source_keyed_cache

use_source_keyed_cache()  # before any kernel is defined: a stale compiled kernel never loads
