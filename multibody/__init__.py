"""Exudyn models of the net capture: net, contact, joints, orbit and the coupled impact system."""
