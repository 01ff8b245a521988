"""Speed of the paper's cluster-then-route heuristics (pytest-benchmark; not in the default run).

Run on one core, CPU time (the machine is shared, so wall time is noisy)::

    .venv/bin/pytest benchmarks/speed/bench_heuristics.py --benchmark-only -p no:cacheprovider \\
        --benchmark-timer time.process_time --benchmark-columns median,mean,min,rounds

Each run is a whole method call at the paper's size M=20, K=3, N=5 (``generate(20, 3, 5, seed)``),
cycling over 10 instances and seeds. Targets: ``adpc-pso`` ≤ 20 ms a run, ``adpc-aco``
≤ 60 ms, so that the paper's experiment (2 figures × 5 settings × 5 methods × 1000 runs) fits in
10 minutes on 2 cores. The clustering step alone is timed too (the paper's Table I lists it).
"""

from __future__ import annotations

import itertools
import os
import warnings

import numpy as np
import pytest

from sarcover.formulations.generate import generate
from sarcover.formulations.instance import to_top
from sarcover.formulations.result import Status
from sarcover.heuristics.pipeline import make_clusterer

os.environ.setdefault("OMP_NUM_THREADS", "1")  # scikit-learn KMeans: one core like the rest

INSTANCES = [to_top(generate(20, 3, 5, seed)) for seed in range(10)]
METHODS = ["adpc-pso", "dpc-pso", "kmeans-pso", "adpc-ga", "adpc-aco", "greedy"]


@pytest.mark.parametrize("name", METHODS)
def test_bench_method(benchmark, name):
    """One full run (cluster, route, repair) of a registered method at M=20, K=3, N=5."""
    from sarcover.benchmarks.registry import get_method

    fn = get_method(name).load()
    cases = itertools.cycle(enumerate(INSTANCES))

    def run():
        seed, inst = next(cases)
        return fn(inst, seed=seed)

    warnings.simplefilter("ignore")
    result = benchmark.pedantic(run, rounds=30, iterations=1, warmup_rounds=2)
    assert result.status == Status.FEASIBLE


@pytest.mark.parametrize("kind", ["adpc", "dpc", "kmeans"])
def test_bench_clustering(benchmark, kind):
    """Clustering the 60 viewpoints of one M=20, K=3 instance into N=5 groups."""
    inst = INSTANCES[0]
    warnings.simplefilter("ignore")
    model = benchmark(lambda: make_clusterer(kind, 5, inst, 0).fit(inst.coords))
    assert len(np.unique(model.labels_)) == 5
