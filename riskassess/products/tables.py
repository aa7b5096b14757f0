"""Rows of the tables people read, as plain strings: the CLI prints them with rich, the
report renders them as HTML. One place decides what a verdict or a summary row says."""
from __future__ import annotations

VERDICT_COLUMNS = ("location", "criterion", "max demand", "at", "allowable", "margin", "fails?", "likelihood",
                   "released piece")


def format_value(value: float, unit: str) -> str:
    """A value with its unit; stresses in MPa.

    Parameters
    ----------
    value : float
        The value in SI unit ``unit``.
    unit : str
        Its unit; ``"Pa"`` is shown in MPa.
    """
    scale, shown = (1e-6, "MPa") if unit == "Pa" else (1.0, unit)
    return f"{value * scale:.4g} {shown}"


def format_allowable(low: float, high: float, unit: str) -> str:
    """An allowable (range) with its unit: one value when both ends agree, else 'low - high'.

    Parameters
    ----------
    low, high : float
        Ends of the allowable, in SI unit ``unit``.
    unit : str
        Their unit; ``"Pa"`` is shown in MPa.
    """
    return format_value(low, unit) if low == high else f"{format_value(low, unit)} - {format_value(high, unit)}"


def format_margin(margin: float) -> str:
    """Margin of safety: two decimals near failure, three significant digits when it is large.

    Parameters
    ----------
    margin : float
        Margin of safety (-), allowable / demand - 1.
    """
    return f"{margin:+.2f}" if abs(margin) < 100 else f"{margin:+.3g}"


def format_vector(values, digits: int = 3) -> str:
    """A vector as '[a, b, c]' with ``digits`` significant digits.

    Parameters
    ----------
    values : sequence of float
        The components (any unit; the caller names it).
    digits : int
        Significant digits per component.
    """
    return "[" + ", ".join(f"{v:.{digits}g}" for v in values) + "]"


def piece_text(piece: dict) -> str:
    """'solar_array, 350 kg, 14.3 x 5 m, at 0.744 s'.

    Parameters
    ----------
    piece : dict
        A released piece of the structural verdict: ``bodies``, ``mass_kg``, ``size_m`` (extents,
        m), ``release_time_s``.
    """
    size = " x ".join(f"{e:.3g}" for e in piece["size_m"][:2])
    return f"{'+'.join(piece['bodies'])}, {piece['mass_kg']:.4g} kg, {size} m, at {piece['release_time_s']:.3f} s"


#: What the "fails?" column says for each location state (structures.verdict.location_state).
STATE_TEXT = {"fails": "FAIL", "holds": "pass", "indeterminate": "indeterminate"}
#: The one-line answer for each debris state (structures.verdict.DEBRIS_STATES).
DEBRIS_TEXT = {"debris": "YES", "no_debris": "none", "indeterminate": "INDETERMINATE"}


def debris_line(verdict: dict) -> str:
    """'secondary debris: YES | none | INDETERMINATE (why)'; a verdict from before the three states
    counts as its boolean.

    Parameters
    ----------
    verdict : dict
        The structural verdict (``structures.json``): ``debris_state`` or ``secondary_debris``,
        and ``indeterminate_reasons``.
    """
    state = verdict.get("debris_state") or ("debris" if verdict["secondary_debris"] else "no_debris")
    line = f"secondary debris: {DEBRIS_TEXT[state]}"
    if state == "indeterminate":
        line += " (" + "; ".join(verdict.get("indeterminate_reasons") or ["no evidence"]) + ")"
    return line


def location_state(loc: dict) -> str:
    """'fails' | 'holds' | 'indeterminate' of a verdict row (older folders: from ``fails``).

    Parameters
    ----------
    loc : dict
        One entry of the verdict's ``locations``.
    """
    return loc.get("state") or ("fails" if loc["fails"] else "holds")


