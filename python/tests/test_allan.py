"""`ttalloc.allan` on a NumPy array: the library's Allan deviation, the array read in place."""

import numpy as np
import pytest

import ttalloc

RATE_HZ = 100.0
SIGMA = 0.1


def white(n: int, seed: int = 7) -> np.ndarray:
    return np.random.default_rng(seed).normal(0.0, SIGMA, n)


#: The library's estimator and the direct sum below add the same ~2e5 squared terms in a
#: different order: rounding, relative.
SUM_ORDER_REL = 1e-12


def test_curve_equals_an_independent_numpy_overlapping_allan_deviation():
    # below the overlap factor every cluster start is used (fully overlapping): the library's
    # streaming estimator equals the textbook sum over the phase x = cumsum(y) / rate
    y = white(200_000)
    a = ttalloc.allan(y, RATE_HZ)
    overlap = a.to_dict()["overlap"]
    phase = np.concatenate([[0.0], np.cumsum(y)]) / RATE_HZ
    checked = 0
    for tau, adev in zip(a.tau_s, a.adev):
        m = int(round(tau * RATE_HZ))
        if m > overlap:
            continue
        d = phase[2 * m :] - 2.0 * phase[m:-m] + phase[: -2 * m]
        assert adev == pytest.approx(np.sqrt(np.mean(d * d) / (2.0 * tau * tau)), rel=SUM_ORDER_REL)
        checked += 1
    assert checked >= 8
    assert a.tau_s[0] == pytest.approx(1.0 / RATE_HZ)
    assert a.samples == 200_000
    # N = sigma / sqrt(rate) (unit/sqrt(Hz)): the fit's estimate of white noise, to a few percent
    assert a.white_noise_per_sqrt_hz == pytest.approx(SIGMA / np.sqrt(RATE_HZ), rel=0.03)


def test_results_are_numpy_arrays_and_to_dict_has_the_cli_keys():
    a = ttalloc.allan(white(10_000), RATE_HZ)
    for arr in (a.tau_s, a.adev, a.lower, a.upper):
        assert isinstance(arr, np.ndarray) and arr.dtype == np.float64
        assert arr.shape == a.tau_s.shape
    d = a.to_dict()
    for key in ("samples", "rate_hz", "white_noise_per_sqrt_hz", "bias_instability", "curve"):
        assert key in d
    assert np.array_equal(d["curve"]["adev"], a.adev)


def test_the_array_is_read_in_place_not_copied_and_left_unchanged():
    # the promise: a C-contiguous float64 array is read where it lies (a read-only view is
    # accepted, nothing is written), and no answer shares memory with it
    x = white(50_000)
    before = x.copy()
    view = x.view()
    view.flags.writeable = False
    a = ttalloc.allan(view, RATE_HZ)
    assert np.array_equal(x, before)
    for arr in (a.tau_s, a.adev, a.lower, a.upper):
        assert not np.shares_memory(arr, x)
    # anything that would need a copy is refused rather than copied (test_errors.py)
    with pytest.raises(ttalloc.InputError):
        ttalloc.allan(x[::2], RATE_HZ)


def test_same_samples_same_curve_as_the_library_on_a_copy():
    x = white(20_000)
    a = ttalloc.allan(x, RATE_HZ)
    b = ttalloc.allan(np.array(x, copy=True), RATE_HZ)
    assert np.array_equal(a.adev, b.adev)
