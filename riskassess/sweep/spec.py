"""What a sweep runs: a grid of varied case keys times Monte Carlo samples of uncertain keys.

Keys address the case file as dotted paths; list items are picked by their ``name``
or by index: ``launch.velocity``, ``contact.mu_kinetic``,
``target.joints[solar_array_hinge].torsional_damping``, ``target.angular_velocity[2]``.

``--vary launch.velocity=10:30:5`` gives 10, 15, 20, 25, 30 (N values, ends included);
``--uncertain contact.mu_kinetic=uniform(0.1,0.2)`` draws from a distribution
(:data:`DISTRIBUTIONS`). Every run's overrides are validated into a case before anything
runs, and every run gets an id from its overrides, so a re-run of the same sweep finds
the runs it already finished.
"""
from __future__ import annotations

import copy
import hashlib
import itertools
import json
import math
import re
from dataclasses import dataclass

from riskassess.cases.uncertain import DISTRIBUTIONS, KEY_TOKEN, SweepSpecError, check_key, split_key

import numpy as np

#: Runs of one sweep above which ``--force`` is needed: 100 000 runs of the smallest case
#: (about 25 s each, docs/sweeps.md) are some 300 core-days, more than anyone asks by accident.
MAX_RUNS = 100_000
#: Runs of one sweep even with ``--force``: every run is a spec in memory and a row in the
#: store (about 1 kB each), so 10 million is about 10 GB.
HARD_MAX_RUNS = 10_000_000


@dataclass(frozen=True)
class RunSpec:
    run_id: str
    overrides: dict      # case key -> value (SI)
    grid_index: int      # which grid point (same varied values)
    sample: int          # Monte Carlo sample number at that grid point (0 without Monte Carlo)


def parse_vary(text: str) -> tuple[str, np.ndarray]:
    """'KEY=START:STOP:N' -> (key, N evenly spaced values, ends included).

    Parameters
    ----------
    text : str
        The ``--vary`` argument, e.g. ``"launch.velocity=10:30:5"`` (values in the key's SI unit).

    Returns
    -------
    key : str
        The dotted case key.
    values : (N,) float
        The values, ends included.
    """
    key, _, spec = text.partition("=")
    parts = spec.split(":")
    try:
        if len(parts) != 3:
            raise ValueError
        start, stop, n = float(parts[0]), float(parts[1]), int(parts[2])
        if n < 1 or not (math.isfinite(start) and math.isfinite(stop)):
            raise ValueError
    except ValueError:
        raise SweepSpecError(f"--vary {text!r}: expected KEY=START:STOP:N with finite numbers and N >= 1, "
                             f"e.g. launch.velocity=10:30:5") from None
    if n > HARD_MAX_RUNS:
        raise SweepSpecError(f"--vary {text!r}: N must be <= {HARD_MAX_RUNS} (the most runs of one sweep). "
                             f"Got {n} instead.")
    check_key(key, "--vary", text)
    return key, np.linspace(start, stop, n)


def set_key(raw: dict, key: str, value) -> None:
    """Set ``key`` in the parsed case file ``raw`` (in place); ``KeyError`` naming what is missing.

    Parameters
    ----------
    raw : dict
        The parsed case file (TOML), changed in place.
    key : str
        Dotted case key; list items by ``[name]`` or ``[index]``.
    value : float or object
        The new value (SI, as the case file takes it).
    """
    node = raw
    parts = split_key(key)
    for depth, part in enumerate(parts):
        name, selectors = KEY_TOKEN.fullmatch(part).groups()
        selectors = re.findall(r"\[([^\]]+)\]", selectors)
        last = depth == len(parts) - 1
        if not isinstance(node, dict) or name not in node:
            raise KeyError(f"'{key}': no key '{name}' at '{'.'.join(parts[:depth]) or 'top level'}'")
        if last and not selectors:
            node[name] = value
            return
        node = node[name]
        for k, selector in enumerate(selectors):
            item = _select(node, selector, key)
            if last and k == len(selectors) - 1:
                index = node.index(item) if isinstance(item, dict) else int(selector)
                node[index] = value
                return
            node = item


def _select(items, selector: str, key: str):
    if not isinstance(items, list):
        raise KeyError(f"'{key}': [{selector}] needs a list")
    if selector.lstrip("-").isdigit():
        try:
            return items[int(selector)]
        except IndexError:
            raise KeyError(f"'{key}': index {selector} out of range ({len(items)} items)") from None
    for item in items:
        if isinstance(item, dict) and item.get("name") == selector:
            return item
    names = [item.get("name") for item in items if isinstance(item, dict)]
    raise KeyError(f"'{key}': no item named '{selector}' (names: {names})")


def run_id(overrides: dict) -> str:
    """Stable id of a run from its overrides (values to 12 significant digits).

    Parameters
    ----------
    overrides : dict
        Dotted case key -> value (SI).

    Returns
    -------
    str
        12 hex digits.
    """
    canonical = json.dumps({k: float(f"{v:.12g}") for k, v in sorted(overrides.items())}, sort_keys=True)
    return hashlib.sha1(canonical.encode()).hexdigest()[:12]


