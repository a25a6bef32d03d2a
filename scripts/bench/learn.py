"""JAX reference of one LeARN meta-iteration (exact second-order MAML), for `make bench`.

Same model as crates/learn: two exact-erf GELU networks [(in x 12), (12 x 16), (16 x 24), (24 x 48),
(48 x out)] in float64, Theta out = P*(I+U), E out = I*P*(I+U), y = Theta . E^T; loss = MSE;
n inner SGD rounds of step alpha on the support batch, meta-loss on the query batch, the exact
meta-gradient (jax.grad through the inner updates), the mean over a batch of tasks (vmap), and an
SGD outer step, all in one jit-compiled function. Synthetic data of the `full` formulation's shape
(I = 6, U = 4). Prints one JSON line with the median and the minimum seconds per meta-iteration.

usage: learn.py [TASKS] [SUPPORT] [QUERY] [ROUNDS] [REPEATS]
"""

import sys

import jax
import meta_iteration_report as report

jax.config.update("jax_enable_x64", True)
import jax.numpy as jnp  # noqa: E402

HIDDEN = [12, 16, 24, 48]
INPUTS, STATES, BASIS_PER_INPUT = 10, 6, 2


def init_mlp(key, sizes):
    layers = []
    for fan_in, fan_out in zip(sizes[:-1], sizes[1:]):
        key, k_w, k_b = jax.random.split(key, 3)
        bound = 1.0 / fan_in**0.5
        layers.append(
            (
                jax.random.uniform(k_w, (fan_in, fan_out), jnp.float64, -bound, bound),
                jax.random.uniform(k_b, (fan_out,), jnp.float64, -bound, bound),
            )
        )
    return layers


def mlp(layers, x):
    for w, b in layers[:-1]:
        x = jax.nn.gelu(x @ w + b, approximate=False)
    w, b = layers[-1]
    return x @ w + b


def predict(params, x):
    library, selection = params
    basis = BASIS_PER_INPUT * INPUTS
    theta = mlp(library, x)  # batch x K
    coefficients = mlp(selection, x).reshape(x.shape[0], STATES, basis)
    return jnp.einsum("bk,bik->bi", theta, coefficients)


def loss(params, x, y):
    return jnp.mean((predict(params, x) - y) ** 2)


def make_step(alpha, rounds, beta):
    def task_meta_loss(params, support_x, support_y, query_x, query_y):
        adapted = params
        for _ in range(rounds):
            grads = jax.grad(loss)(adapted, support_x, support_y)
            adapted = jax.tree_util.tree_map(lambda p, g: p - alpha * g, adapted, grads)
        return loss(adapted, query_x, query_y)

    meta_grad = jax.grad(task_meta_loss)

    @jax.jit
    def step(params, support_x, support_y, query_x, query_y):
        grads = jax.vmap(meta_grad, in_axes=(None, 0, 0, 0, 0))(
            params, support_x, support_y, query_x, query_y
        )
        mean = jax.tree_util.tree_map(lambda g: jnp.mean(g, axis=0), grads)
        return jax.tree_util.tree_map(lambda p, g: p - beta * g, params, mean)

    return step


def main():
    arguments = report.sizes(sys.argv[1:])
    tasks, support, query, rounds, repeats = arguments
    key = jax.random.PRNGKey(0)
    k1, k2, k3 = jax.random.split(key, 3)
    basis = BASIS_PER_INPUT * INPUTS
    params = (
        init_mlp(k1, [INPUTS, *HIDDEN, basis]),
        init_mlp(k2, [INPUTS, *HIDDEN, STATES * basis]),
    )
    keys = jax.random.split(k3, 4)
    support_x = jax.random.uniform(keys[0], (tasks, support, INPUTS), jnp.float64, -2, 2)
    support_y = jax.random.uniform(keys[1], (tasks, support, STATES), jnp.float64, -1, 1)
    query_x = jax.random.uniform(keys[2], (tasks, query, INPUTS), jnp.float64, -2, 2)
    query_y = jax.random.uniform(keys[3], (tasks, query, STATES), jnp.float64, -1, 1)
    step = make_step(0.05, rounds, 1e-3)
    params = jax.block_until_ready(step(params, support_x, support_y, query_x, query_y))

    def iteration():
        nonlocal params
        params = jax.block_until_ready(step(params, support_x, support_y, query_x, query_y))

    times = report.time_calls(iteration, repeats)
    parameters = sum(w.size + b.size for net in params for w, b in net)
    report.print_report("jax", {"jax": jax.__version__}, arguments, parameters, times)


if __name__ == "__main__":
    main()
