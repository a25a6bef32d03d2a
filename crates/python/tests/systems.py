"""Deterministic test systems with controls, integrated by fixed-step RK4 (no random numbers)."""

import numpy as np


def rk4(rhs, x0, times, control):
    states = np.empty((times.size, len(x0)))
    states[0] = x0
    for k in range(times.size - 1):
        h, t = times[k + 1] - times[k], times[k]
        x = states[k]
        k1 = rhs(x, control(t))
        k2 = rhs(x + h / 2 * k1, control(t + h / 2))
        k3 = rhs(x + h / 2 * k2, control(t + h / 2))
        k4 = rhs(x + h * k3, control(t + h))
        states[k + 1] = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return states


def lorenz_forced(n=2000, dt=0.002, x0=(-8.0, 8.0, 27.0), phase=0.0):
    """Lorenz with two inputs: u0 = sin(2t + phase) into x0, u1 = cos(t)^2 into x2."""
    times = np.arange(n) * dt
    control = lambda t: np.array([np.sin(2 * t + phase), np.cos(t) ** 2])
    rhs = lambda x, u: np.array(
        [10 * (x[1] - x[0]) + 2.0 * u[0], x[0] * (28 - x[2]) - x[1], x[0] * x[1] - 8 / 3 * x[2] - 1.5 * u[1]]
    )
    states = rk4(rhs, np.array(x0), times, control)
    return times, states, np.array([control(t) for t in times])


def pendulum_forced(n=1500, dt=0.01, x0=(1.0, 0.0)):
    """A damped pendulum driven by u = 0.5 sin(1.3 t): θ' = ω, ω' = −4 sin θ − 0.3 ω + u."""
    times = np.arange(n) * dt
    control = lambda t: np.array([0.5 * np.sin(1.3 * t)])
    rhs = lambda x, u: np.array([x[1], -4.0 * np.sin(x[0]) - 0.3 * x[1] + u[0]])
    states = rk4(rhs, np.array(x0), times, control)
    return times, states, np.array([control(t) for t in times])