def check_options(workers: int, confidence: float, reliability: float) -> None:
    """``workers`` >= 1; ``confidence`` and ``reliability`` strictly between 0 and 1.

    Parameters
    ----------
    workers : int
        ``--workers``, worker processes.
    confidence : float
        ``--confidence``.
    reliability : float
        ``--reliability``, required P(no debris).
    """
    if workers < 1:
        raise SweepSpecError(f"--workers must be >= 1. Got {workers} instead.")
    for name, value in (("confidence", confidence), ("reliability", reliability)):
        if not 0.0 < value < 1.0:
            raise SweepSpecError(f"--{name} must be between 0 and 1 (both excluded). Got {value} instead.")


def check_sweep(vary: list[tuple[str, np.ndarray]], uncertain: list[tuple[str, str, tuple]] = (),
                monte_carlo: int = 0, seed: int = 0, force: bool = False) -> int:
    """Check a sweep definition before any work; returns its number of runs.

    Each key at most once; ``--monte-carlo`` >= 0, and >= 1 exactly when there are uncertain
    keys; something to vary; ``seed`` >= 0; at most :data:`MAX_RUNS` runs unless ``force``,
    and never more than :data:`HARD_MAX_RUNS`.

    Parameters
    ----------
    vary : list of (str, (N,) float)
        Varied keys and their values (:func:`parse_vary`).
    uncertain : list of (str, str, tuple)
        Uncertain keys, distribution names and parameters
        (:func:`riskassess.cases.uncertain.parse_uncertain`).
    monte_carlo : int
        Samples per grid point (``--monte-carlo``).
    seed : int
        Seed of the random draw.
    force : bool
        Allow up to :data:`HARD_MAX_RUNS` runs.
    """
    keys = [key for key, _ in vary] + [key for key, _, _ in uncertain]
    repeated = sorted({k for k in keys if keys.count(k) > 1})
    if repeated:
        raise SweepSpecError(f"each key may be varied or uncertain once; repeated: {', '.join(repeated)}")
    if monte_carlo < 0:
        raise SweepSpecError(f"--monte-carlo must be >= 0. Got {monte_carlo} instead.")
    if uncertain and monte_carlo < 1:
        raise SweepSpecError("--uncertain needs --monte-carlo N (samples per grid point, N >= 1)")
    if monte_carlo and not uncertain:
        raise SweepSpecError(f"--monte-carlo {monte_carlo} needs --uncertain keys: without them every sample "
                             f"would be the same run")
    if not keys:
        raise SweepSpecError("nothing to sweep: give --vary KEY=START:STOP:N and/or --uncertain KEY=DIST(...)")
    if seed < 0:
        raise SweepSpecError(f"--seed must be >= 0. Got {seed} instead.")
    total = math.prod(len(values) for _, values in vary) * max(monte_carlo, 1)
    limit = HARD_MAX_RUNS if force else MAX_RUNS
    if total > limit:
        more = "" if force else f" without --force (at most {HARD_MAX_RUNS} with it)"
        raise SweepSpecError(f"the sweep has {total} runs; at most {limit} are allowed{more}")
    return total


def run_specs(vary: list[tuple[str, np.ndarray]], uncertain: list[tuple[str, str, tuple]] = (),
              monte_carlo: int = 0, seed: int = 0) -> list[RunSpec]:
    """The cartesian grid of ``vary``; at each grid point ``monte_carlo`` samples of ``uncertain``.

    The same samples are used at every grid point (common random numbers), so differences
    along the grid come from the varied keys, not from the draw.

    Parameters
    ----------
    vary : list of (str, (N,) float)
        Varied keys and their values (:func:`parse_vary`), values in the key's SI unit.
    uncertain : list of (str, str, tuple)
        Uncertain keys, distribution names and parameters
        (:func:`riskassess.cases.uncertain.parse_uncertain`).
    monte_carlo : int
        Samples per grid point; >= 1 when ``uncertain`` is given.
    seed : int
        Seed of ``numpy.random.default_rng``.

    Returns
    -------
    list of RunSpec
        Grid point by grid point, the samples of each in order.
    """
    if uncertain and monte_carlo < 1:
        raise SweepSpecError("--uncertain needs --monte-carlo N (samples per grid point, N >= 1)")
    rng = np.random.default_rng(seed)
    samples = [{} for _ in range(max(monte_carlo, 1))]
    for key, name, params in uncertain:
        values = DISTRIBUTIONS[name][1](rng, len(samples), *params)
        for sample, value in zip(samples, values):
            sample[key] = float(value)
    keys = [key for key, _ in vary]
    specs = []
    for g, values in enumerate(itertools.product(*(v for _, v in vary))):
        for m, sample in enumerate(samples):
            overrides = {**dict(zip(keys, map(float, values))), **sample}
            specs.append(RunSpec(run_id(overrides), overrides, g, m))
    return specs


def case_with(raw: dict, overrides: dict) -> dict:
    """A copy of the parsed case file with the overrides applied.

    Parameters
    ----------
    raw : dict
        The parsed case file (TOML); not changed.
    overrides : dict
        Dotted case key -> value (SI).
    """
    out = copy.deepcopy(raw)
    for key, value in overrides.items():
        set_key(out, key, value)
    return out
