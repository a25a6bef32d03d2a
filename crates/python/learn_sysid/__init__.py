"""learn-sysid: learned-library system identification from Python.

- SINDy with PySINDy's API (``SINDy``, ``PolynomialLibrary``, ``FourierLibrary``,
  ``FiniteDifference``, ``SavitzkyGolay``; optimizers ``STLSQ`` and ``Lasso``, also usable as
  ``pysindy.SINDy(optimizer=learn_sysid.STLSQ(...))``; ``BaggedRegression`` with coefficient
  intervals), models saved as ``learn sindy`` saves them;
- LeARN (``LeARN.meta_train``, ``evaluate``, ``adapt``, ``predict``, ``explain``; checkpoints as
  ``learn meta-train --tasks`` writes them, ``read_checkpoint`` for NumPy);
- the quadrotor mismatch analysis (``analyze``).

Every computation runs in the workspace's Rust crates; errors are ``LearnSysidError``
(a ``ValueError``) with the crates' one-line messages. See docs/python.md.
"""

from ._learn import LeARN, numpy_predict, read_checkpoint
from ._libraries import ConcatLibrary, FiniteDifference, FourierLibrary, PolynomialLibrary, SavitzkyGolay
from ._mismatch import ANALYSIS_FILES, analyze, write_recording
from ._native import LearnSysidError, __version__
from ._optimizers import STLSQ, BaggedRegression, Lasso
from ._sindy import SINDy

__all__ = [
    "ANALYSIS_FILES",
    "BaggedRegression",
    "ConcatLibrary",
    "FiniteDifference",
    "FourierLibrary",
    "LeARN",
    "Lasso",
    "LearnSysidError",
    "PolynomialLibrary",
    "SINDy",
    "STLSQ",
    "SavitzkyGolay",
    "analyze",
    "numpy_predict",
    "read_checkpoint",
    "write_recording",
    "__version__",
]
