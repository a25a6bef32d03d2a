"""learn_sysid's SINDy against PySINDy 2.1: coefficients, names, equations, predictions, scores;
our optimizers inside pysindy.SINDy; saved models across Python and the CLI; bad input."""

import io
import json
import warnings
from contextlib import redirect_stdout

import numpy as np
import pysindy as ps
import pytest

import learn_sysid as ls
from systems import lorenz_forced, pendulum_forced

TOLERANCE = 1e-8


def pysindy_fit(x, t, u, library, threshold=0.1, names=None):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = ps.SINDy(optimizer=ps.STLSQ(threshold=threshold), feature_library=library)
        return model.fit(x, t=t, u=u, feature_names=names)


CASES = {
    "lorenz with two controls, poly:2": (
        lorenz_forced,
        lambda: ps.PolynomialLibrary(degree=2),
        lambda: ls.PolynomialLibrary(degree=2),
        0.1,
    ),
    "pendulum with a control, poly:1 + fourier:1": (
        pendulum_forced,
        lambda: ps.PolynomialLibrary(degree=1) + ps.FourierLibrary(n_frequencies=1),
        lambda: ls.PolynomialLibrary(degree=1) + ls.FourierLibrary(n_frequencies=1),
        0.05,
    ),
    "pendulum with a control, poly:3 without constant": (
        pendulum_forced,
        lambda: ps.PolynomialLibrary(degree=3, include_bias=False),
        lambda: ls.PolynomialLibrary(degree=3, include_bias=False),
        0.05,
    ),
}


@pytest.mark.parametrize("case", CASES)
def test_coefficients_names_and_equations_equal_pysindy(case):
    system, theirs, ours, threshold = CASES[case]
    t, x, u = system()
    reference = pysindy_fit(x, t[1] - t[0], u, theirs(), threshold)
    model = ls.SINDy(optimizer=ls.STLSQ(threshold=threshold), feature_library=ours())
    model.fit(x, t=t[1] - t[0], u=u)
    np.testing.assert_allclose(model.coefficients(), reference.coefficients(), rtol=0, atol=TOLERANCE)
    assert model.get_feature_names() == reference.get_feature_names()
    assert model.equations() == reference.equations()
    assert model.equations(precision=5) == reference.equations(precision=5)
    ours_printed, theirs_printed = io.StringIO(), io.StringIO()
    with redirect_stdout(ours_printed):
        model.print()
    with redirect_stdout(theirs_printed):
        reference.print()
    assert ours_printed.getvalue() == theirs_printed.getvalue()
    np.testing.assert_allclose(model.predict(x, u=u), reference.predict(x, u=u), rtol=0, atol=1e-7)
    assert model.score(x, t=t[1] - t[0], u=u) == pytest.approx(reference.score(x, t=t[1] - t[0], u=u), abs=1e-10)
    assert model.complexity == reference.complexity


def test_several_trajectories_and_names_equal_pysindy():
    runs = [lorenz_forced(n=800, x0=x0, phase=p) for x0, p in [((-8, 8, 27), 0.0), ((5, -3, 20), 1.0), ((1, 1, 1), 2.0)]]
    xs, us = [r[1] for r in runs], [r[2] for r in runs]
    dt = runs[0][0][1]
    names = ["x", "y", "z", "f", "g"]
    reference = pysindy_fit(xs, dt, us, ps.PolynomialLibrary(degree=2), names=names)
    model = ls.SINDy().fit(xs, t=dt, u=us, feature_names=names)
    np.testing.assert_allclose(model.coefficients(), reference.coefficients(), rtol=0, atol=TOLERANCE)
    assert model.get_feature_names() == reference.get_feature_names()
    # one array of times for every trajectory, as PySINDy takes it
    same_times = ls.SINDy().fit(xs, t=runs[0][0], u=us, feature_names=names)
    np.testing.assert_allclose(same_times.coefficients(), reference.coefficients(), rtol=0, atol=TOLERANCE)
    predicted, expected = model.predict(xs, u=us), reference.predict(xs, u=us)
    assert len(predicted) == 3
    for ours, theirs in zip(predicted, expected):
        np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-7)


