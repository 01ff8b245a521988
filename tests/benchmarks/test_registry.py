"""The method layer: parameters declared, checked and resolved; variants; one pre-check per run."""

import dataclasses
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import sarcover
from sarcover.benchmarks.cli import EXIT_BAD_INPUT, EXIT_OK, main
from sarcover.benchmarks.params import ParamError, fields, literal, parse_literal, split_variant, variant_name
from sarcover.benchmarks.registry import METHODS, get_method, run_method
from sarcover.formulations.instance import TOPInstance
from sarcover.formulations.result import Status, Termination

ROOT = Path(__file__).resolve().parents[2]
SMALL = sarcover.generate(targets=10, views=2, uavs=3, seed=3)


def one_line(capsys) -> str:
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    return err


@pytest.mark.parametrize("name", [n for n, spec in METHODS.items() if spec.params is not None])
def test_every_declared_parameter_has_a_type_a_default_and_a_meaning(name):
    """Each registered method's parameters resolve to JSON values and each has a one-line meaning."""
    spec = METHODS[name]
    resolved = spec.resolve()
    assert json.loads(json.dumps(resolved)) == resolved
    for field, _, default, help in fields(spec.params):
        assert help and "\n" not in help, field
        assert resolved[field] == default


def test_unknown_parameter_is_one_line_naming_the_valid_ones(capsys):
    """solve --param with a misspelt name: exit 2, one line naming the method's valid parameters."""
    assert main(["solve", "p2.2.b", "--method", "pyvrp", "--param", "iteratons=10"]) == EXIT_BAD_INPUT
    err = one_line(capsys)
    assert "'iteratons'" in err and "'pyvrp'" in err
    assert all(f"{f} (" in err for f in ("iterations", "no_improvement", "history_length", "neighbours"))


@pytest.mark.parametrize("argv, needle", [
    (["--method", "pyvrp", "--param", "iterations=ten"], "'iterations' must be int, got \"ten\""),
    (["--method", "pyvrp", "--param", "iterations=0.5"], "'iterations' must be int, got 0.5"),
    (["--method", "pyvrp", "--param", "iterations=0"], "'iterations' must be >= 1, got 0"),
    (["--method", "cpsat", "--param", "model=tree"], "'model' must be one of \"multi\", \"vehicle\""),
    (["--method", "bp", "--param", "group_branching=1"], "'group_branching' must be bool, got 1"),
    (["--method", "bp", "--param", "enum_share=1.5"], "'enum_share' must be in [0, 1], got 1.5"),
    (["--method", "greedy", "--param", "iterations=3"], "'greedy' takes no parameters"),
    (["--method", "pyvrp", "--param", "iterations"], "--param takes KEY=VALUE"),
    (["--method", "pyvrp[iterations=x]"], "'iterations' must be int"),
])
def test_bad_value_is_one_line_and_nothing_runs(capsys, argv, needle):
    """A value of the wrong type or out of range: one line naming it, exit 2."""
    assert main(["solve", "p2.2.b", *argv]) == EXIT_BAD_INPUT
    assert needle in one_line(capsys)


def test_solve_json_carries_the_resolved_parameters_and_they_change_the_run(capsys):
    """solve --json prints every parameter, given or default, and PyVRP ran the given iterations."""
    assert main(["solve", "p2.2.b", "--method", "pyvrp", "--param", "iterations=7", "--json"]) == EXIT_OK
    record = json.loads(capsys.readouterr().out)
    assert record["params"] == {**METHODS["pyvrp"].resolve(), "iterations": 7}
    assert record["info"]["params"] == record["params"]
    assert record["info"]["iterations"] == 7  # a TOP file has no groups: one PyVRP pass


def test_api_solve_takes_params_and_a_parameter_changes_the_plan():
    """sarcover.solve(params=...): ADPC's ξ changes the clusters; the default run records ξ = 0.25."""
    base = sarcover.solve(SMALL, "adpc-pso")
    wide = sarcover.solve(SMALL, "adpc-pso", params={"xi": 3.0})
    assert base.info["params"]["xi"] == 0.25 and wide.info["params"]["xi"] == 3.0
    assert base.info["cluster_sizes"] != wide.info["cluster_sizes"]
    with pytest.raises(ParamError, match="unknown parameter 'ksi'"):
        sarcover.solve(SMALL, "adpc-pso", params={"ksi": 1.0})


