"""Launch velocity error: the net leaves the launcher faster or slower than the case says."""
from __future__ import annotations

from riskassess.diagnosis.effects.base import Parameter
from riskassess.diagnosis.impact_effects.base import ImpactEffect

#: Range of the error (-, of the launch speed): +-10 %, a spring or gas launcher's shot-to-shot scatter
#: is a few per cent.
RELATIVE_RANGE = 0.1


class LaunchVelocityError(ImpactEffect):
    id = "launch_velocity_error"
    title = "Launch speed of the net differs from the case's (same direction)"

    def parameter(self, impact_case) -> Parameter:
        """The speed error dv (m/s), fitted linearly in +-10 % of the launch speed."""
        span = RELATIVE_RANGE * impact_case.launch.velocity
        return Parameter("launch_speed_error", "m/s", "launch speed minus the case's", 0.0, -span, span)

    def case_value(self, impact_case) -> float:
        """0 (m/s): the case's launch speed."""
        return 0.0

    def overrides(self, impact_case, value: float) -> dict:
        """``launch.velocity`` = the case's + value (m/s)."""
        return {"launch.velocity": float(impact_case.launch.velocity + value)}


EFFECT = LaunchVelocityError()
