"""Structures: weak locations and their sections, stresses from the recorded joint loads, allowables
and failure criteria, the verdict with its evidence rules (debris / no_debris / indeterminate), the
pieces a failed joint releases, and the net threads' tension check."""
