"""Fits of a registered pose sequence: correlation time of the residuals."""
import numpy as np
import pytest
from scipy.signal import lfilter
from scipy.spatial.transform import Rotation

from perception.motion import integrated_autocorrelation_time, isotropic_attitude_weights


def _ar1(phi, k, d, rng):
    """AR(1) series x_k = phi x_(k-1) + e_k, (k, d), stationary start."""
    e = rng.normal(size=(k, d))
    e[0] /= np.sqrt(1 - phi**2)
    return lfilter([1.0], [1.0, -phi], e, axis=0)


@pytest.mark.parametrize("seed", range(5))
@pytest.mark.parametrize("phi", [0.0, 0.6])
def test_correlation_time_of_ar1_noise(phi, seed):
    # AR(1): rho(lag) = phi^lag, so tau = 1 + 2 sum phi^lag = (1 + phi) / (1 - phi) (1 for white
    # noise, 4 for phi = 0.6). With 3 x 20000 samples the estimate scatters by ~2 % and the
    # truncation at the first non-positive lag drops a tail below 1 %: 7 % is > 3 sigma.
    rng = np.random.default_rng(seed)
    tau = integrated_autocorrelation_time(_ar1(phi, 20000, 3, rng))
    assert tau == pytest.approx((1 + phi) / (1 - phi), rel=0.07)


def test_correlated_errors_widen_the_mean_sigma_to_its_scatter():
    # The white-noise sigma of a mean, times sqrt(tau), matches the scatter of the mean over many
    # AR(1) series (variance of a correlated mean = sigma^2 tau / k); 15 % covers the scatter of
    # a standard deviation from 400 trials (~3.5 %) and of tau (~5 % with 2000 samples).
    rng = np.random.default_rng(1)
    series = [_ar1(0.7, 2000, 1, rng) for _ in range(400)]
    predicted = np.mean([s.std() * np.sqrt(integrated_autocorrelation_time(s) / len(s)) for s in series])
    assert predicted == pytest.approx(np.std([s.mean() for s in series]), rel=0.15)


def test_isotropic_weights_keep_the_frame_information_volume():
    # s^3 = |det W|: the isotropic weight has the same information volume as the frame's own
    # (a rotated diag(1, 2, 32) -> s = 4), exactly up to round-off.
    turn = Rotation.from_rotvec([0.3, -1.1, 0.7]).as_matrix()
    w = np.array([turn @ np.diag([1.0, 2.0, 32.0]) @ turn.T, np.diag([5.0, 5.0, 5.0])])
    iso = isotropic_attitude_weights(w)
    assert iso[0] == pytest.approx(4.0 * np.eye(3), abs=1e-12)
    assert iso[1] == pytest.approx(5.0 * np.eye(3), abs=1e-12)
