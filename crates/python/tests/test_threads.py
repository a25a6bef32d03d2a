"""The interpreter lock is released while a fit runs: another Python thread keeps running."""

import threading

import numpy as np

import learn_sysid as ls


def test_a_long_fit_lets_other_threads_run():
    t = np.arange(200_000) * 1e-3
    x = np.column_stack([np.sin(f * t + p) for f, p in zip(np.linspace(0.3, 2.9, 8), range(8))])
    done = []
    worker = threading.Thread(target=lambda: done.append(ls.SINDy(feature_library=ls.PolynomialLibrary(3)).fit(x, t=t)))
    ticks = 0
    worker.start()
    while worker.is_alive():
        ticks += 1
    worker.join()
    assert done and done[0].coefficients().shape == (8, 165)
    # With the lock held through the fit this loop would be stopped for its whole length.
    assert ticks > 100_000, ticks
