"""Corrections to the copied TOP table: the corrected value is the one every check uses, the
copied table stays as copied, and the shipped evidence says what the correction claims."""

from __future__ import annotations

import csv
import dataclasses

import pandas as pd
import pytest

import sarcover
from sarcover.benchmarks.catalog import TOP_DIR, corrections, published
from sarcover.benchmarks.plancheck import known_value


def _copied(name: str) -> tuple[float, str]:
    with (TOP_DIR / "optimal.csv").open() as fh:
        row = next(r for r in csv.DictReader(fh) if r["instance"] == name)
    return float(row["value"]), row["status"]


def test_every_correction_names_a_shipped_file_and_its_copied_value():
    fixes = corrections()
    assert fixes, "corrections.csv ships with at least one row"
    for fix in fixes:
        assert (TOP_DIR / f"{fix['instance']}.txt").is_file()
        assert _copied(fix["instance"]) == (float(fix["copied_value"]), fix["copied_status"])
        assert fix["status"] in ("optimal", "best_known") and fix["evidence"]
        assert published(TOP_DIR / f"{fix['instance']}.txt") == (float(fix["value"]), fix["status"])


def test_p4_4_n_is_checked_against_976_not_the_copied_977():
    """The copied table says 977 (best known); the file as written has optimum 976."""
    assert _copied("p4.4.n") == (977.0, "best_known")
    assert published(TOP_DIR / "p4.4.n.txt") == (976.0, "optimal")
    known = known_value(sarcover.read_instance("p4.4.n"))
    assert (known.kind, known.value) == ("optimum", 976.0)


def test_the_977_plan_of_p4_4_n_overruns_the_budget_by_what_the_evidence_says():
    """The shipped 977 plan needs one route of 45.0017 > tmax 45: invalid on the file, valid with
    tmax 45.01; the shipped 976 plan is valid on the file."""
    inst = sarcover.read_instance("p4.4.n")
    plan977 = sarcover.read_plan(TOP_DIR / "evidence" / "p4.4.n-977.json", inst)
    rep = sarcover.verify(inst, plan977)
    assert not rep.valid and rep.prize == 977
    assert max(rep.energy) == pytest.approx(45.00167, abs=1e-5)
    assert sum(e > inst.budget for e in rep.energy) == 1
    assert sarcover.verify(dataclasses.replace(inst, budget=45.01), plan977).valid
    rep976 = sarcover.verify(inst, sarcover.read_plan(TOP_DIR / "evidence" / "p4.4.n-976.json", inst))
    assert rep976.valid and rep976.prize == 976


def test_the_top_section_checks_old_rows_against_the_corrected_value(tmp_path):
    """A row stored with the copied value (best known 977, proof of 976 below it) is a conflict
    without the correction and a proof equal to the optimum with it; the section lists it."""
    from sarcover.reports.top_sets import file_table, top_sets_section

    row = {"instance": "p4.4.n", "method": "bp", "status": "optimal", "objective": 976.0, "bound": 976.0,
           "reference": None, "best_known": 977.0, "runtime_s": 373.0, "time_limit": 600, "valid": True,
           "kind": "top", "suite": "top-4-7", "exact": True, "seed": 0, "run": 0}
    df = pd.DataFrame([row])
    fix = {"instance": "p4.4.n", "value": "976", "status": "optimal", "copied_value": "977",
           "copied_status": "best_known", "evidence": "the why."}
    assert "below" in file_table(df, fixes=[]).loc["p4.4.n", "conflict"]
    files = file_table(df, fixes=[fix])
    assert files.loc["p4.4.n", "conflict"] == "" and files.loc["p4.4.n", "proven_equal"]
    text = "\n".join(top_sets_section(df, tmp_path, fixes=[fix]))
    assert "Conflicts with the published values: none." in text
    assert "- p4.4.n: 976 (optimal) in place of the copied 977 (best_known). the why." in text
