"""Controllers and guidance: MU approach optimal control, tether elongation MRAC, attitude control."""