def test_bp_parameters_reach_branch_and_price_with_the_rest_decided_on_the_users_limit():
    """bp's enum_share=0 turns route enumeration off; cut rounds left None follow the 60 s limit."""
    default = sarcover.solve(SMALL, "bp", time_limit=60)
    off = sarcover.solve(SMALL, "bp", time_limit=60, params={"enum_share": 0.0})
    assert default.info["params"]["enum_share"] is None and default.info["options"]["enum_share"] == 0.6
    assert off.info["params"]["enum_share"] == 0.0 and off.info["options"]["enum_share"] == 0.0
    assert off.info["options"]["cut_rounds"] == 6  # decided on the user's 60 s, not on what greedy left
    assert off.objective == default.objective


@pytest.mark.parametrize("values", [
    {"iterations": 300}, {"xi": 0.5, "refill": False}, {"metaheuristic": "tabu_search"},
    {"model": "true"}, {"dc": None}, {"label": "a b,c"},
])
def test_variant_names_read_back_to_their_values(values):
    """variant_name and split_variant are inverse, strings that read as other literals are quoted."""
    name = variant_name("m", values)
    assert split_variant(name) == ("m", values)
    assert "\"" not in variant_name("m", {"metaheuristic": "tabu_search"})


def test_a_variant_is_a_method_of_its_own_with_its_parameters_fixed():
    """get_method('adpc-pso[iterations=3]') names the variant; its run uses and records them."""
    spec = get_method("adpc-pso[iterations=3]")
    assert spec.name == "adpc-pso[iterations=3]" and spec.base == "adpc-pso" and spec.fixed == {"iterations": 3}
    run = run_method(spec.name, sarcover.to_top(SMALL))
    assert run.method == "adpc-pso[iterations=3]" and run.info["params"]["iterations"] == 3
    assert literal(3.0) == "3.0" and parse_literal("3.0") == 3.0


def test_methods_name_prints_the_parameter_table(capsys):
    """`sarcover methods adpc-ga` prints each parameter with its type, default and meaning."""
    assert main(["methods", "adpc-ga"]) == EXIT_OK
    out = capsys.readouterr().out
    for name, _, default, help in fields(METHODS["adpc-ga"].params):
        line = next(line for line in out.splitlines() if line.split()[:1] == [name])
        assert literal(default) in line and help in line
    assert main(["methods", "greedy"]) == EXIT_OK and "parameters: none" in capsys.readouterr().out
    assert main(["methods", "nope"]) == EXIT_BAD_INPUT and "unknown method 'nope'" in one_line(capsys)


def far_group() -> TOPInstance:
    """One group whose only node no vehicle can reach and return from."""
    return TOPInstance(coords=np.array([[1000.0, 0.0]]), prizes=np.ones(1), start=np.zeros(2), end=np.zeros(2),
                       budget=100.0, n_vehicles=1, groups=((0,),))


@pytest.mark.parametrize("front_door", ["milp", "cpsat", "bp"])
def test_solver_front_doors_prove_a_group_out_of_reach_infeasible_without_the_precheck(front_door):
    """Called directly (no run_method, so no pre-check), each solver still answers infeasible."""
    from sarcover.formulations.bp import solve_bp
    from sarcover.formulations.cpsat import solve_cpsat
    from sarcover.formulations.milp import solve_milp

    solve = {"milp": solve_milp, "cpsat": solve_cpsat, "bp": solve_bp}[front_door]
    res = solve(far_group(), time_limit=10)
    assert res.termination is Termination.INFEASIBLE and res.plan is None


def test_run_method_prechecks_once_and_the_solver_is_not_called(monkeypatch):
    """run_method's pre-check answers for a group out of reach; the method itself never runs."""
    calls = []
    monkeypatch.setitem(METHODS, "bp", dataclasses.replace(METHODS["bp"], run=lambda *a, **k: calls.append(1)))
    res = run_method("bp", far_group())
    assert res.status == Status.INFEASIBLE and "cannot be covered" in res.reason and calls == []


@pytest.mark.parametrize("name, module, front_door", [
    ("milp", "sarcover.formulations.milp", "solve_milp"),
    ("cpsat", "sarcover.formulations.cpsat", "solve_cpsat"),
    ("bp", "sarcover.formulations.bp", "solve_bp"),
])
def test_a_model_too_large_for_memory_ends_with_greedys_plan_and_says_why(monkeypatch, name, module, front_door):
    """A MemoryError in an exact method's model or search (CP-SAT and the MILP have passed a
    worker's 4 GB at 240 points) is not an error row: the run returns the warm start, verified, with
    the reason."""
    import importlib

    def too_large(*args, **kwargs):
        raise MemoryError("Unable to allocate 34.1 MiB for an array")

    monkeypatch.setattr(importlib.import_module(module), front_door, too_large)
    inst = sarcover.generate(targets=6, views=2, uavs=2, seed=3)
    res = sarcover.solve(inst, name, time_limit=5)
    greedy = sarcover.solve(inst, "greedy")
    assert res.status == Status.FEASIBLE and res.termination is Termination.COMPLETED
    assert res.valid and res.objective == greedy.objective and res.bound is None
    assert "out of memory (Unable to allocate 34.1 MiB" in res.reason


