"""Plots and report writing leave the caller's matplotlib backend alone."""

from __future__ import annotations

import json
import os
import subprocess
import sys

from sarcover.benchmarks.rows import run_one

SCRIPT = """
import sys
import matplotlib

before = matplotlib.get_backend()
import sarcover

inst = sarcover.generate(targets=4, views=2, uavs=2, seed=0)
ax = sarcover.plot_plan(inst, sarcover.solve(inst, "greedy").plan)
after_plot = matplotlib.get_backend()
sarcover.write_report(sys.argv[1], sys.argv[2])
print(before, after_plot, matplotlib.get_backend(), type(ax.figure.canvas).__module__)
"""


def test_plot_plan_and_write_report_keep_the_callers_backend(tmp_path):
    """On the 'template' backend, plot_plan draws in it, write_report writes PNGs, and the backend stays 'template'."""
    source = {"type": "generate", "M": 4, "K": 2, "N": 2, "instance_seed": 0, "preset": "paper", "overrides": {},
              "exact": False}
    job = {"key": "sar-m4-k2-n2-s0|greedy|0", "instance": "sar-m4-k2-n2-s0", "method": "greedy", "seed": 0,
           "run": 0, "time_limit": 5, "grace": 5, "source": source, "suite": "backend"}
    results = tmp_path / "results"
    results.mkdir()
    (results / "results.jsonl").write_text(json.dumps(run_one(job)) + "\n")
    env = {**os.environ, "MPLBACKEND": "template"}
    done = subprocess.run([sys.executable, "-c", SCRIPT, str(results), str(tmp_path / "report")], env=env,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    before, after_plot, after_report, canvas = done.stdout.split()
    assert before == after_plot == after_report == "template"
    assert canvas.endswith("backend_template")  # plot_plan's own figure is the caller's backend's
    assert (tmp_path / "report" / "example_routes.png").stat().st_size > 0
