"""Golden values for the learn crate's MAML meta-gradient, computed with JAX (jax.grad through the
inner SGD updates, in float64) by the very functions of scripts/bench/learn.py, the reference that
`make bench` times. A small architecture (I + U = 3 inputs, I = 2 states, P = 2, hidden [5, 4]),
parameters and two tasks built deterministically (no random numbers), two inner rounds; the
second-order and first-order meta-gradients of each task, and the support and query losses.

Usage: .venv/bin/python scripts/golden/learn_golden.py > scripts/golden/learn_golden.json
"""

import json
import os
import sys

import jax

jax.config.update("jax_enable_x64", True)
import jax.numpy as jnp  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "bench"))
import learn as reference  # noqa: E402

INPUTS, STATES, BASIS_PER_INPUT, HIDDEN = 3, 2, 2, [5, 4]
STEP, ROUNDS, ROWS = 0.3, 2, 7


def layer_sizes(outputs):
    return [INPUTS, *HIDDEN, outputs]


def deterministic_parameters():
    """Each network's layers as (weights fan_in x fan_out, biases), from a smooth formula."""
    basis = BASIS_PER_INPUT * INPUTS
    networks, counter = [], 0
    for outputs in (basis, STATES * basis):
        layers = []
        for fan_in, fan_out in zip(layer_sizes(outputs)[:-1], layer_sizes(outputs)[1:]):
            scale = 1.2 / fan_in**0.5
            values = [scale * jnp.sin(0.7 * (counter + i) + 0.3) for i in range((fan_in + 1) * fan_out)]
            counter += (fan_in + 1) * fan_out
            weights = jnp.array(values[: fan_in * fan_out]).reshape(fan_in, fan_out)
            layers.append((weights, jnp.array(values[fan_in * fan_out:])))
        networks.append(layers)
    return tuple(networks)


def batch(task, phase):
    k = jnp.arange(ROWS, dtype=jnp.float64)[:, None]
    j = jnp.arange(INPUTS, dtype=jnp.float64)[None, :]
    inputs = 1.4 * jnp.sin(0.9 * k * (j + 1) + phase + 0.5 * task)
    i = jnp.arange(STATES, dtype=jnp.float64)[None, :]
    targets = jnp.cos(0.6 * k + i + task) * (0.5 + 0.3 * i)
    return inputs, targets


def flatten(params):
    return [float(v) for net in params for w, b in net for v in (*w.ravel(), *b.ravel())]


def flatten_rows(matrix):
    return [float(v) for v in matrix.ravel()]


def main():
    reference.INPUTS, reference.STATES, reference.BASIS_PER_INPUT = INPUTS, STATES, BASIS_PER_INPUT
    params = deterministic_parameters()

    def meta_loss(params, support, query, second_order):
        adapted = params
        for _ in range(ROUNDS):
            grads = jax.grad(reference.loss)(adapted, *support)
            if not second_order:
                grads = jax.lax.stop_gradient(grads)
            adapted = jax.tree_util.tree_map(lambda p, g: p - STEP * g, adapted, grads)
        return reference.loss(adapted, *query)

    tasks = []
    for task in range(2):
        support, query = batch(task, 0.0), batch(task, 2.0)
        tasks.append(
            {
                "support_inputs": flatten_rows(support[0]),
                "support_targets": flatten_rows(support[1]),
                "query_inputs": flatten_rows(query[0]),
                "query_targets": flatten_rows(query[1]),
                "support_loss": float(reference.loss(params, *support)),
                "query_loss": float(meta_loss(params, support, query, True)),
                "second_order": flatten(jax.grad(meta_loss)(params, support, query, True)),
                "first_order": flatten(jax.grad(meta_loss)(params, support, query, False)),
            }
        )
    print(
        json.dumps(
            {
                "generator": "scripts/golden/learn_golden.py",
                "jax": jax.__version__,
                "architecture": {
                    "input_dim": INPUTS,
                    "state_dim": STATES,
                    "basis_per_input": BASIS_PER_INPUT,
                    "hidden": HIDDEN,
                },
                "inner_step": STEP,
                "inner_rounds": ROUNDS,
                "parameters": flatten(params),
                "tasks": tasks,
            },
            indent=1,
        )
    )


if __name__ == "__main__":
    main()