def test_ad_hoc_methods_do_not_join_the_registry(tmp_path):
    """A suite's ``module:function`` method runs, but never shows up in the shared registry."""
    from sarcover.benchmarks.registry import METHODS, get_method, run_method
    from sarcover.formulations.generate import generate
    from sarcover.formulations.instance import to_top
    from sarcover.formulations.result import Status

    before = set(METHODS)
    inst = to_top(generate(2, 2, 1, 0))
    result = run_method("bench_methods:all_but_last", inst, time_limit=5.0)
    assert result.status == Status.FEASIBLE
    assert get_method("bench_methods:nap").name == "bench_methods:nap"
    assert set(METHODS) == before


WARM_CHECK = r"""
import json, sys
from numba.core.registry import CPUDispatcher
from sarcover.formulations.bp.compile import KERNEL_MODULES
import sarcover.heuristics.kernels as kernels
from sarcover.benchmarks.registry import METHODS, run_method, warm_up
from sarcover.formulations.generate import generate
from sarcover.formulations.instance import to_top

def compiled():
    out = {}
    for mod in (*KERNEL_MODULES, kernels):
        for name in dir(mod):
            f = getattr(mod, name)
            if isinstance(f, CPUDispatcher):
                out[f"{mod.__name__}.{name}"] = len(f.signatures)
    return out

before = compiled()
hooks = warm_up(list(METHODS))
warmed = compiled()
inst = to_top(generate(6, 3, 2, seed=1))
statuses = {m: str(run_method(m, inst, seed=0, time_limit=10).status)
            for m in ("bp", "adpc-pso", "dpc-pso", "kmeans-pso", "adpc-ga", "adpc-aco")}
print(json.dumps({"before": before, "hooks": hooks, "warmed": warmed, "after": compiled(),
                  "statuses": statuses}))
"""


def test_warm_up_leaves_nothing_for_the_jobs_to_compile():
    """In a fresh process, the registry's warm-up hooks compile (or load from numba's disk cache)
    every numba function that bp and the paper's pipelines then call: running them afterwards
    adds no compiled signature. That is what keeps JIT compilation out of a job's time."""
    out = subprocess.run([sys.executable, "-c", WARM_CHECK], cwd=ROOT, capture_output=True,
                         text=True, timeout=600, check=True)
    data = json.loads(out.stdout.strip().splitlines()[-1])
    assert sorted(data["hooks"]) == sorted({m.warm_up.__name__ for m in METHODS.values() if m.warm_up})
    assert sum(data["before"].values()) == 0  # a fresh process: nothing compiled yet
    assert data["warmed"]["sarcover.formulations.bp.labelling.label_search"] > 0
    assert data["warmed"]["sarcover.heuristics.kernels.pso_iterations"] > 0
    assert data["after"] == data["warmed"]
    assert set(data["statuses"].values()) <= {"optimal", "feasible"}


def test_warm_up_runs_each_hook_once_and_skips_a_broken_one(monkeypatch):
    """Methods that share a hook compile once per process; a hook that fails is skipped."""
    import dataclasses

    import sarcover.benchmarks.registry as registry

    calls = []

    def hook_a():
        calls.append("a")

    def hook_b():
        calls.append("b")

    def broken():
        raise ImportError("no such module")

    methods = dict(registry.METHODS)
    for name in ("adpc-pso", "dpc-pso", "adpc-ga"):
        methods[name] = dataclasses.replace(methods[name], warm_up=hook_a)
    methods["bp"] = dataclasses.replace(methods["bp"], warm_up=hook_b)
    monkeypatch.setattr(registry, "METHODS", methods)
    monkeypatch.setattr(registry, "_WARMED", set())
    assert registry.warm_up(["adpc-pso", "dpc-pso", "greedy", "bp", "tests.x:y"]) == ["hook_a", "hook_b"]
    assert registry.warm_up(["adpc-ga", "bp"]) == []  # already done in this process
    assert calls == ["a", "b"]

    methods["bp"] = dataclasses.replace(methods["bp"], warm_up=broken)
    monkeypatch.setattr(registry, "_WARMED", set())
    assert registry.warm_up(["bp"]) == []  # the job itself will report the problem
