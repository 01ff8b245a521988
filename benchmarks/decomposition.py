"""Where the paper's gap comes from: clustering loss against routing loss, per instance and method.

For a cluster-then-route method on an instance with optimum OPT (proven, or else the best proven
bound) whose verified plan P has objective obj, with C the clustering its clustering stage made
(cluster i for UAV i, :func:`sarcover.heuristics.pipeline.cluster_stage`) and OPT|C the clustered
optimum (:func:`sarcover.formulations.clustered.solve_clustered`)::

    gap              = OPT − obj
    clustering loss  = OPT − OPT|C      >= 0 (every restricted plan is a plan)
    cross-cluster    = OPT|C − OPT|C'   (0 when P stays inside C, since then C' = C)
    routing loss     = OPT|C' − obj     >= 0 (P is a restricted plan of C')

and the three sum to the gap exactly. C' is the clustering the plan ends with: the repair's
refill (and, rarely, its cover and rebuild steps) may put a viewpoint of cluster j on route i;
C' moves every visited viewpoint into the cluster of the route that visits it and leaves the
others where C had them. The cross-cluster part is what those moves are worth to a perfect router:
negative when they won back clustering loss, positive when they cost it, and reported on its own
so that no loss goes negative unexplained. ``n_outside`` and ``outside_prize`` count the moved
viewpoints of the plan.

Flags: ``opt_proven`` False means OPT is a bound, so the clustering loss (and the gap) are upper
bounds; ``opt_c_proven`` / ``opt_cp_proven`` False means that clustered optimum stopped at its
time limit and its bound is used (clustering loss then a lower bound, routing loss an upper
bound). ``clustering_infeasible``: no plan inside C covers every target (only the repair's moves
made a plan); the clustering loss is then taken as OPT − OPT|C' and the cross-cluster part as 0.

Oracle rows (``oracle-pso``, ``oracle-ga``, ``oracle-aco``): the clustering an optimal plan induces
(:func:`sarcover.formulations.clustered.oracle_clusters`; with ``oracle="assign"`` the viewpoints
the plan leaves out join the cluster of the route that takes them most cheaply, so the clusters
partition the reachable viewpoints as a clusterer's do) fed to the paper's routers
(:func:`sarcover.heuristics.pipeline.route_clusters`): clustering loss 0 by construction (OPT|C =
OPT, computed and checked), so their gap is routing loss alone.

:func:`decompose` runs it at scale: cases with their OPT (from the stored rows of a results
directory or computed), one JSON line per (instance, method, seed) appended to a file as each
ends, rows already there skipped, progress on stderr. The rows are computed on the benchmark
harness's worker pool, each with a deadline and a memory cap: a row whose process is killed
becomes a ``time_limit`` or ``error`` row instead of a run that waits forever.
"""

from __future__ import annotations

import json
import math
import sys
import time
import traceback
from dataclasses import dataclass, field
from pathlib import Path

from sarcover.benchmarks.suite import DEFAULT_MEMORY_MB
from sarcover.formulations.clustered import oracle_clusters, solve_clustered, split_groups
from sarcover.formulations.instance import TOPInstance
from sarcover.formulations.plan import Plan
from sarcover.formulations.records import drop_torn_tail, read_decomposition
from sarcover.formulations.result import Status
from sarcover.formulations.verify import verify
from sarcover.heuristics.pipeline import cluster_stage, route_clusters

# method -> (clusterer, router); "oracle" is the clustering of the best known plan
PAPER_METHODS = {"adpc-pso": ("adpc", "pso"), "dpc-pso": ("dpc", "pso"), "kmeans-pso": ("kmeans", "pso"),
                 "adpc-ga": ("adpc", "ga"), "adpc-aco": ("adpc", "aco")}
ORACLE_METHODS = {"oracle-pso": ("oracle", "pso"), "oracle-ga": ("oracle", "ga"), "oracle-aco": ("oracle", "aco")}
METHODS = {**PAPER_METHODS, **ORACLE_METHODS}
TOL = 1e-6


