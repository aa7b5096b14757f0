"""Uncertain inputs of a case: ``KEY=DIST(params)``, the grammar shared by the ``[monte_carlo]``
table of an impact case, ``riskassess assess --uncertain`` and ``riskassess sweep --uncertain``.

Keys address the case file as dotted paths; list items are picked by their ``name`` or by index
(``contact.mu_kinetic``, ``target.joints[solar_array_hinge].torsional_damping``). Whether a key
exists in a case is checked when the sampled cases are validated, before any run.
"""
from __future__ import annotations

import math
import re

import numpy as np

#: name -> (parameter names, sampler(rng, n, *params)); all parameters in the key's SI unit.
DISTRIBUTIONS = {
    "uniform": (("low", "high"), lambda rng, n, a, b: rng.uniform(a, b, n)),
    "normal": (("mean", "std"), lambda rng, n, m, s: rng.normal(m, s, n)),
    "lognormal": (("median", "sigma_log"), lambda rng, n, med, s: med * np.exp(rng.normal(0.0, s, n))),
    "triangular": (("low", "mode", "high"), lambda rng, n, a, c, b: rng.triangular(a, c, b, n)),
}
#: name -> check(params) -> problem or None: the parameter ranges each distribution accepts.
DISTRIBUTION_CHECKS = {
    "uniform": lambda a, b: None if a < b else "low < high",
    "normal": lambda m, s: None if s >= 0 else "std >= 0",
    "lognormal": lambda med, s: None if med > 0 and s >= 0 else "median > 0 and sigma_log >= 0",
    "triangular": lambda a, c, b: None if a <= c <= b and a < b else "low <= mode <= high and low < high",
}
KEY_TOKEN = re.compile(r"([A-Za-z_][A-Za-z0-9_]*)((?:\[[^\]]+\])*)")


class SweepSpecError(ValueError):
    """A --vary or --uncertain argument that cannot be used; the message says what is allowed."""


def parse_uncertain(text: str) -> tuple[str, str, tuple]:
    """'KEY=DIST(a,b)' -> (key, distribution name, parameters).

    Parameters
    ----------
    text : str
        One uncertain input, ``KEY=DIST(p1, p2, ...)`` with DIST in :data:`DISTRIBUTIONS`.

    Returns
    -------
    key : str
        Dotted case key.
    name : str
        Distribution name.
    params : tuple of float
        Its parameters, in the key's SI unit (``sigma_log`` is dimensionless).

    Raises
    ------
    SweepSpecError
        For bad syntax, an unknown distribution, a wrong number of parameters or parameters out
        of range.
    """
    key, _, spec = text.partition("=")
    match = re.fullmatch(r"\s*([a-z]+)\s*\(([^)]*)\)\s*", spec)
    allowed = ", ".join(f"{name}({', '.join(p)})" for name, (p, _) in DISTRIBUTIONS.items())
    if not match or match.group(1) not in DISTRIBUTIONS:
        raise SweepSpecError(f"--uncertain {text!r}: expected KEY=DIST(...) with DIST one of {allowed}")
    name = match.group(1)
    try:
        params = tuple(float(v) for v in match.group(2).split(","))
    except ValueError:
        raise SweepSpecError(f"--uncertain {text!r}: parameters must be numbers") from None
    if len(params) != len(DISTRIBUTIONS[name][0]):
        raise SweepSpecError(f"--uncertain {text!r}: {name} takes {len(DISTRIBUTIONS[name][0])} parameters "
                             f"({', '.join(DISTRIBUTIONS[name][0])}); got {len(params)}")
    if not all(math.isfinite(p) for p in params):
        raise SweepSpecError(f"--uncertain {text!r}: parameters must be finite numbers")
    problem = DISTRIBUTION_CHECKS[name](*params)
    if problem:
        raise SweepSpecError(f"--uncertain {text!r}: {name}({', '.join(DISTRIBUTIONS[name][0])}) needs {problem}")
    check_key(key, "--uncertain", text)
    return key, name, params


def check_key(key: str, option: str, text: str) -> None:
    """SweepSpecError when ``key`` is not shaped like a case key (dotted names, optional ``[item]``).

    Parameters
    ----------
    key : str
        The key, such as ``target.joints[solar_array_hinge].torsional_damping``.
    option : str
        The command-line option it came from, named in the error.
    text : str
        The whole argument, quoted in the error.
    """
    if not key or not all(KEY_TOKEN.fullmatch(part) for part in split_key(key)):
        raise SweepSpecError(f"{option} {text!r}: '{key}' is not a case key like launch.velocity or "
                             f"target.joints[solar_array_hinge].torsional_damping")


def split_key(key: str) -> list[str]:
    """The dotted parts of a case key, each with its ``[item]`` selectors.

    Parameters
    ----------
    key : str
        A case key, e.g. ``target.joints[hinge].torsional_damping``.

    Returns
    -------
    list of str
        E.g. ``["target", "joints[hinge]", "torsional_damping"]``.
    """
    return re.findall(r"[^.\[]+(?:\[[^\]]+\])*", key)


