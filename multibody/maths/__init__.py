"""Shared maths of every package: 3-vector algebra (``linalg3``), rotations and quaternions
(``rotations``), the compiled RK4 integrator (``rk4``) and the plug-in discovery (``plugins``).

Nothing here imports anything of ours, so every room may use it without a cycle
(docs/architecture.md, "Layers").
"""
