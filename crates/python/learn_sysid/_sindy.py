"""``SINDy``: PySINDy's model class, fitted, evaluated and saved by the Rust ``sindy`` crate."""

from __future__ import annotations

import json
import os

import numpy as np

from . import _native
from ._libraries import (
    PolynomialLibrary,
    _checked,
    _differentiation,
    _differentiation_from_spec,
    _library_from_spec,
)
from ._optimizers import _matrix, _optimizer, _optimizer_from_spec


def _as_list(value, multiple: bool, what: str):
    if value is None:
        return None
    if multiple:
        if not isinstance(value, (list, tuple)):
            raise _native.LearnSysidError(f"{what}: x is a list of trajectories, so {what} must be one too")
        return list(value)
    return [value]


def _times(t, x: np.ndarray, index: int) -> np.ndarray:
    if t is None:
        return np.arange(x.shape[0], dtype=np.float64)
    if np.ndim(t) == 0:
        step = float(t)
        if not step > 0:
            raise _native.LearnSysidError(f"trajectory {index}: the time step {t} must be positive")
        return np.arange(x.shape[0], dtype=np.float64) * step
    times = np.ascontiguousarray(t, dtype=np.float64)
    if times.ndim != 1 or times.shape[0] != x.shape[0]:
        raise _native.LearnSysidError(
            f"trajectory {index}: {times.size} times for {x.shape[0]} samples"
        )
    return times


def _trajectories(x, t, x_dot, u):
    """Each trajectory's (t, x, u, x_dot) arrays, and whether x was a list."""
    multiple = isinstance(x, (list, tuple))
    xs = [_matrix(xi, "x") for xi in (x if multiple else [x])]
    if not xs:
        raise _native.LearnSysidError("x: no trajectory")
    if multiple and (t is None or np.ndim(t) == 0 or isinstance(t, np.ndarray)):
        ts = [t] * len(xs)  # one step or one array of times for every trajectory, as PySINDy
    else:
        ts = _as_list(t, multiple, "t") or [None] * len(xs)
    x_dots = _as_list(x_dot, multiple, "x_dot") or [None] * len(xs)
    us = _as_list(u, multiple, "u") or [None] * len(xs)
    for what, values in (("t", ts), ("x_dot", x_dots), ("u", us)):
        if len(values) != len(xs):
            raise _native.LearnSysidError(f"{what}: {len(values)} trajectories, x has {len(xs)}")
    arrays = []
    for index, (ti, xi, ui, di) in enumerate(zip(ts, xs, us, x_dots)):
        if ti is None and di is None:
            raise _native.LearnSysidError(f"trajectory {index}: give t (a time step or the sample times) or x_dot")
        arrays.append(
            (
                _times(ti, xi, index),
                xi,
                None if ui is None else _matrix(ui, "u"),
                None if di is None else _matrix(di, "x_dot"),
            )
        )
    return arrays, multiple


def _r2_score(actual: np.ndarray, predicted: np.ndarray) -> float:
    """scikit-learn's ``r2_score`` (uniform average over columns; a constant column scores 1
    when predicted exactly, else 0)."""
    scores = []
    for a, p in zip(actual.T, predicted.T):
        residual = float(np.sum((a - p) ** 2))
        total = float(np.sum((a - a.mean()) ** 2))
        if total == 0.0:
            scores.append(1.0 if residual == 0.0 else 0.0)
        else:
            scores.append(1.0 - residual / total)
    return float(np.mean(scores))


