"""What the Python references of the LeARN meta-iteration share (scripts/bench/learn.py with JAX,
scripts/bench/learn_torch.py with PyTorch): the command-line sizes, the timing loop and the one
JSON line that scripts/bench/learn.sh reads. Standard library only, so either environment runs it.
"""

import json
import os
import time

DEFAULTS = [4, 64, 64, 1, 20]


def sizes(argv):
    """TASKS SUPPORT QUERY ROUNDS REPEATS from the first five arguments, defaults for the rest."""
    args = [int(a) for a in argv[:5]]
    return (args + DEFAULTS[len(args):])[:5]


def time_calls(call, repeats):
    """Seconds of each of `repeats` calls of `call()` (after the caller's warm-up), sorted."""
    times = []
    for _ in range(repeats):
        started = time.perf_counter()
        call()
        times.append(time.perf_counter() - started)
    return sorted(times)


def print_report(implementation, versions, sizes, parameters, times):
    """The JSON line: `versions` (library versions and settings) then the sizes, the parameter
    count, and the median and minimum seconds per meta-iteration."""
    tasks, support, query, rounds, _ = sizes
    print(
        json.dumps(
            {
                "implementation": implementation,
                **versions,
                "tasks": tasks,
                "support": support,
                "query": query,
                "inner_rounds": rounds,
                "parameters": int(parameters),
                "cpu_count": os.cpu_count(),
                "seconds_per_iteration": times[len(times) // 2],
                "seconds_per_iteration_min": times[0],
            }
        )
    )