@dataclass
class Case:
    """One instance with its optimum: ``opt`` is proven when ``opt_proven``, else the best proven
    bound; ``opt_plan`` is the best verified plan known (the oracle clustering's source)."""

    name: str
    instance: TOPInstance
    opt: float
    opt_proven: bool
    opt_plan: Plan | None = None
    opt_source: str = ""
    meta: dict = field(default_factory=dict)  # M, K, N, instance_seed, source (for the rows)


def plan_clusters(clusters, plan: Plan) -> list[list[int]]:
    """C': every node the plan visits moves to the cluster of the route visiting it; the others
    stay where ``clusters`` had them. The plan's route i lies inside C'_i."""
    where = {int(v): i for i, route in enumerate(plan.routes) for v in route}
    n = max(len(clusters), len(plan.routes))
    out: list[list[int]] = [[] for _ in range(n)]
    for i, c in enumerate(clusters):
        out[i] += [int(v) for v in c if int(v) not in where]
    for v, i in where.items():
        out[i].append(v)
    return [sorted(c) for c in out]


def _key(clusters) -> str:
    return json.dumps([sorted(int(v) for v in c) for c in clusters])


class ClusteredCache:
    """OPT|C per (instance, clustering), solved once: the three ADPC methods share their
    clustering, and a resumed run reuses what the stored rows hold."""

    def __init__(self, time_limit: float | None):
        self.time_limit = time_limit
        self.store: dict[tuple[str, str], dict] = {}

    def remember(self, instance_name: str, clusters, entry: dict) -> None:
        self.store[(instance_name, _key(clusters))] = entry

    def get(self, case: Case, clusters) -> dict:
        """``value`` (OPT|C, or its bound when not proven; None if no restricted plan exists),
        ``proven``, ``status``, ``bound``, ``plan_value``, ``seconds``."""
        k = (case.name, _key(clusters))
        if k not in self.store:
            res = solve_clustered(case.instance, clusters, time_limit=self.time_limit)
            plan_value = verify(case.instance, res.plan).prize if res.plan is not None else None
            if res.status == Status.OPTIMAL:
                value, proven = plan_value, True
            elif res.status == Status.INFEASIBLE:
                value, proven = None, True
            else:
                value, proven = res.bound, False
            self.store[k] = {"value": value, "proven": proven, "status": str(res.status), "bound": res.bound,
                             "plan_value": plan_value, "seconds": round(res.runtime_s, 3),
                             "bb_nodes": res.info.get("bb_nodes"), "split_groups": res.info.get("split_groups")}
        return self.store[k]


def _run_paper_method(method: str, instance: TOPInstance, seed: int, time_limit: float):
    """The registered method's verified run: (status, objective or None, plan, info)."""
    from sarcover.benchmarks.registry import run_method

    result = run_method(method, instance, seed=seed, time_limit=time_limit)
    return str(result.status), result.objective, result.plan, result.info


def _run_oracle(case: Case, router: str, seed: int, time_limit: float, unvisited: str):
    """The paper's router on the best known plan's clustering, verified here."""
    clusters = oracle_clusters(case.instance, case.opt_plan, unvisited=unvisited)
    res = route_clusters(case.instance, clusters, router, seed=seed, time_limit=time_limit,
                         name=f"oracle-{router}")
    objective = None
    if res.plan is not None:
        rep = verify(case.instance, res.plan)
        if not rep.valid:
            return "error", None, None, res.info
        objective = rep.prize
    return str(res.status), objective, res.plan, res.info


def _entry_fields(prefix: str, c: dict) -> dict:
    return {prefix: c["value"], f"{prefix}_proven": c["proven"], f"{prefix}_status": c["status"],
            f"{prefix}_bound": c["bound"], f"{prefix}_s": c["seconds"], f"{prefix}_bb_nodes": c["bb_nodes"]}


def _entry_from_row(row: dict, prefix: str) -> dict:
    return {"value": row[prefix], "proven": row[f"{prefix}_proven"], "status": row[f"{prefix}_status"],
            "bound": row[f"{prefix}_bound"], "plan_value": None, "seconds": row[f"{prefix}_s"],
            "bb_nodes": row.get(f"{prefix}_bb_nodes"), "split_groups": None}