@pytest.mark.parametrize("case", list(CASES)[:2])
def test_our_stlsq_inside_pysindy_gives_pysindy_coefficients(case):
    system, theirs, _, threshold = CASES[case]
    t, x, u = system()
    reference = pysindy_fit(x, t[1] - t[0], u, theirs(), threshold)
    hosted = ps.SINDy(optimizer=ls.STLSQ(threshold=threshold), feature_library=theirs())
    hosted.fit(x, t=t[1] - t[0], u=u)
    assert isinstance(hosted.optimizer, ps.optimizers.BaseOptimizer)
    np.testing.assert_allclose(hosted.coefficients(), reference.coefficients(), rtol=0, atol=TOLERANCE)
    np.testing.assert_allclose(hosted.predict(x, u=u), reference.predict(x, u=u), rtol=0, atol=1e-7)
    assert hosted.equations() == reference.equations()
    assert hosted.complexity == reference.complexity


def test_stlsq_on_a_library_matrix_equals_pysindy_for_every_setting():
    k, j = np.arange(150)[:, None], np.arange(7)[None, :]
    theta = np.sin(0.37 * (k + 1) * (j + 1) + 0.11 * j) * (1 + 0.3 * j) + 0.2 * np.cos(0.05 * k * (j + 2))
    true = np.array([[1.5, 0, -0.8, 0, 0, 0.12, 0], [0, 2.0, 0, 0, -0.25, 0, 0.05]])
    y = theta @ true.T + 0.05 * np.sin(1.7 * k + np.arange(2)[None, :]) * np.cos(0.21 * k)
    for threshold, alpha, max_iter in [(0.1, 0.05, 20), (0.28, 0.5, 20), (0.35, 0.0, 20), (0.1, 5.0, 2)]:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            reference = ps.STLSQ(threshold=threshold, alpha=alpha, max_iter=max_iter).fit(theta, y)
        ours = ls.STLSQ(threshold=threshold, alpha=alpha, max_iter=max_iter).fit(theta, y)
        np.testing.assert_allclose(ours.coef_, reference.coef_, rtol=0, atol=TOLERANCE)
        # the same matrix through other memory layouts, read in place
        fortran = ls.STLSQ(threshold=threshold, alpha=alpha, max_iter=max_iter).fit(np.asfortranarray(theta), y)
        np.testing.assert_array_equal(fortran.coef_, ours.coef_)
    wide = np.hstack([theta, theta[:, ::-1]])[:, ::2]  # a strided view
    strided = ls.STLSQ().fit(wide, y).coef_
    np.testing.assert_allclose(strided, ls.STLSQ().fit(np.ascontiguousarray(wide), y).coef_, rtol=0, atol=0)


def test_lasso_equals_scikit_learn():
    from sklearn.linear_model import Lasso

    t, x, u = pendulum_forced(n=600)
    theta = np.hstack([x, u, np.sin(x)])
    y = np.gradient(x, t, axis=0)
    for penalty in [0.5, 5.0]:
        reference = Lasso(alpha=penalty / len(t), fit_intercept=False, tol=1e-14, max_iter=1_000_000).fit(theta, y)
        ours = ls.Lasso(penalty=penalty).fit(theta, y)
        np.testing.assert_allclose(ours.coef_, reference.coef_, rtol=0, atol=1e-6)


def test_uneven_time_stamps_use_the_true_times():
    t, x, u = pendulum_forced(n=3000, dt=0.002)
    keep = np.sort(np.r_[0, np.random.default_rng(3).choice(np.arange(1, 2999), 1500, replace=False), 2999])
    model = ls.SINDy(feature_library=ls.PolynomialLibrary(1) + ls.FourierLibrary(1))
    model.fit(x[keep], t=t[keep], u=u[keep])
    c = dict(zip(model.get_feature_names(), model.coefficients()[1]))
    assert c["sin(1 x0)"] == pytest.approx(-4.0, rel=2e-3)
    assert c["x1"] == pytest.approx(-0.3, rel=1e-2)
    assert c["u0"] == pytest.approx(1.0, rel=1e-2)


