"""LeARN: a meta-learned library y = Θ(X; ψ)·ℰ(X; φ)ᵀ, meta-trained on tasks, adapted online on
a support segment of a new recording, and explained through ℰ (``docs/own-data.md``)."""

from __future__ import annotations

import json
import math
import os

import numpy as np

from . import _native
from ._libraries import _differentiation
from ._optimizers import _matrix


def _rows(rows, what: str) -> tuple[int, int]:
    start, end = (int(v) for v in rows)
    if not 0 <= start < end:
        raise _native.LearnSysidError(f"{what}: rows {start}:{end} are not a range start < end")
    return start, end


class LeARN:
    """A meta-trained LeARN model of named columns (``learn meta-train --tasks``' checkpoint)."""

    def __init__(self, native):
        self._native = native

    @classmethod
    def meta_train(cls, tasks, state, control=(), *, interval, differentiation_method=None, config=None, seed=None, names=None,
                   progress=None):
        """Meta-trains on ``tasks`` (arrays, one row per sample: the ``state`` columns, then the
        ``control`` columns, sampled every ``interval`` seconds), with the paper's settings or
        those a ``config`` file names (any subset of ``experiments/learn.json``); ``seed``
        replaces the configuration's. The interpreter is released while it trains;
        ``progress(done, total)`` is called after each meta-iteration (an exception it raises is
        raised when the training ends)."""
        arrays = [_matrix(task, "task") for task in tasks]
        names = list(names) if names is not None else [f"task {i}" for i in range(len(arrays))]
        if len(names) != len(arrays):
            raise _native.LearnSysidError(f"names: {len(names)} names for {len(arrays)} tasks")
        native = _native.meta_train_arrays(
            arrays,
            names,
            list(state),
            list(control),
            float(interval),
            _differentiation(differentiation_method)._spec(),
            config=None if config is None else os.fspath(config),
            seed=seed,
            progress=progress,
        )
        return cls(native)

    @classmethod
    def meta_train_files(cls, pattern, state, control=(), *, time="t", differentiation_method=None, config=None,
                         seed=None, task_column=None, progress=None):
        """``learn meta-train --tasks PATTERN``: every CSV or Parquet file ``pattern`` matches is a
        task (or, with ``task_column``, each run of one value of that column of the file
        ``pattern``), read with its ``time``, ``state`` and ``control`` columns; the model records
        the files and their SHA-256. The same file as the CLI writes (tested). ``progress`` as
        for :meth:`meta_train`."""
        native = _native.meta_train_files(
            os.fspath(pattern),
            time,
            list(state),
            list(control),
            _differentiation(differentiation_method)._spec(),
            config=None if config is None else os.fspath(config),
            seed=seed,
            task_column=task_column,
            progress=progress,
        )
        return cls(native)

    @classmethod
    def load(cls, path) -> "LeARN":
        """A checkpoint written by ``learn meta-train --tasks`` or ``save``."""
        return cls(_native.NativeLearnModel.load(os.fspath(path)))

    def save(self, path) -> None:
        self._native.save(os.fspath(path))

    @property
    def input_names(self) -> list[str]:
        return self._native.input_names()

    @property
    def output_names(self) -> list[str]:
        return self._native.output_names()

    @property
    def interval(self) -> float:
        return self._native.interval()

    @property
    def seed(self) -> int:
        return self._native.seed()

    @property
    def meta_loss_history(self) -> list[float]:
        return self._native.meta_loss_history()

    def predict(self, inputs, parameters=None) -> np.ndarray:
        """ẋ for inputs [x, u] (one row per sample), with the meta-trained θ or ``parameters``
        (e.g. ``adapt``'s)."""
        params = None if parameters is None else [float(v) for v in np.ravel(parameters)]
        return self._native.predict(_matrix(inputs, "inputs"), params)

    def evaluate(self, recording, support, query) -> dict:
        """Adapts online on the ``support`` rows (start, end) of ``recording`` (states then
        controls at the model's interval), then scores it there and, frozen, on the ``query``
        rows: the paper's adaptation and generalisation MSE, and the adapted θ."""
        adaptation, generalisation, before_support, before_query, theta = self._native.evaluate(
            _matrix(recording, "recording"), _rows(support, "support"), _rows(query, "query")
        )
        return {
            "adaptation_mse": adaptation,
            "generalisation_mse": generalisation,
            "meta_trained_support_mse": before_support,
            "meta_trained_query_mse": before_query,
            "adapted_parameters": np.asarray(theta),
        }

    def adapt(self, recording, support) -> np.ndarray:
        """θ adapted online on the ``support`` rows of ``recording``."""
        rows = _rows(support, "support")
        return self.evaluate(recording, rows, rows)["adapted_parameters"]

    def explain(self, recording, support=None, max_terms: int = 3, relative_threshold: float = 0.2) -> dict:
        """Each output's equation and each input's mean feature-selection coefficient over
        ``recording`` (adapted first on ``support`` rows when given), as ``learn explain``."""
        rows = None if support is None else _rows(support, "support")
        text = self._native.explain(_matrix(recording, "recording"), rows, max_terms, relative_threshold)
        return json.loads(text)


