"""The stages a user runs (run/assess, perceive, tow, identify, approach, diagnose) and the
work estimate checked before any of them starts."""
