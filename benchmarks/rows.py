"""One job, one row: build the job's instance, run its method, and fill the result row.

:func:`run_one` never raises: any failure is an ``error`` row whose ``info.traceback`` holds the
whole traceback. :func:`failed_row` is the row of a job whose process was killed or died (no
result came back). The row's fields are :data:`~sarcover.formulations.records.FIELDS`, in
order; ``params`` (the method's resolved parameters, ``job["params"]``) and ``versions.sarcover``
(:func:`~sarcover.benchmarks.provenance.code_version`) say which settings and code made it.
"""

from __future__ import annotations

import datetime as _dt
import json
import math
import os
import time
import traceback

from sarcover.benchmarks.provenance import environment
from sarcover.formulations.records import FIELDS, SCHEMA_VERSION, outcome

_LAST_INSTANCE: tuple[str, object] | None = None


def cached_instance(source: dict):
    """:func:`build_instance`, reusing the previous job's instance when the source is the same
    (a suite lists each instance's methods in a row, and a batch runs them in one process)."""
    global _LAST_INSTANCE
    key = json.dumps({k: v for k, v in source.items() if k not in ("exact",)}, sort_keys=True, default=str)
    if _LAST_INSTANCE is not None and _LAST_INSTANCE[0] == key:
        return _LAST_INSTANCE[1]
    instance = build_instance(source)
    _LAST_INSTANCE = (key, instance)
    return instance


def build_instance(source: dict):
    """The TOPInstance a job's ``source`` describes (generator parameters or a file)."""
    if source["type"] == "generate":
        from sarcover.formulations.generate import generate
        from sarcover.formulations.instance import to_top

        return to_top(generate(source["M"], source["K"], source["N"], source["instance_seed"],
                               source["preset"], **source["overrides"]))
    from sarcover.formulations.io import load_instance

    return load_instance(source["path"])


def now() -> str:
    """The current UTC time, ISO 8601 to the second."""
    return _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")


def job_params(job: dict) -> dict:
    """The method's resolved parameters a job carries (``{}`` for a method without any)."""
    return job.get("params") or {}


def base_row(job: dict) -> dict:
    """A row of the schema's fields (:data:`~sarcover.formulations.records.FIELDS`, in order): the
    job's identity and provenance, and the outcome of a job that has not run (an error)."""
    src = job["source"]
    source = {k: v for k, v in src.items() if k not in ("exact", "reference", "best_known")}
    row = dict.fromkeys(FIELDS)
    row.update({
        "schema": SCHEMA_VERSION, "key": job["key"], "suite": job.get("suite"),
        "instance": job["instance"], "method": job["method"], "params": job_params(job), "exact": src.get("exact"),
        "seed": job["seed"], "run": job["run"], "source": source,
        "kind": "sar" if src["type"] == "generate" else None,
        "M": src.get("M"), "K": src.get("K"), "N": src.get("N"), "instance_seed": src.get("instance_seed"),
        "reference": src.get("reference"), "best_known": src.get("best_known"),
        "termination": "error", "solution": "none", "status": "error", "valid": False, "reason": "", "info": {},
        "time_limit": job["time_limit"], "workers": job.get("workers"), **environment(), "pid": os.getpid(),
    })
    return row


def run_one(job: dict) -> dict:
    """Run one job and return its row. Never raises: any failure is an ``error`` row with a reason."""
    t0, c0 = time.perf_counter(), time.thread_time()
    row = base_row(job)
    try:
        from sarcover.benchmarks.registry import run_method

        instance = cached_instance(job["source"])
        row.update(kind=instance.kind, n_nodes=instance.n_nodes, n_groups=len(instance.groups),
                   n_vehicles=instance.n_vehicles, e_max=instance.budget)
        run = run_method(job["method"], instance, seed=job["seed"], time_limit=job["time_limit"],
                         params=job.get("params"))
        rec = outcome(run, instance)
        rec.pop("instance")
        rec.pop("method")  # the job's name (a variant keeps its name in the row)
        if "traceback" in run.info:  # outcome() leaves it out of `solve --json`; a row keeps it
            rec["info"]["traceback"] = run.info["traceback"]
        row.update(rec)
        row["threads"] = run.info.get("threads")
        if isinstance(run.info.get("params"), dict):  # what the method ran with, every default filled in
            row["params"] = run.info["params"]
    except BaseException as exc:
        if isinstance(exc, KeyboardInterrupt):
            raise
        row.update(termination="error", solution="none", status="error")
        row["reason"] = f"harness: {type(exc).__name__}: {exc}"
        row["info"] = {"traceback": traceback.format_exc().strip().splitlines()}
    row["wall_s"] = time.perf_counter() - t0
    row["cpu_s"] = time.thread_time() - c0
    if row["runtime_s"] is None:
        row["runtime_s"] = row["wall_s"]
    row["finished_at"] = now()
    return clean(row)


def failed_row(job: dict, status: str, reason: str, elapsed: float) -> dict:
    """The row of a job whose worker was killed or died (no result came back)."""
    row = base_row(job)
    row.update(termination=status, solution="none", status=status, reason=reason, runtime_s=elapsed,
               wall_s=elapsed, finished_at=now())
    row["pid"] = None
    return clean(row)


def clean(obj):
    """JSON-safe copy: numpy scalars to Python, tuples to lists, NaN/inf to None."""
    if isinstance(obj, dict):
        return {str(k): clean(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [clean(v) for v in obj]
    if isinstance(obj, bool) or obj is None or isinstance(obj, str):
        return obj
    if isinstance(obj, int):
        return int(obj)
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if hasattr(obj, "item"):  # numpy scalar
        return clean(obj.item())
    if hasattr(obj, "tolist"):
        return clean(obj.tolist())
    return str(obj)
