"""BaggedRegression: the crate's cross-validated regression with bagged members, as a
PySINDy-compatible optimizer with coefficient intervals and a predictive band."""

import warnings

import numpy as np
import pysindy as ps
import pytest

import learn_sysid as ls
from systems import pendulum_forced

TRUE = np.array([[0.0, 0.0, 1.0, 0.0], [0.0, -4.0, -0.3, 1.0]])  # [1, θ, ω, u] → [θ', ω']


def library_and_targets(noise=0.05, seed=4):
    t, x, u = pendulum_forced(n=3000, dt=0.01)
    theta = np.column_stack([np.ones(len(t)), x, u])
    y = theta @ TRUE.T + noise * np.random.default_rng(seed).standard_normal((len(t), 2))
    return theta, y


def test_intervals_cover_the_truth_over_noise_draws_and_the_band_the_targets():
    # Nominal 95 % intervals of the four true terms over 20 noise draws: at least 80 % cover the
    # truth (a moving-block bootstrap's percentile interval runs a little short), and none is wide.
    covered, total = 0, 0
    for seed in range(20):
        theta, y = library_and_targets(seed=seed)
        model = ls.BaggedRegression(penalty="stlsq", members=30, block=100, seed=7).fit(theta, y)
        low, high = model.coef_interval_
        assert model.coef_members_.shape == (30, 2, 4)
        for i, j in zip(*np.nonzero(TRUE)):
            covered += low[i, j] <= TRUE[i, j] <= high[i, j]
            total += 1
            assert high[i, j] - low[i, j] < 0.05
        np.testing.assert_allclose(model.coef_, TRUE, atol=0.02)
    assert covered >= 0.8 * total, (covered, total)
    mean, lower, upper = model.predict_band(theta)
    assert np.all(lower <= mean) and np.all(mean <= upper)
    inside = np.mean((lower <= y) & (y <= upper))
    assert 0.85 <= inside <= 1.0, inside


def test_the_seed_decides_the_members():
    theta, y = library_and_targets()
    first = ls.BaggedRegression(members=5, block=100, seed=1).fit(theta, y).coef_members_
    again = ls.BaggedRegression(members=5, block=100, seed=1).fit(theta, y).coef_members_
    other = ls.BaggedRegression(members=5, block=100, seed=2).fit(theta, y).coef_members_
    np.testing.assert_array_equal(first, again)
    assert not np.array_equal(first, other)


def test_inside_pysindy():
    t, x, u = pendulum_forced(n=3000, dt=0.01)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = ps.SINDy(optimizer=ls.BaggedRegression(members=10, block=100),
                         feature_library=ps.PolynomialLibrary(1) + ps.FourierLibrary(1))
        model.fit(x, t=0.01, u=u)
    c = dict(zip(model.get_feature_names(), model.coefficients()[1]))
    assert c["sin(1 x0)"] == pytest.approx(-4.0, rel=0.01) and c["u0"] == pytest.approx(1.0, rel=0.02)
    assert model.optimizer.coef_interval_.shape == (2, 2, len(c))


def test_bad_settings_name_the_field():
    theta, y = library_and_targets()
    with pytest.raises(ls.LearnSysidError, match="bagging.members"):
        ls.BaggedRegression(members=1).fit(theta, y)
    with pytest.raises(ls.LearnSysidError, match="penalty"):
        ls.BaggedRegression(penalty="sr3").fit(theta, y)
    with pytest.raises(TypeError, match="BaggedRegression"):
        ls.SINDy(optimizer=ls.BaggedRegression())