def _criterion_state(criterion: dict, state_of_location: str) -> str:
    """A criterion row's state: its own exceedance, else its location's lack of evidence, else a pass."""
    if criterion["fails"]:
        return "fails"
    if criterion["peak"] is None or state_of_location == "indeterminate":
        return "indeterminate"
    return "holds"


def _or_dash(value, text) -> str:
    return "-" if value is None else text(value)


def verdict_rows(verdict: dict) -> list[dict]:
    """One row per location and criterion, keyed by :data:`VERDICT_COLUMNS`; ``fails`` stays a bool,
    ``state`` is the location's state ('fails', 'holds', 'indeterminate').

    Likelihoods of released locations read '>= x': their loads after the release are not
    known, so the value is a lower bound.

    Parameters
    ----------
    verdict : dict
        The structural verdict (``structures.json``): ``locations`` with their ``criteria``
        (``peak``, ``unit``, ``allowable``, ``margin_of_safety``, ...) and ``released_pieces``.

    Returns
    -------
    list of dict
        Rows keyed by :data:`VERDICT_COLUMNS` plus ``fails`` and ``state``.
    """
    pieces = {p["location"]: p for p in verdict["released_pieces"]}
    rows = []
    for loc in verdict["locations"]:
        piece = pieces.get(loc["name"])
        for k, (name, c) in enumerate(loc["criteria"].items()):
            rows.append({
                "location": loc["name"] if k == 0 else "",
                "criterion": f"{name} ({c['mode']})",
                "max demand": _or_dash(c["peak"], lambda v: format_value(v, c["unit"])),
                "at": f"{c['peak_time_s']:.3f} s" if c.get("peak_time_s") is not None else "-",
                "allowable": format_allowable(*c["allowable"], c["unit"]),
                "margin": _or_dash(c["margin_of_safety"], format_margin),
                "fails": bool(c["fails"]),
                "state": _criterion_state(c, location_state(loc)),
                "likelihood": _or_dash(c["likelihood"], lambda v: (">= " if loc["released_at_s"] is not None
                                                                   else "") + f"{v:.0%}"),
                "released piece": (piece_text(piece) if piece else "-") if k == 0 else "",
            })
    return rows


def piece_fate(piece: dict) -> str:
    """Where a released piece is at the end of the run, relative to the chaser (LVLH).

    Parameters
    ----------
    piece : dict
        A released piece: ``velocity_relative_to_chaser_lvlh_m_s`` (3,) m/s LVLH,
        ``inside_net_at_end``, ``spin_rate_rad_s``.
    """
    v = piece["velocity_relative_to_chaser_lvlh_m_s"]
    return (f"at end {'inside' if piece['inside_net_at_end'] else 'OUTSIDE'} the net, velocity rel. chaser "
            f"{format_vector(v)} m/s LVLH, spin {piece['spin_rate_rad_s']:.3f} rad/s")


def summary_rows(summary: dict) -> list[tuple[str, str, str]]:
    """(quantity, this run, paper reference) rows of a run summary.

    Parameters
    ----------
    summary : dict
        A run summary (``summary.json``, :func:`riskassess.products.summary.run_summary`).
    """
    ref = summary["paper_reference"]
    f = summary["peak_contact_force_N"]
    m = summary["peak_contact_moment_about_debris_com_Nm"]
    dv = summary["debris_velocity_change_final_third_mean_lvlh_m_s"]
    est = summary["momentum_exchange_estimate_lvlh_m_s"]
    rows = [
        ("coupling", "sequential (the paper's method: net on the fixed target, then the recorded loads on the "
                     "free debris)" if summary.get("coupling") == "sequential" else "coupled (net and debris in one "
                                                                                     "system)", "sequential"),
        ("peak contact force (N)", f"{f['value']:.4g} at {f['time_s']:.3f} s", f"{ref['peak_contact_force_N']:.3g}"),
        ("peak contact moment (N m)", f"{m['value']:.4g} at {m['time_s']:.3f} s", f"{ref['peak_contact_moment_Nm']:.3g}"),
        ("debris along-track velocity change, mean of last third (m/s)", f"{dv[1]:.4f} (estimate {est[1]:.4f})",
         f"{ref['debris_along_track_velocity_simulated_m_s']}"),
    ]
    for name, j in summary["joints"].items():
        mom = j["max_abs_moment_after_transient_Nm"] or j["max_abs_moment_joint_Nm"]
        text = "/".join(f"{v:.3g}" for v in mom)
        if j["kind"] == "revolute":
            text += f"; angle {j['max_abs_angle_rad']:.4f} rad"
        paper = f"{ref['hinge_moment_h1_Nm']:.0f}/-/{ref['hinge_moment_h3_Nm']:.0f}" if j["kind"] == "revolute" else ""
        rows.append((f"{name}: |M| h1/h2/h3 after 0.25 s (N m)", text, paper))
    rows.append(("energy balance drift (rel.)", f"{summary['checks']['energy_balance_relative_drift']:.2e}", ""))
    rows.append(("wall time (s), steps/s", f"{summary['wall_time_s']:.1f}, {summary['steps_per_second']:.0f}", ""))
    return rows


