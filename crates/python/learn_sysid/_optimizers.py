"""STLSQ and LASSO on a library matrix, computed in Rust; usable inside ``pysindy.SINDy``.

When PySINDy is installed the two classes subclass ``pysindy.optimizers.BaseOptimizer`` (so
``isinstance`` checks, ``complexity`` and scikit-learn's parameter handling work); ``fit`` is
ours: the library matrix is read in place (no copy for ``float64``), without PySINDy's initial
least-squares solve, and the interpreter is released while Rust runs.
"""

from __future__ import annotations

import json

import numpy as np

from . import _native

try:  # PySINDy's base class when it is there; a plain object otherwise.
    from pysindy.optimizers import BaseOptimizer as _Base

    _HAVE_PYSINDY = True
except ImportError:  # pragma: no cover - exercised without pysindy
    _Base = object
    _HAVE_PYSINDY = False


def _matrix(values, what: str) -> np.ndarray:
    array = np.asarray(values, dtype=np.float64)
    if array.ndim == 1:
        array = array.reshape(-1, 1)
    if array.ndim != 2:
        raise _native.LearnSysidError(f"{what}: expected a 2-D array, got {array.ndim} dimensions")
    return array


class _Optimizer(_Base):
    """What PySINDy's ``SINDy`` needs of an optimizer: ``fit``, ``predict``, ``coef_``."""

    def _base_init(self, max_iter: int) -> None:
        if _HAVE_PYSINDY:
            _Base.__init__(self, max_iter=max_iter, unbias=False)
        else:
            self.max_iter = max_iter

    def fit(self, x_, y, sample_weight=None, **_):
        if sample_weight is not None:
            raise _native.LearnSysidError(f"{type(self).__name__}: sample_weight is not supported")
        theta, targets = _matrix(x_, "library matrix"), _matrix(y, "targets")
        self.coef_ = self._solve(theta, targets)
        self.ind_ = np.abs(self.coef_) > 1e-14
        self.history_ = [self.coef_]
        self.intercept_ = 0.0
        self.n_features_in_ = theta.shape[1]
        return self

    def _reduce(self, x, y, **_):  # PySINDy's hook, for callers of BaseOptimizer.fit
        self.coef_ = self._solve(_matrix(x, "library matrix"), _matrix(y, "targets"))

    def predict(self, x):
        return _matrix(x, "library matrix") @ self.coef_.T

    @property
    def complexity(self) -> int:
        return int(np.count_nonzero(self.coef_))


class STLSQ(_Optimizer):
    """Sequentially thresholded least squares, PySINDy's ``STLSQ`` to rounding.

    Ridge steps ``‖Θξ − y‖² + α‖ξ‖²``, coefficients below ``threshold`` dropped, at most
    ``max_iter`` iterations, then an unregularised least-squares refit of the kept terms.
    """

    def __init__(self, threshold: float = 0.1, alpha: float = 0.05, max_iter: int = 20):
        self.threshold = threshold
        self.alpha = alpha
        self._base_init(max_iter)

    def _solve(self, theta, targets):
        coefficients, iterations = _native.stlsq(
            theta, targets, float(self.threshold), float(self.alpha), int(self.max_iter)
        )
        self.iterations_ = iterations
        return coefficients

    def _spec(self) -> str:
        return json.dumps(
            {"kind": "stlsq", "threshold": self.threshold, "alpha": self.alpha, "max_iter": self.max_iter}
        )

    def __repr__(self) -> str:
        return f"STLSQ(threshold={self.threshold}, alpha={self.alpha}, max_iter={self.max_iter})"


class Lasso(_Optimizer):
    """``min ½‖Θξ − y‖² + λ‖ξ‖₁`` for each target, solved by clarabel.

    scikit-learn's ``Lasso(alpha=a)`` minimises ``1/(2n)‖y − Θξ‖² + a‖ξ‖₁``: it is
    ``Lasso(penalty=a·n)`` here.
    """

    def __init__(self, penalty: float = 1.0):
        self.penalty = penalty
        self._base_init(1)

    def _solve(self, theta, targets):
        return _native.lasso(theta, targets, float(self.penalty))

    def _spec(self) -> str:
        return json.dumps({"kind": "lasso", "lambda": self.penalty})

    def __repr__(self) -> str:
        return f"Lasso(penalty={self.penalty})"


