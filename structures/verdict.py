"""The structures stage of a run: every weak location judged, every released piece reported."""
from __future__ import annotations

import numpy as np

from structures.release import ReleaseEvent, released_pieces
from structures.weak_location import WeakLocation, assess, demands

#: The three answers to "does this capture create secondary debris?" (``debris_state`` in
#: structures.json, the CLI, the report and the sweep store). ``secondary_debris`` carries the
#: same as True / False / None: None is "indeterminate" (a failed or diverged run, or no judged
#: evidence), which no consumer may read as "no debris".
DEBRIS, NO_DEBRIS, INDETERMINATE = "debris", "no_debris", "indeterminate"
DEBRIS_STATES = (DEBRIS, NO_DEBRIS, INDETERMINATE)


def structures_verdict(locations: list[WeakLocation], series: dict, assembly, events: list[ReleaseEvent],
                       net_positions_final, skip_until: float, policy: str) -> dict:
    """JSON-ready verdict: per location the criteria, margins, likelihood and any release."""
    time = series["time"]
    released_at = {e.location: e for e in events}
    rows = []
    for loc in locations:
        result = assess(loc, time, series["joint_force_joint"][:, loc.joint], series["joint_moment_joint"][:, loc.joint],
                        skip_until, policy if policy != "never" else "low")
        result["joint"] = assembly.joints[loc.joint].name
        event = released_at.get(loc.name)
        result["released_at_s"] = event.time if event else None
        # After a release the location carries nothing, so its peak (and likelihood) only
        # covers the loads up to the release: a lower bound of what the intact joint would see.
        result["likelihood_is_lower_bound"] = event is not None
        rows.append(result)
    pieces = released_pieces(events, assembly, series, net_positions_final)
    return {"skip_initial_s": skip_until, "release_policy": policy, "locations": rows, "released_pieces": pieces,
            "secondary_debris": bool(pieces) or any(r["fails"] for r in rows)}


def demand_series(locations: list[WeakLocation], series: dict) -> dict:
    """Per location and demand, the time series (SI), keyed ``<location>/<demand>``, for the run folder."""
    out = {"time": series["time"]}
    for loc in locations:
        for name, values in demands(loc, series["joint_force_joint"][:, loc.joint],
                                    series["joint_moment_joint"][:, loc.joint]).items():
            out[f"{loc.name}/{name}"] = np.asarray(values)
    return out
