"""Model diagnosis: residuals against measured data, a catalog of candidate effects, fit and selection."""