class SINDy:
    """Sparse identification of nonlinear dynamics with control, PySINDy's ``SINDy`` API.

    ``feature_library``: ``PolynomialLibrary`` (default, degree 2), ``FourierLibrary`` or their
    sum; ``optimizer``: ``STLSQ`` (default, threshold 0.1) or ``Lasso``;
    ``differentiation_method``: ``FiniteDifference`` (default, central) or ``SavitzkyGolay``.
    """

    def __init__(self, optimizer=None, feature_library=None, differentiation_method=None):
        self.optimizer = _optimizer(optimizer)
        self.feature_library = _checked(feature_library if feature_library is not None else PolynomialLibrary())
        self.differentiation_method = _differentiation(differentiation_method)
        self._model = None

    # --- fitting ---------------------------------------------------------------------------

    def fit(self, x, t=None, x_dot=None, u=None, feature_names=None):
        """Fits ẋ = Ξ Θ(x, u) on one trajectory or a list of them (samples stacked); ``t`` is a
        time step or the sample times (the samples need not be evenly spaced), ``x_dot`` known
        derivatives, ``u`` controls. The interpreter is released while the fit runs."""
        arrays, _ = _trajectories(x, t, x_dot, u)
        n_states = arrays[0][1].shape[1]
        n_controls = 0 if arrays[0][2] is None else arrays[0][2].shape[1]
        names = list(feature_names) if feature_names is not None else (
            [f"x{i}" for i in range(n_states)] + [f"u{i}" for i in range(n_controls)]
        )
        if len(names) != n_states + n_controls:
            raise _native.LearnSysidError(
                f"feature_names: {len(names)} names for {n_states} states and {n_controls} controls"
            )
        self._model = _native.fit_sindy(
            arrays,
            names[:n_states],
            names[n_states:],
            self.feature_library._spec(),
            self.optimizer._spec(),
            self.differentiation_method._spec(),
        )
        self._set_shape(names, n_controls)
        return self

    def _set_shape(self, names, n_controls):
        self.feature_names = names
        self.n_control_features_ = n_controls
        self.n_features_in_ = len(names)
        self.n_output_features_ = len(self._model.feature_names())
        # PySINDy's names are made here; the crate's features must be as many, in its order.
        assert len(self.get_feature_names()) == self.n_output_features_, "library names out of step"
        self.optimizer.coef_ = self._model.coefficients()

    def _fitted(self):
        if self._model is None:
            raise _native.LearnSysidError("this SINDy model is not fitted yet: call fit() or SINDy.load()")
        return self._model

    # --- using the model -------------------------------------------------------------------

    def predict(self, x, u=None):
        """ẋ predicted for states ``x`` (and controls ``u`` when fitted with them)."""
        model = self._fitted()
        multiple = isinstance(x, (list, tuple))
        xs = [_matrix(xi, "x") for xi in (x if multiple else [x])]
        us = _as_list(u, multiple, "u")
        if self.n_control_features_ > 0 and us is None:
            raise TypeError("Model was fit using control variables, so u is required")
        if us is None:
            us = [np.zeros((xi.shape[0], 0)) for xi in xs]
        result = [model.predict(xi, _matrix(ui, "u")) for xi, ui in zip(xs, us)]
        return result if multiple else result[0]

    def score(self, x, t=None, x_dot=None, u=None, metric=None, **metric_kws):
        """``metric`` (default R², as scikit-learn's ``r2_score``) of the predicted ẋ against
        ``x_dot`` or the derivatives estimated from ``x`` at ``t``."""
        arrays, _ = _trajectories(x, t, x_dot, u)
        predicted, actual = [], []
        for times, xi, ui, di in arrays:
            predicted.append(self.predict(xi, ui))
            if di is None:
                di = _native.differentiate(xi, times, self.differentiation_method._spec())
            actual.append(di)
        actual, predicted = np.vstack(actual), np.vstack(predicted)
        keep = ~(np.isnan(actual).any(axis=1) | np.isnan(predicted).any(axis=1))
        metric = metric or _r2_score
        return metric(actual[keep], predicted[keep], **metric_kws)

    def differentiate(self, x, t):
        """ẋ estimated from ``x`` at ``t`` with the model's differentiation method."""
        x = _matrix(x, "x")
        return _native.differentiate(x, _times(t, x, 0), self.differentiation_method._spec())

    def simulate(self, x0, t, u=None):
        """The states from ``x0`` at every time of ``t`` (RK4, one step per interval; the controls
        ``u``, one row per time, interpolated linearly). PySINDy integrates with SciPy's LSODA."""
        model = self._fitted()
        x0 = np.ascontiguousarray(x0, dtype=np.float64).ravel()
        if np.ndim(t) != 1:
            raise _native.LearnSysidError("simulate: t must be the array of times to report")
        times = np.ascontiguousarray(t, dtype=np.float64)
        if u is None:
            if self.n_control_features_ > 0:
                raise TypeError("Model was fit using control variables, so u is required")
            controls = np.zeros((times.shape[0], 0))
        elif callable(u):
            controls = _matrix(np.array([np.atleast_1d(u(ti)) for ti in times]), "u")
        else:
            controls = _matrix(u, "u")
        return model.simulate(x0, times, controls)

    # --- reading the model -----------------------------------------------------------------

    def coefficients(self) -> np.ndarray:
        """Ξ: one row per state, one column per feature (PySINDy's ``coefficients()``)."""
        return self._fitted().coefficients()

    def get_feature_names(self) -> list[str]:
        """The library's features as PySINDy names them (``1``, ``x0``, ``x0 x1``, ``sin(1 x0)``)."""
        self._fitted()
        return self.feature_library.get_feature_names(self.feature_names)

    def equations(self, precision: int = 3) -> list[str]:
        """Each state's right-hand side, printed as PySINDy prints it."""
        names = self.get_feature_names()
        equations = []
        for row in self.coefficients():
            terms = [f"{c: .{precision}f} {name}" for c, name in zip(row, names) if np.round(c, precision) != 0]
            equations.append(" + ".join(terms) if terms else f"{0: .{precision}f}")
        return equations

    def print(self, lhs=None, precision: int = 3, **kwargs) -> None:
        """Prints ``(x0)' = …`` for each state, as PySINDy does."""
        states = self.feature_names[: self.n_features_in_ - self.n_control_features_]
        for name, equation in zip(lhs or states, self.equations(precision)):
            print(f"({name})' = {equation}", **kwargs)

    @property
    def complexity(self) -> int:
        return int(np.count_nonzero(self.coefficients()))

    # --- files -----------------------------------------------------------------------------

    def save(self, path, overwrite: bool = False) -> None:
        """Writes the model file (``sindy-model/1``, as ``learn sindy --out`` writes it)."""
        self._fitted().save(os.fspath(path), overwrite)

    def to_json(self) -> str:
        return self._fitted().to_json()

    @classmethod
    def load(cls, path) -> "SINDy":
        """A model file written by ``learn sindy --out`` or ``save``."""
        return cls._from_native(_native.NativeModel.load(os.fspath(path)))

    @classmethod
    def from_json(cls, text: str) -> "SINDy":
        return cls._from_native(_native.NativeModel.from_json(text, "the model text"))

    @classmethod
    def _from_native(cls, model) -> "SINDy":
        file = json.loads(model.to_json())
        sindy = cls(
            optimizer=_optimizer_from_spec(file["optimizer"]),
            feature_library=_library_from_spec(file["library"]),
            differentiation_method=_differentiation_from_spec(file["derivative"]),
        )
        sindy._model = model
        sindy._set_shape(model.state_names() + model.control_names(), len(model.control_names()))
        return sindy

    def __repr__(self) -> str:
        return (
            f"SINDy(optimizer={self.optimizer!r}, feature_library={self.feature_library!r}, "
            f"differentiation_method={self.differentiation_method!r})"
        )
