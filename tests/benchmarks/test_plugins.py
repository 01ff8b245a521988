"""Plugins: an installed package registers methods through the entry-point group sarcover.methods."""

import json
import os
import subprocess
import sys
import textwrap

import pytest

from sarcover.formulations.records import read_rows

PLUGIN = '''
"""A tiny sarcover plugin: two methods, one with a parameters dataclass, one taking **params."""
from dataclasses import dataclass, field

from sarcover.formulations.plan import Plan
from sarcover.formulations.result import Result, Termination


@dataclass(frozen=True)
class NearestParams:
    visits: int = field(default=1, metadata={"help": "nodes each vehicle visits at most"})


def nearest(instance, *, seed=0, time_limit=None, visits=1):
    """Each vehicle flies to the cheapest nodes it can still return from, up to `visits` each."""
    cost = instance.cost_matrix()
    taken, routes = set(), []
    for _ in range(instance.n_vehicles):
        route, here, used = [], 0, 0.0
        for _ in range(visits):
            best = None
            for v in range(instance.n_nodes):
                step, back = cost[here, v + 1], cost[v + 1, instance.n_nodes + 1]
                if v not in taken and used + step + back <= instance.budget and (best is None or step < best[0]):
                    best = (step, v)
            if best is None:
                break
            taken.add(best[1]); route.append(best[1]); used += best[0]; here = best[1] + 1
        routes.append(route)
    return Result("nearest", Termination.COMPLETED, plan=Plan.of(routes), info={"visits": visits})


nearest.params = NearestParams


def anything(instance, *, seed=0, time_limit=None, **params):
    """Returns no plan; records the parameters it was given."""
    return Result("anything", Termination.COMPLETED, reason="no plan by design", info={"given": params})
'''


@pytest.fixture
def plugin_path(tmp_path):
    """A folder holding the plugin module and its .dist-info (what pip would install), for PYTHONPATH."""
    site = tmp_path / "site"
    site.mkdir()
    (site / "sarcover_tiny_plugin.py").write_text(PLUGIN)
    info = site / "sarcover_tiny_plugin-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: sarcover-tiny-plugin\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text(textwrap.dedent("""
        [sarcover.methods]
        nearest = sarcover_tiny_plugin:nearest
        anything = sarcover_tiny_plugin:anything
        greedy = sarcover_tiny_plugin:anything
    """))
    return site


def sarcover_cli(plugin_path, *args, cwd=None):
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(plugin_path), os.environ.get("PYTHONPATH", "")])}
    return subprocess.run([sys.executable, "-m", "sarcover.benchmarks.cli", *args], capture_output=True, text=True,
                          env=env, cwd=cwd, timeout=300)


def test_methods_lists_a_plugins_methods_with_the_package_they_come_from(plugin_path):
    """`sarcover methods` shows the plugin's methods and their package; a built-in name stays built in."""
    out = sarcover_cli(plugin_path, "methods")
    assert out.returncode == 0, out.stderr
    lines = {line.split()[0]: line for line in out.stdout.splitlines()}
    assert "[plugin sarcover-tiny-plugin]" in lines["nearest"] and "cheapest nodes" in lines["nearest"]
    assert "[plugin" in lines["anything"] and "[plugin" not in lines["greedy"]
    card = sarcover_cli(plugin_path, "methods", "nearest").stdout
    assert "visits" in card and "nodes each vehicle visits at most" in card
    assert "any (passed through" in sarcover_cli(plugin_path, "methods", "anything").stdout


def test_a_plugin_method_runs_through_bench_with_its_parameters_and_a_grid(plugin_path, tmp_path):
    """`sarcover bench` on a suite naming the plugin's methods: verified rows, variants, parameters."""
    suite = tmp_path / "plug.toml"
    suite.write_text(textwrap.dedent("""
        methods = ["nearest", "anything"]
        time_limit = 5
        [method.nearest.grid]
        visits = [1, 3]
        [method.anything.params]
        colour = "blue"
        [[instances]]
        files = ["p2.2.b"]
    """))
    out = sarcover_cli(plugin_path, "bench", str(suite), "-o", str(tmp_path / "res"), "--quiet", "--workers", "1")
    assert out.returncode == 0, out.stderr
    rows = {r["method"]: r for r in read_rows(tmp_path / "res")[0]}
    assert set(rows) == {"nearest[visits=1]", "nearest[visits=3]", "anything"}
    for visits in (1, 3):
        row = rows[f"nearest[visits={visits}]"]
        assert row["valid"] and row["status"] == "feasible", row["reason"]
        assert row["info"]["visits"] == visits and max(len(r) for r in row["routes"]) <= visits
    assert rows["nearest[visits=3]"]["objective"] > rows["nearest[visits=1]"]["objective"]
    assert rows["anything"]["info"]["given"] == {"colour": "blue"} and rows["anything"]["status"] == "no_plan"


def test_solve_json_with_a_plugin_parameter_and_a_bad_one(plugin_path):
    """solve --param on a plugin's method: the parameter reaches it; an unknown one is one line, exit 2."""
    out = sarcover_cli(plugin_path, "solve", "p2.2.b", "--method", "nearest", "--param", "visits=2", "--json")
    assert out.returncode == 0, out.stderr
    record = json.loads(out.stdout)
    assert record["params"] == {"visits": 2} and record["info"]["visits"] == 2
    bad = sarcover_cli(plugin_path, "solve", "p2.2.b", "--method", "nearest", "--param", "speed=2")
    assert bad.returncode == 2 and bad.stderr.strip().count("\n") == 0
    assert "unknown parameter 'speed'; valid: visits (int, 1)" in bad.stderr
