"""Names and units of the measured channels, shared by the models that predict them
(:mod:`riskassess.diagnosis.observation`, :mod:`riskassess.diagnosis.plants.towing_plant`) and the
readers and fits that compare them.

Channels (SI): ``omega_x..z`` inertial angular velocity of the main body, its own frame B
(rad/s, a gyro); ``q_w..q_z`` attitude B->LVLH (unit quaternion, scalar first);
``hinge_angle`` (rad) and ``hinge_rate`` (rad/s); ``rel_x..z`` the target-frame origin
relative to the chaser, LVLH (m); ``tether_tension`` (N, towing only); ``vel_x..z`` the main
body's CoM velocity relative to the chaser, LVLH axes, the time derivative of its LVLH position
(m/s, impact scenario only).
"""
OMEGA = ("omega_x", "omega_y", "omega_z")
QUATERNION = ("q_w", "q_x", "q_y", "q_z")
HINGE = ("hinge_angle", "hinge_rate")
REL = ("rel_x", "rel_y", "rel_z")
TENSION = ("tether_tension",)
VELOCITY = ("vel_x", "vel_y", "vel_z")
CHANNELS = OMEGA + QUATERNION + HINGE + REL + TENSION + VELOCITY
UNITS = {**{c: "rad/s" for c in OMEGA}, **{c: "-" for c in QUATERNION}, "hinge_angle": "rad",
         "hinge_rate": "rad/s", **{c: "m" for c in REL}, "tether_tension": "N", **{c: "m/s" for c in VELOCITY}}