class BaggedRegression(_Optimizer):
    """The ``sindy`` crate's regression with a bagged ensemble, on a library matrix.

    The columns are standardised; each target's penalty is chosen among ``candidates`` by
    blocked ``folds``-fold cross-validation inside the rows given (``gap`` samples dropped beside
    each validation block); the fit on all rows is ``coef_``; ``members`` refits on moving-block
    bootstraps of ``block`` samples (drawn from ``seed``) give ``coef_members_`` and
    ``coef_interval_`` (their 2.5 % and 97.5 % quantiles, the coefficients' 95 % interval), and
    ``predict_band`` the members' mean ± 2√(s² + σ²) (s² the members' variance, σ² the
    cross-validation error). ``penalty``: ``"stlsq"`` (``candidates`` are thresholds as
    fractions of each target's standard deviation, ridge ``alpha``), ``"ridge"`` (λ per sample)
    or ``"lasso"`` (fractions of the smallest λ that zeroes every coefficient).
    """

    def __init__(self, penalty="stlsq", candidates=(0.02, 0.05, 0.1, 0.2), alpha=0.05, members=20, block=125,
                 folds=5, gap=0, seed=0, intercept=False):
        self.penalty = penalty
        self.candidates = candidates
        self.alpha = alpha
        self.members = members
        self.block = block
        self.folds = folds
        self.gap = gap
        self.seed = seed
        self.intercept = intercept
        self._base_init(1)

    def _spec_dict(self) -> dict:
        values = [float(v) for v in self.candidates]
        penalty = {
            "stlsq": {"kind": "stlsq", "thresholds": values, "alpha": float(self.alpha)},
            "ridge": {"kind": "ridge", "lambdas": values},
            "lasso": {"kind": "lasso", "fractions": values},
        }.get(self.penalty)
        if penalty is None:
            raise _native.LearnSysidError(f"BaggedRegression: penalty '{self.penalty}' is not stlsq, ridge or lasso")
        return {
            "penalty": penalty,
            "intercept": bool(self.intercept),
            "folds": {"folds": int(self.folds), "gap": int(self.gap)},
            "bagging": {"members": int(self.members), "block": int(self.block)},
        }

    def _solve(self, theta, targets):
        self._fit = _native.fit_regression(theta, targets, json.dumps(self._spec_dict()), int(self.seed))
        coefficients, intercepts = self._fit.full()
        members = self._fit.members()
        self.coef_members_ = np.stack([m[0] for m in members])
        self.coef_interval_ = np.quantile(self.coef_members_, [0.025, 0.975], axis=0)
        self.chosen_ = self._fit.chosen()
        self._intercepts = np.asarray(intercepts)
        return coefficients

    def fit(self, x_, y, sample_weight=None, **kws):
        super().fit(x_, y, sample_weight=sample_weight, **kws)
        self.intercept_ = self._intercepts if self.intercept else 0.0
        return self

    def predict(self, x):
        return _matrix(x, "library matrix") @ self.coef_.T + self.intercept_

    def predict_band(self, x):
        """The members' mean prediction and its predictive band: (mean, lower, upper)."""
        return self._fit.ensemble(_matrix(x, "library matrix"))

    def __repr__(self) -> str:
        return (f"BaggedRegression(penalty={self.penalty!r}, candidates={tuple(self.candidates)}, "
                f"members={self.members}, block={self.block}, seed={self.seed})")


def _optimizer(optimizer) -> _Optimizer:
    if optimizer is None:
        return STLSQ()
    if not isinstance(optimizer, (STLSQ, Lasso)):
        raise TypeError(
            f"optimizer: {type(optimizer).__name__} is not one of learn_sysid's STLSQ or Lasso "
            "(BaggedRegression and PySINDy's own optimizers run in pysindy.SINDy)"
        )
    return optimizer


def _optimizer_from_spec(spec: dict) -> _Optimizer:
    if spec.get("kind") == "stlsq":
        return STLSQ(spec["threshold"], spec["alpha"], spec["max_iter"])
    if spec.get("kind") == "lasso":
        return Lasso(spec["lambda"])
    raise ValueError(f"a saved model's optimizer {spec!r} is not one learn_sysid knows")
