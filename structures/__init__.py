"""Structures (issue 3, not built yet): stresses at weak joints from the recorded joint loads,
failure verdicts and released secondary debris. Nothing here yet."""
