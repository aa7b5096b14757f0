"""Monte Carlo spread of the free-flight fits: the registered attitudes' residuals about the fitted
torque-free motion resampled in blocks, the fits redone on each draw, and the spread of what they give.

Why: the fits' covariances (:class:`perception.euler_poinsot.TorqueFreeFit`) are first order in the
residuals, white noise scaled by the residuals' integrated autocorrelation time, and the after-collision fit
takes the inertia shape of the before fit as exact. On the featured debris (model-free, seed 3) the spin
per C before and after (h0, h1) each cost C 0.13-0.19 %, 1-2.4 times their stated shares (docs/perception.md,
"The re-acquisition's candidates, the propagation's limit and the moments' 1-sigma"). A resampling of the
residuals carries the registration's slowly varying error (the blocks keep its correlation), the fits'
nonlinearity and the shape's uncertainty into h1 (each draw refits the shape before and uses it after).

The residual bootstrap (Efron & Tibshirani 1993, An Introduction to the Bootstrap, ch. 9.5) with circular
moving blocks (Kuensch 1989, Ann. Statist. 17, 1217; Politis & Romano 1992): synthetic data = fitted values
+ residuals drawn as blocks of ``block`` consecutive frames. For a least-squares fit linear in its
parameters with white residuals its covariance tends to the analytic one times (n - p) / n
(tests/perception/test_fit_bootstrap.py).
"""
from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from perception.euler_poinsot import TorqueFreeFit

#: Draws of the free-flight Monte Carlo: the 1-sigma of a Gaussian spread is known to 1 / sqrt(2 (N - 1)),
#: 10 % with 50 draws [assumed: enough to tell a 1-sigma 2-3 times too small, the question asked].
DRAWS = 50
#: Block length of the resampling in integrated autocorrelation times of the residuals (at least one frame):
#: a block must span the residuals' correlation for the resampled series to keep it; 2 tau [assumed; the
#: optimal length grows as n^(1/3), Hall, Horowitz & Jing 1995, which for 60-200 frames is 4-6 frames].
BLOCK_TAUS = 2.0


def block_resampled(residuals, block, rng) -> np.ndarray:
    """A circular moving-block resample of ``residuals`` (k, d) (any unit, frame order): blocks of ``block``
    consecutive rows (wrapping round the end) starting at uniform random rows, cut to k rows.

    Parameters
    ----------
    residuals : (k, d) float    Residuals in frame order.
    block : int                 Block length (frames, >= 1); 1: the ordinary (white) bootstrap.
    rng : numpy.random.Generator

    Returns
    -------
    (k, d) float
    """
    residuals = np.asarray(residuals, float)
    k = len(residuals)
    block = int(min(max(block, 1), k))
    starts = rng.integers(0, k, int(np.ceil(k / block)))
    rows = (starts[:, None] + np.arange(block)[None, :]).ravel()[:k] % k
    return residuals[rows]


def block_length(correlation_time) -> int:
    """Frames per block (>= 1) for residuals of integrated autocorrelation time ``correlation_time``
    (frames): :data:`BLOCK_TAUS` times it, rounded up."""
    return max(1, int(np.ceil(BLOCK_TAUS * float(correlation_time))))


def resampled_attitudes(fit: TorqueFreeFit, times, body_to_world: Rotation, block, rng) -> Rotation:
    """Synthetic attitudes B->W (k,): the fitted motion at ``times`` (s) with the registered attitudes'
    residuals (rotation vectors, B frame, as the fit defines them: measured^-1 fitted) block-resampled.

    Parameters
    ----------
    fit : TorqueFreeFit        A fit through ``body_to_world`` at ``times``.
    times : (k,) float         Frame times (s).
    body_to_world : Rotation   The k registered attitudes B->W.
    block : int                Block length (frames).
    rng : numpy.random.Generator
    """
    fitted = fit.predict_body_to_world(times)
    residuals = (body_to_world.inv() * fitted).as_rotvec()
    return fitted * Rotation.from_rotvec(-block_resampled(residuals, block, rng))


def refit(fit: TorqueFreeFit, times, body_to_world: Rotation, weights, shape=None) -> TorqueFreeFit:
    """The torque-free fit redone on other attitudes B->W (k,) at ``times`` (s), started from ``fit``'s rate at
    the first frame (rad/s, B) and, when the shape is estimated, its shape; the whole span at once (no
    continuation: the start is within the resampled data's noise of the optimum). ``shape``: (normalized
    moments (3,), principal -> body (3, 3)) to hold instead of ``fit``'s own (a known-shape fit)."""
    times = np.asarray(times, float)
    rate = fit.rate_body_at(times[0])
    if shape is None and fit.moments is None:
        return TorqueFreeFit(first_span=np.inf).fit(times, body_to_world, weights, rate, fit.moments_,
                                                    fit.principal_to_body_)
    moments, principal_to_body = shape if shape is not None else (fit.moments, fit.principal_to_body)
    return TorqueFreeFit(moments, principal_to_body, first_span=np.inf).fit(times, body_to_world, weights, rate)


def spin_change_monte_carlo(before, after, attitudes_before: Rotation, weights_before, attitudes_after: Rotation,
                            weights_after, rng, draws=DRAWS) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Monte Carlo of the spin per C before and after a collision and their change: per draw, the before
    fit (shape estimated) and the after fit (with that draw's shape) redone on block-resampled attitudes.

    Parameters
    ----------
    before, after : perception.free_flight.FreeMotion
        The stage's free-flight fits (before: shape estimated; after: the before fit's shape).
    attitudes_before, attitudes_after : Rotation
        The registered attitudes B->W the fits went through, at ``before.times`` and ``after.times``.
    weights_before, weights_after : (k, 3, 3) float
        The fits' attitude weights (1/rad), as :func:`perception.free_flight.fit_free_motion` gave them.
    rng : numpy.random.Generator
    draws : int

    Returns
    -------
    h0 : (draws, 3) float       Spin per C before of each draw (rad/s, world).
    h1 : (draws, 3) float       Spin per C after (rad/s, world).
    moments : (draws, 3) float  The draws' normalized principal moments [A/C, B/C, 1] (-).
    """
    block0, block1 = block_length(before.fit.correlation_time_), block_length(after.fit.correlation_time_)
    h0, h1, moments = [], [], []
    for _ in range(draws):
        fit0 = refit(before.fit, before.times, resampled_attitudes(before.fit, before.times, attitudes_before, block0, rng),
                     weights_before)
        fit1 = refit(after.fit, after.times, resampled_attitudes(after.fit, after.times, attitudes_after, block1, rng),
                     weights_after, shape=(fit0.moments_, fit0.principal_to_body_))
        h0.append(fit0.spin_momentum_per_c()[0])
        h1.append(fit1.spin_momentum_per_c()[0])
        moments.append(fit0.moments_)
    return np.array(h0), np.array(h1), np.array(moments)
