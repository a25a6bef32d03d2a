"""Feature libraries and differentiation methods: PySINDy's names, the Rust crate's specs."""

from __future__ import annotations

import json
from itertools import combinations_with_replacement


class _Library:
    """A feature library: its spec for the Rust fit and PySINDy's feature names."""

    def __add__(self, other: "_Library") -> "ConcatLibrary":
        return ConcatLibrary([self, other])

    def _parts(self) -> list["_Library"]:
        return [self]


class PolynomialLibrary(_Library):
    """All monomials of the inputs up to ``degree`` (PySINDy's ``PolynomialLibrary``)."""

    def __init__(self, degree: int = 2, include_bias: bool = True, include_interaction: bool = True):
        if not include_interaction:
            raise ValueError("PolynomialLibrary: include_interaction=False is not supported")
        if int(degree) != degree or degree < 0:
            raise ValueError(f"PolynomialLibrary: degree {degree} must be a whole number ≥ 0")
        self.degree = int(degree)
        self.include_bias = bool(include_bias)
        self.include_interaction = True

    def _spec(self) -> str:
        return f"poly:{self.degree}" + ("" if self.include_bias else ":noconstant")

    def get_feature_names(self, input_features: list[str]) -> list[str]:
        names = ["1"] if self.include_bias else []
        for degree in range(1, self.degree + 1):
            for term in combinations_with_replacement(range(len(input_features)), degree):
                powers = [(index, term.count(index)) for index in sorted(set(term))]
                names.append(
                    " ".join(
                        input_features[i] if power == 1 else f"{input_features[i]}^{power}"
                        for i, power in powers
                    )
                )
        return names

    def __repr__(self) -> str:
        return f"PolynomialLibrary(degree={self.degree}, include_bias={self.include_bias})"


class FourierLibrary(_Library):
    """``sin(k z)`` and ``cos(k z)`` of every input for k = 1..n_frequencies (PySINDy's)."""

    def __init__(self, n_frequencies: int = 1, include_sin: bool = True, include_cos: bool = True):
        if not (include_sin and include_cos):
            raise ValueError("FourierLibrary: only include_sin=True with include_cos=True is supported")
        if int(n_frequencies) != n_frequencies or n_frequencies < 1:
            raise ValueError(f"FourierLibrary: n_frequencies {n_frequencies} must be a whole number ≥ 1")
        self.n_frequencies = int(n_frequencies)
        self.include_sin = self.include_cos = True

    def _spec(self) -> str:
        return f"fourier:{self.n_frequencies}"

    def get_feature_names(self, input_features: list[str]) -> list[str]:
        names = []
        for k in range(1, self.n_frequencies + 1):
            for feature in input_features:
                names += [f"sin({k} {feature})", f"cos({k} {feature})"]
        return names

    def __repr__(self) -> str:
        return f"FourierLibrary(n_frequencies={self.n_frequencies})"


class ConcatLibrary(_Library):
    """The features of each library, one after the other (PySINDy's ``lib1 + lib2``)."""

    def __init__(self, libraries: list[_Library]):
        if not libraries:
            raise ValueError("ConcatLibrary needs at least one library")
        self.libraries = [part for library in libraries for part in _checked(library)._parts()]

    def _parts(self) -> list[_Library]:
        return list(self.libraries)

    def _spec(self) -> str:
        return "+".join(library._spec() for library in self.libraries)

    def get_feature_names(self, input_features: list[str]) -> list[str]:
        return [name for library in self.libraries for name in library.get_feature_names(input_features)]

    def __repr__(self) -> str:
        return " + ".join(repr(library) for library in self.libraries)


def _checked(library) -> _Library:
    if not isinstance(library, _Library):
        raise TypeError(
            f"feature_library: {type(library).__name__} is not one of learn_sysid's "
            "PolynomialLibrary, FourierLibrary or their sum"
        )
    return library


class _Differentiation:
    def _spec(self) -> str:
        return json.dumps(self._fields())


class FiniteDifference(_Differentiation):
    """PySINDy's ``FiniteDifference``: ``order=2`` central differences (second-order ends), ``order=1`` forward."""

    def __init__(self, order: int = 2):
        if order not in (1, 2):
            raise ValueError(f"FiniteDifference: order {order} must be 1 (forward) or 2 (central)")
        self.order = order

    def _fields(self) -> dict:
        return {"kind": "central" if self.order == 2 else "forward"}

    def __repr__(self) -> str:
        return f"FiniteDifference(order={self.order})"


class SavitzkyGolay(_Differentiation):
    """The derivative of a local polynomial fit of ``order`` over ``window`` samples (odd), evenly spaced."""

    def __init__(self, window: int = 9, order: int = 3):
        self.window = int(window)
        self.order = int(order)

    def _fields(self) -> dict:
        return {"kind": "savitzky_golay", "window": self.window, "order": self.order}

    def __repr__(self) -> str:
        return f"SavitzkyGolay(window={self.window}, order={self.order})"


def _differentiation(method) -> _Differentiation:
    if method is None:
        return FiniteDifference()
    if not isinstance(method, _Differentiation):
        raise TypeError(
            f"differentiation_method: {type(method).__name__} is not one of learn_sysid's "
            "FiniteDifference or SavitzkyGolay"
        )
    return method


def _library_from_spec(spec: dict) -> _Library:
    """The library a saved model records (its ``library`` field)."""
    kind = spec.get("kind")
    if kind == "polynomial":
        return PolynomialLibrary(spec["degree"], include_bias=spec["constant"])
    if kind == "fourier":
        return FourierLibrary(spec["frequencies"])
    if kind == "concatenation":
        return ConcatLibrary([_library_from_spec(part) for part in spec["parts"]])
    raise ValueError(f"a saved model's library {spec!r} is not one learn_sysid knows")


def _differentiation_from_spec(spec: dict) -> _Differentiation:
    kind = spec.get("kind")
    if kind == "central":
        return FiniteDifference(2)
    if kind == "forward":
        return FiniteDifference(1)
    if kind == "savitzky_golay":
        return SavitzkyGolay(spec["window"], spec["order"])
    raise ValueError(f"a saved model's derivative {spec!r} is not one learn_sysid knows")