def decompose_one(case: Case, method: str, *, seed: int = 0, cache: ClusteredCache | None = None,
                  time_limit: float = 60.0, unvisited: str = "assign") -> dict:
    """The decomposition row of one method on one case (see the module docstring)."""
    cache = cache or ClusteredCache(time_limit)
    clusterer, router = METHODS[method]
    t0 = time.perf_counter()
    row = {"instance": case.name, **case.meta, "method": method, "clusterer": clusterer, "router": router,
           "seed": seed, "opt": case.opt, "opt_proven": case.opt_proven, "opt_source": case.opt_source,
           "gap": None, "clustering_loss": None, "cross_cluster": None, "routing_loss": None}
    if clusterer == "oracle":
        if case.opt_plan is None:
            return {**row, "status": "no_plan", "reason": "no known plan to take the oracle clustering from"}
        clusters = oracle_clusters(case.instance, case.opt_plan, unvisited=unvisited)
        status, objective, plan, info = _run_oracle(case, router, seed, time_limit, unvisited)
        row["oracle_unvisited"] = unvisited
    else:
        status, objective, plan, info = _run_paper_method(method, case.instance, seed, time_limit)
        clusters = info.get("clusters")
        if clusters is None:  # a run that stopped before clustering: the stage alone
            clusters = [c.tolist() for c in cluster_stage(case.instance, clusterer, seed=seed)]
    row.update(status=status, objective=objective, routes=None if plan is None else [list(r) for r in plan.routes],
               clusters=clusters,
               cluster_sizes=[len(c) for c in clusters], split_groups=split_groups(case.instance, clusters))
    c = cache.get(case, clusters)
    row.update(_entry_fields("opt_c", c))
    if objective is None or plan is None:
        row["wall_s"] = round(time.perf_counter() - t0, 3)
        return row
    outside = [[int(v) for v in route if int(v) not in set(clusters[i] if i < len(clusters) else [])]
               for i, route in enumerate(plan.routes)]
    n_out = sum(len(o) for o in outside)
    row.update(n_outside=n_out, outside_prize=float(sum(case.instance.prizes[v] for o in outside for v in o)))
    if n_out:
        moved = plan_clusters(clusters, plan)
        cp = cache.get(case, moved)
        row["clusters_plan"] = moved
    else:
        cp = c  # the plan stays inside C: C' = C
    row.update(_entry_fields("opt_cp", cp))
    row["gap"] = case.opt - objective
    if cp["value"] is not None and c["status"] == "infeasible":  # only the repair's moves made plans
        row.update(clustering_infeasible=True, clustering_loss=case.opt - cp["value"], cross_cluster=0.0,
                   routing_loss=cp["value"] - objective)
    elif cp["value"] is not None and c["value"] is not None:
        row.update(clustering_infeasible=False, clustering_loss=case.opt - c["value"],
                   cross_cluster=c["value"] - cp["value"], routing_loss=cp["value"] - objective)
    row["wall_s"] = round(time.perf_counter() - t0, 3)
    return row


# ---------------------------------------------------------------- cases


def cases_from_results(results_dir: str | Path, *, exact=("bp", "milp", "cpsat")) -> list[Case]:
    """One case per SAR instance of a results directory written by the harness, with OPT from its
    stored exact rows: the best proven optimum (status ``optimal``, verified) if any, else the
    smallest stored bound (``opt_proven`` False); the best verified plan of any row is the oracle's.
    Instances without an optimum or a bound are skipped."""
    from sarcover.benchmarks.rows import build_instance
    from sarcover.reports.results import read_rows

    rows, _ = read_rows(results_dir)
    by_instance: dict[str, list[dict]] = {}
    for r in rows:
        if (r.get("source") or {}).get("type") == "generate":  # random SAR sets (M, K, N known)
            by_instance.setdefault(r["instance"], []).append(r)
    cases = []
    for name, group in sorted(by_instance.items()):
        ex = [r for r in group if r["method"] in exact]
        proven = [r for r in ex if r["status"] == "optimal" and r.get("valid") and r["objective"] is not None]
        bounds = [r["bound"] for r in ex if r.get("bound") is not None]
        if not proven and not bounds:
            continue
        first = group[0]
        instance = build_instance(first["source"])
        plans = [r for r in group if r.get("valid") and r.get("routes") is not None and r["objective"] is not None]
        best = max(plans, key=lambda r: r["objective"], default=None)
        plan = Plan.of(best["routes"]) if best is not None else None
        if plan is not None and not verify(instance, plan).valid:  # the rows are trusted for nothing
            plan = None
        if proven:
            top = max(proven, key=lambda r: r["objective"])
            opt, ok, src = float(top["objective"]), True, top["method"]
        else:
            opt, ok, src = float(min(bounds)), False, "bound"
        meta = {k: first.get(k) for k in ("M", "K", "N", "instance_seed")}
        cases.append(Case(name, instance, opt, ok, plan, src, meta))
    return cases