def read_checkpoint(path) -> dict:
    """A LeARN checkpoint's networks as NumPy arrays, for use without learn-sysid (e.g. to load
    them into PyTorch ``Linear`` layers, whose ``weight`` is the transpose of ``W`` here).

    Returns ``library`` and ``selection``: lists of ``(W, b)`` per layer, ``W`` of shape
    (fan_in, fan_out) so that a layer is ``h @ W + b``, GELU (exact, with erf) between layers
    and none after the last; ``mean``, ``std`` (and ``low``, ``high`` when the inputs are
    clamped) of the input standardisation; ``output_scale`` (the targets' scales, or ones);
    ``state_dim``. See :func:`numpy_predict` for the forward pass.
    """
    with open(path, encoding="utf-8") as file:
        checkpoint = json.load(file)
    architecture = checkpoint["architecture"]
    inputs, states = architecture["input_dim"], architecture["state_dim"]
    basis = architecture["basis_per_input"] * inputs
    hidden = list(architecture["hidden"])
    theta = np.asarray(checkpoint["parameters"], dtype=np.float64)
    offset = 0

    def network(output: int):
        nonlocal offset
        sizes = [inputs, *hidden, output]
        layers = []
        for fan_in, fan_out in zip(sizes[:-1], sizes[1:]):
            weights = theta[offset : offset + fan_in * fan_out].reshape(fan_in, fan_out)
            biases = theta[offset + fan_in * fan_out : offset + (fan_in + 1) * fan_out]
            offset += (fan_in + 1) * fan_out
            layers.append((weights, biases))
        return layers

    library, selection = network(basis), network(states * basis)
    standardiser = checkpoint["standardiser"]
    trained_on = checkpoint.get("trained_on") or {}
    result = {
        "library": library,
        "selection": selection,
        "state_dim": states,
        "mean": np.asarray(standardiser["mean"]),
        "std": np.asarray(standardiser["std"]),
        "output_scale": np.asarray(trained_on.get("target_scale", np.ones(states))),
    }
    if standardiser.get("clamp") and standardiser.get("range"):
        result["low"] = np.asarray(standardiser["range"]["low"])
        result["high"] = np.asarray(standardiser["range"]["high"])
    return result


def _gelu(z: np.ndarray) -> np.ndarray:
    return 0.5 * z * (1.0 + np.vectorize(math.erf)(z / math.sqrt(2.0)))


def numpy_predict(weights: dict, inputs) -> np.ndarray:
    """The model's ẋ for raw inputs [x, u] with :func:`read_checkpoint`'s arrays, in NumPy alone."""
    x = np.asarray(inputs, dtype=np.float64)
    if "low" in weights:
        x = np.clip(x, weights["low"], weights["high"])
    x = (x - weights["mean"]) / weights["std"]

    def run(layers):
        h = x
        for index, (w, b) in enumerate(layers):
            h = h @ w + b
            if index + 1 < len(layers):
                h = _gelu(h)
        return h

    library = run(weights["library"])  # rows × K
    selection = run(weights["selection"]).reshape(x.shape[0], weights["state_dim"], -1)
    return np.einsum("rik,rk->ri", selection, library) * weights["output_scale"]
