"""PyTorch reference of one LeARN meta-iteration (exact second-order MAML), for `make bench`.

The same computation as scripts/bench/learn.py (the JAX reference) and crates/learn: two exact-erf
GELU networks [(in x 12), (12 x 16), (16 x 24), (24 x 48), (48 x out)] in float64, Theta out =
P*(I+U), E out = I*P*(I+U), y = Theta . E^T; loss = MSE; n inner SGD rounds of step alpha on the
support batch, meta-loss on the query batch, the exact meta-gradient (torch.func.grad through the
inner updates, so second order), the mean over a batch of tasks (torch.func.vmap), and an SGD outer
step. Synthetic data of the `full` formulation's shape (I = 6, U = 4). torch.set_num_threads follows
the cores the process may use.

MODE `eager` (the default) runs the step as torch.func MAML code is usually written; MODE `compile`
wraps the same step in torch.compile (TorchInductor, which generates C++ for the CPU; the first call
compiles, which takes minutes on a cold cache, and is timed apart as `compile_seconds`).
Prints one JSON line with the median and the minimum seconds per meta-iteration.

usage: learn_torch.py [TASKS] [SUPPORT] [QUERY] [ROUNDS] [REPEATS] [MODE]
"""

import os
import sys

import meta_iteration_report as report
import torch
from torch.func import grad, vmap

torch.set_default_dtype(torch.float64)

HIDDEN = [12, 16, 24, 48]
INPUTS, STATES, BASIS_PER_INPUT = 10, 6, 2


def init_mlp(generator, sizes):
    layers = []
    for fan_in, fan_out in zip(sizes[:-1], sizes[1:]):
        bound = 1.0 / fan_in**0.5
        weight = (torch.rand(fan_in, fan_out, generator=generator) * 2 - 1) * bound
        bias = (torch.rand(fan_out, generator=generator) * 2 - 1) * bound
        layers.append((weight, bias))
    return layers


def mlp(layers, x):
    for w, b in layers[:-1]:
        x = torch.nn.functional.gelu(x @ w + b, approximate="none")
    w, b = layers[-1]
    return x @ w + b


def predict(params, x):
    library, selection = params
    basis = BASIS_PER_INPUT * INPUTS
    theta = mlp(library, x)  # batch x K
    coefficients = mlp(selection, x).reshape(x.shape[0], STATES, basis)
    return torch.einsum("bk,bik->bi", theta, coefficients)


def loss(params, x, y):
    return torch.mean((predict(params, x) - y) ** 2)


def tree_map(function, *trees):
    return tuple(
        [tuple(function(*leaves) for leaves in zip(*layers)) for layers in zip(*networks)]
        for networks in zip(*trees)
    )


def make_step(alpha, rounds, beta):
    def task_meta_loss(params, support_x, support_y, query_x, query_y):
        adapted = params
        for _ in range(rounds):
            grads = grad(loss)(adapted, support_x, support_y)
            adapted = tree_map(lambda p, g: p - alpha * g, adapted, grads)
        return loss(adapted, query_x, query_y)

    meta_grad = vmap(grad(task_meta_loss), in_dims=(None, 0, 0, 0, 0))

    def step(params, support_x, support_y, query_x, query_y):
        grads = meta_grad(params, support_x, support_y, query_x, query_y)
        return tree_map(lambda p, g: p - beta * g.mean(dim=0), params, grads)

    return step


def main():
    arguments = report.sizes(sys.argv[1:6])
    tasks, support, query, rounds, repeats = arguments
    mode = sys.argv[6] if len(sys.argv) > 6 else "eager"
    if mode not in ("eager", "compile"):
        sys.exit(f"learn_torch.py: unknown MODE '{mode}' (eager or compile)")
    torch.set_num_threads(len(os.sched_getaffinity(0)))
    generator = torch.Generator().manual_seed(0)
    basis = BASIS_PER_INPUT * INPUTS
    params = (
        init_mlp(generator, [INPUTS, *HIDDEN, basis]),
        init_mlp(generator, [INPUTS, *HIDDEN, STATES * basis]),
    )
    support_x = torch.rand(tasks, support, INPUTS, generator=generator) * 4 - 2
    support_y = torch.rand(tasks, support, STATES, generator=generator) * 2 - 1
    query_x = torch.rand(tasks, query, INPUTS, generator=generator) * 4 - 2
    query_y = torch.rand(tasks, query, STATES, generator=generator) * 2 - 1
    step = make_step(0.05, rounds, 1e-3)
    if mode == "compile":
        step = torch.compile(step)

    def iteration():
        nonlocal params
        params = step(params, support_x, support_y, query_x, query_y)

    with torch.no_grad():
        first_call = report.time_calls(iteration, 1)[0]
        times = report.time_calls(iteration, repeats)
    parameters = sum(w.numel() + b.numel() for net in params for w, b in net)
    versions = {
        "torch": torch.__version__,
        "compile_seconds": first_call if mode == "compile" else None,
        "threads": torch.get_num_threads(),
    }
    report.print_report(f"torch-{mode}", versions, arguments, parameters, times)


if __name__ == "__main__":
    main()