def cases_from_instances(instances, *, opt_method: str = "bp", time_limit: float = 60.0, seed: int = 0,
                         stream=sys.stderr) -> list[Case]:
    """Cases for (name, instance, meta) triples, OPT from a run of ``opt_method`` (registry,
    verified): its optimum when proven, else its bound."""
    from sarcover.benchmarks.registry import run_method

    cases = []
    for name, instance, meta in instances:
        t = time.perf_counter()
        result = run_method(opt_method, instance, seed=seed, time_limit=time_limit)
        proven = result.status == Status.OPTIMAL
        value = result.objective if proven else result.bound
        if stream is not None:
            print(f"decompose: OPT of {name} by {opt_method}: {value} ({result.status}, "
                  f"{time.perf_counter() - t:.1f} s)", file=stream, flush=True)
        if value is None:
            continue
        plan = result.plan if result.objective is not None else None
        cases.append(Case(name, instance, float(value), proven, plan, opt_method, dict(meta)))
    return cases


# ---------------------------------------------------------------- at scale


def row_key(row: dict) -> str:
    return f"{row['instance']}|{row['method']}|{row['seed']}"


def decompose(source, out_path: str | Path, *, methods=tuple(METHODS), seeds=(0,), time_limit: float = 60.0,
              clustered_time_limit: float | None = 120.0, unvisited: str = "assign", workers: int = 1,
              memory_mb: int = DEFAULT_MEMORY_MB, grace: float | None = None, stream=sys.stderr) -> list[dict]:
    """Decompose every (case, method, seed) into ``out_path`` (JSON lines), resumably.

    ``source``: a results directory (:func:`cases_from_results`) or a list of :class:`Case`.
    A row whose key (instance|method|seed) is already in the file is skipped; each new row is
    appended and flushed when it is done, so a killed run loses at most the rows in flight (one
    per worker). OPT|C solves already stored (same instance and clustering) are reused.
    ``time_limit`` is the methods' (a safety net for the pipelines), ``clustered_time_limit`` each
    OPT|C solve's. The rows are computed on the benchmark harness's worker pool
    (:func:`sarcover.benchmarks.pool.run_local`): ``workers`` processes of one thread each, an
    instance's rows in one process (its methods share their OPT|C solves), each row with a
    deadline (the method's limit and two OPT|C solves' plus ``grace``, default 5 s + 20 %) and
    each process with an address-space cap of ``memory_mb``; a row whose process was killed at
    its deadline or died (the OOM killer) is stored as ``time_limit`` or ``error`` with the
    reason, and the run goes on. Worker output goes to ``out_path`` with suffix
    ``.workers.log``. Rows are appended in the order they finish. Returns all rows of the file.
    """
    from sarcover.benchmarks.pool import run_local

    cases = cases_from_results(source) if isinstance(source, (str, Path)) else list(source)
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise ValueError(f"workers must be an integer >= 1, got {workers!r}")
    out_path = Path(out_path)
    out_path.parent.mkdir(parents=True, exist_ok=True)
    done = read_decomposition(out_path)
    have = {row_key(r) for r in done}
    stored: dict[str, dict] = {c.name: {} for c in cases}  # per instance: OPT|C entries by clustering
    for r in done:  # stored OPT|C values, by clustering (C and, where it was solved, C')
        entries = stored.setdefault(r["instance"], {})
        _remember_row(entries, r)
    limit = time_limit + 2 * (clustered_time_limit if clustered_time_limit is not None else math.inf)
    jobs = [{"key": f"{c.name}|{m}|{s}", "group": c.name, "case": c, "method": m, "seed": s,
             "time_limit": limit, "grace": grace if grace is not None else 5.0 + 0.2 * min(limit, 3600.0),
             "method_time_limit": time_limit, "clustered_time_limit": clustered_time_limit,
             "unvisited": unvisited, "stored": stored[c.name]}
            for c in cases for m in methods for s in seeds if f"{c.name}|{m}|{s}" not in have]
    total = len(jobs)
    drop_torn_tail(out_path)  # a row in flight when a run was killed
    t0 = time.perf_counter()
    count = 0
    with out_path.open("a") as fh:
        def store(row: dict) -> None:
            nonlocal count
            fh.write(json.dumps(row) + "\n")
            fh.flush()
            done.append(row)
            _remember_row(stored.setdefault(row["instance"], {}), row)  # for the instance's jobs not yet sent
            count += 1
            if stream is not None:
                print(f"decompose: {count}/{total} {row_key(row)}: gap {row.get('gap')} = clustering "
                      f"{row.get('clustering_loss')} + cross {row.get('cross_cluster')} + routing "
                      f"{row.get('routing_loss')} (OPT|C {row.get('opt_c')} in {row.get('opt_c_s')} s; "
                      f"{time.perf_counter() - t0:.0f} s so far)"
                      + (f" [{row['status']}: {row['reason']}]" if row.get("reason") else ""), file=stream, flush=True)

        run_local(jobs, store, workers=workers, memory_mb=memory_mb, run=run_job, failed=failed_job_row,
                  output=out_path.with_name(out_path.name + ".workers.log"))
    return done


