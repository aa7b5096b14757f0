"""Pictures of a run: 3-D snapshots, an animation and an offline interactive viewer (:mod:`.products`)."""