def perception_rows(answer: dict) -> list[list[str]]:
    """Rows (quantity, estimate, 1 sigma, error vs truth) of a perception answer; a quantity the
    data could not determine reads 'not observable'.

    Parameters
    ----------
    answer : dict
        The perception answer (``perception.json``): estimates, their 1-sigma and errors, keys
        with their units (``mass_kg``, ``principal_moments_kg_m2``, ``center_of_mass_target_m``
        in the target frame, ...); a missing or None estimate is not observable.
    """
    def row(name, value, sigma, error, fmt="{:.5g}", error_fmt="{:+.3f} %"):
        if value is None:
            return [name, "not observable", "", ""]
        return [name, fmt.format(value), "" if sigma is None else fmt.format(sigma),
                "" if error is None else error_fmt.format(error)]

    rows = [row("mass (kg)", answer.get("mass_kg"), answer.get("mass_std_kg"), answer.get("mass_error_signed_percent"))]
    for k, axis in enumerate("ABC"):
        moments = answer.get("principal_moments_kg_m2")
        rows.append(row(f"principal moment {axis} (kg m^2)", moments and moments[k],
                        moments and answer["principal_moments_std_kg_m2"][k],
                        moments and answer["principal_moments_error_percent"][k]))
    for k, name in enumerate(("A/C", "B/C")):
        ratios = answer.get("inertia_ratios")
        rows.append(row(f"inertia ratio {name} (-)", ratios and ratios[k], ratios and answer["inertia_ratios_std"][k],
                        ratios and answer["inertia_ratio_error_percent"][k]))
    com = answer.get("center_of_mass_target_m")
    rows.append(["centre of mass, target frame (m)", "not observable" if com is None else format_vector(com, 4),
                 "" if com is None else format_vector(answer["center_of_mass_std_m"], 5),
                 "" if com is None else f"{answer['center_of_mass_error_m'] * 1e3:.2f} mm"])
    rows.append(row("normalized kinetic energy D = 2E/C (rad^2/s^2)", answer.get("normalized_kinetic_energy_D_rad2_s2"),
                    None, answer.get("normalized_kinetic_energy_error_percent")))
    rows.append(row("normalized angular momentum F = L^2/C^2 (rad^2/s^2)",
                    answer.get("normalized_angular_momentum_F_rad2_s2"), None,
                    answer.get("normalized_angular_momentum_error_percent")))
    rows.append(row("angular momentum direction error (deg)", answer.get("angular_momentum_direction_error_deg"),
                    None, None, "{:.3f}"))
    rows.append(row("registration (ms/frame)", answer["registration_ms_per_frame"], None, None, "{:.1f}"))
    rows.append(row("first frame global search (s)", answer["first_frame_search_s"], None, None, "{:.2f}"))
    rows.append(row("observation time used (s)", answer["observation_time_s"], None, None, "{:.1f}"))
    return rows