def _remember_row(entries: dict, row: dict) -> None:
    """Add a row's solved OPT|C values (of C, and of C' where solved) to ``entries`` (by clustering)."""
    if row.get("clusters") is not None and row.get("opt_c_status") is not None:
        entries[_key(row["clusters"])] = _entry_from_row(row, "opt_c")
    if row.get("clusters_plan") is not None and row.get("opt_cp_status") is not None:
        entries[_key(row["clusters_plan"])] = _entry_from_row(row, "opt_cp")


_CACHES: dict[str, ClusteredCache] = {}  # a worker process's OPT|C solves, per instance


def run_job(job: dict) -> dict:
    """A pool worker's row of one decomposition job (never raises: a failure is an ``error`` row)."""
    case = job["case"]
    cache = _CACHES.get(case.name)
    if cache is None or cache.time_limit != job["clustered_time_limit"]:
        cache = _CACHES[case.name] = ClusteredCache(job["clustered_time_limit"])
    for clustering, entry in job["stored"].items():
        cache.store.setdefault((case.name, clustering), entry)
    t0 = time.perf_counter()
    try:
        return decompose_one(case, job["method"], seed=job["seed"], cache=cache, time_limit=job["method_time_limit"],
                             unvisited=job["unvisited"])
    except Exception as exc:  # noqa: BLE001 - one failing row must not stop the run
        row = failed_job_row(job, "error", f"{type(exc).__name__}: {exc}", time.perf_counter() - t0)
        row["traceback"] = traceback.format_exc().strip().splitlines()
        return row


def failed_job_row(job: dict, status: str, reason: str, elapsed: float) -> dict:
    """The row of a job that returned no decomposition (killed at its deadline, died, raised)."""
    case = job["case"]
    clusterer, router = METHODS[job["method"]]
    return {"instance": case.name, **case.meta, "method": job["method"], "clusterer": clusterer, "router": router,
            "seed": job["seed"], "opt": case.opt, "opt_proven": case.opt_proven, "opt_source": case.opt_source,
            "gap": None, "clustering_loss": None, "cross_cluster": None, "routing_loss": None,
            "status": status, "reason": reason, "wall_s": round(elapsed, 3)}