def test_simulate_follows_the_identified_system():
    t, x, u = lorenz_forced(n=1500)
    model = ls.SINDy().fit(x, t=t[1] - t[0], u=u)
    simulated = model.simulate(x[0], t[:500], u=u[:500])
    assert simulated.shape == (500, 3)
    assert np.max(np.abs(simulated - x[:500])) < 0.05 * np.max(np.abs(x[:500]))
    as_function = model.simulate(x[0], t[:500], u=lambda ti: [np.sin(2 * ti), np.cos(ti) ** 2])
    np.testing.assert_allclose(as_function, simulated, rtol=0, atol=1e-12)


def test_models_round_trip_through_files_and_the_cli(tmp_path, run_learn):
    t, x, u = lorenz_forced(n=1200)
    model = ls.SINDy(feature_library=ls.PolynomialLibrary(2)).fit(x, t=t, u=u, feature_names=["a", "b", "c", "p", "q"])
    path = tmp_path / "model.json"
    model.save(path)
    loaded = ls.SINDy.load(path)
    np.testing.assert_array_equal(loaded.coefficients(), model.coefficients())
    assert loaded.get_feature_names() == model.get_feature_names()
    assert loaded.equations() == model.equations()
    np.testing.assert_array_equal(loaded.predict(x, u=u), model.predict(x, u=u))
    with pytest.raises(ls.LearnSysidError, match="model.json"):
        model.save(path)  # never replaces a file unless asked
    model.save(path, overwrite=True)

    # the CLI fits the same recording from a CSV: Python loads its model, the coefficients agree
    csv = tmp_path / "run.csv"
    np.savetxt(csv, np.column_stack([t, x, u]), delimiter=",", header="t,a,b,c,p,q", comments="", fmt="%.17g")
    cli_model = tmp_path / "cli.json"
    run_learn("sindy", "--csv", csv, "--state", "a,b,c", "--control", "p,q", "--library", "poly:2",
              "--threshold", "0.1", "--derivative", "central", "--out", cli_model)
    from_cli = ls.SINDy.load(cli_model)
    np.testing.assert_allclose(from_cli.coefficients(), model.coefficients(), rtol=0, atol=1e-10)
    assert from_cli.get_feature_names() == model.get_feature_names()

    # and the CLI predicts with the model Python saved
    predictions = tmp_path / "predicted.csv"
    run_learn("sindy", "predict", "--model", path, "--csv", csv, "--out", predictions)
    header, *rows = predictions.read_text().splitlines()
    columns = header.split(",")
    values = np.array([[float(v) for v in row.split(",")] for row in rows])
    derivative_columns = [columns.index(name) for name in columns if name.endswith("'") or name.startswith("d")]
    assert derivative_columns, header
    np.testing.assert_allclose(values[:, derivative_columns[:3]], model.predict(x, u=u), rtol=1e-9, atol=1e-9)


def test_bad_input_raises_one_line_errors():
    t, x, u = pendulum_forced(n=200)
    bad = x.copy()
    bad[17, 1] = np.nan
    with pytest.raises(ls.LearnSysidError) as error:
        ls.SINDy().fit(bad, t=t, u=u)
    assert "17" in str(error.value) and "\n" not in str(error.value)
    with pytest.raises(ls.LearnSysidError, match="control rows"):
        ls.SINDy().fit(x, t=t, u=u[:-1])
    with pytest.raises(ls.LearnSysidError, match="threshold"):
        ls.SINDy(optimizer=ls.STLSQ(threshold=-1)).fit(x, t=t, u=u)
    with pytest.raises(ls.LearnSysidError, match="increasing"):
        ls.SINDy().fit(x, t=t[::-1], u=u)
    with pytest.raises(ls.LearnSysidError, match="absent.json"):
        ls.SINDy.load("absent.json")
    with pytest.raises(ls.LearnSysidError, match="not fitted"):
        ls.SINDy().coefficients()
    with pytest.raises(TypeError, match="u is required"):
        ls.SINDy().fit(x, t=t, u=u).predict(x)
    with pytest.raises(TypeError, match="feature_library"):
        ls.SINDy(feature_library=ps.PolynomialLibrary())
    assert issubclass(ls.LearnSysidError, ValueError)
