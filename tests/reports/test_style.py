"""Plots a reader can tell apart: one look (colour, marker) per method in every figure of both
reports, the paper's methods grouped apart from the peers and the exact methods, legends outside
the data, and no figure title above panel titles."""

import json

import matplotlib
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg

from sarcover.benchmarks.rows import run_one
from sarcover.benchmarks.registry import METHODS
from sarcover.reports import optimum, reference, report
from sarcover.reports.style import GROUPS, look, ordered


def test_every_registered_method_has_its_own_colour_and_marker_in_its_group():
    """Every registered method has its own colour, and its own marker and one line style within its group."""
    looks = {m: look(m) for m in METHODS}
    assert len({lk.color for lk in looks.values()}) == len(METHODS)  # 11 methods, 11 colours
    assert len({(lk.color, lk.marker) for lk in looks.values()}) == len(METHODS)
    for group, members in GROUPS.items():
        assert len({looks[m].marker for m in members}) == len(members)
        assert {looks[m].group for m in members} == {group} and len({looks[m].ls for m in members}) == 1
    assert len({looks[GROUPS[g][0]].ls for g in GROUPS}) == len(GROUPS)  # groups differ by line style
    assert ordered(["bp", "greedy", "x:y", "adpc-aco", "adpc-pso"]) == ["adpc-pso", "adpc-aco", "greedy", "bp", "x:y"]
    assert look("x:y") == look("x:y") and look("bp-300s").color == look("bp").color


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    """A results folder of every registered method on two instances (K = 2 and 3): real greedy
    rows copied under each method's name with a coverage of its own, so that figures are drawn
    without running eleven solvers."""
    folder = tmp_path_factory.mktemp("res")
    rows = []
    for k in (2, 3):
        source = {"type": "generate", "M": 4, "K": k, "N": 2, "instance_seed": 0, "preset": "paper",
                  "overrides": {}, "exact": False}
        job = {"key": "", "instance": f"sar-m4-k{k}-n2-s0", "method": "greedy", "seed": 0, "run": 0,
               "time_limit": 5, "grace": 5, "source": source, "suite": "style"}
        base = run_one(job)
        for i, m in enumerate(METHODS):
            exact = METHODS[m].exact
            row = {**base, "key": f"{job['instance']}|{m}|0", "method": m, "exact": exact,
                   "coverage": base["coverage"] * (1 - 0.01 * (i % 4)), "runtime_s": 0.01 * (i + 1)}
            if exact:  # proven at greedy's objective, with an anytime history
                row.update(status="optimal", termination="optimal", solution="optimal", bound=base["objective"],
                           info={"history": [[0.0, None, base["objective"] + 2], [0.01 * (i + 1), base["objective"],
                                                                                 base["objective"]]]})
            rows.append(row)
    (folder / "results.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    return folder


def _figures(monkeypatch, module):
    """Record every figure ``module`` saves (drawn, as saved) before it is written."""
    seen = []
    original = module.save_figure

    def record(fig, path, *args, **kwargs):
        FigureCanvasAgg(fig).draw()  # the reports' figures belong to no backend: draw them as saved
        seen.append((str(path), fig, _facts(fig)))
        return original(fig, path, *args, **kwargs)

    monkeypatch.setattr(module, "save_figure", record)
    return seen


def _facts(fig):
    """What a reader sees: per legend entry that names a method its colour and marker; whether
    each legend overlaps any axes' data area; the figure title and the panel titles."""
    from matplotlib.colors import to_hex

    renderer = fig.canvas.get_renderer()
    legends = [leg for ax in fig.axes if (leg := ax.get_legend()) is not None] + list(fig.legends)
    entries, overlaps = {}, []
    for leg in legends:
        box = leg.get_window_extent(renderer)
        overlaps += [box.overlaps(ax.get_window_extent(renderer)) for ax in fig.axes if ax.axison]
        for handle, text in zip(leg.legend_handles, leg.get_texts()):
            if text.get_text() in METHODS and hasattr(handle, "get_color"):
                entries[text.get_text()] = (to_hex(handle.get_color()), handle.get_marker())
    titles = [ax.get_title() for ax in fig.axes if ax.get_title()]
    suptitle = fig._suptitle.get_text() if fig._suptitle is not None else ""
    return {"entries": entries, "overlaps": overlaps, "titles": titles, "suptitle": suptitle}


def test_both_reports_draw_each_method_alike_with_legends_outside(results, tmp_path, monkeypatch):
    """Every figure of both reports draws each method in its look, with legends off the data."""
    import pandas as pd

    figures = _figures(monkeypatch, report)
    report.write_report(results, tmp_path / "report")
    ref_figures = _figures(monkeypatch, reference)
    df = pd.read_json(results / "results.jsonl", lines=True).assign(has_plan=True)
    df["cov0"] = df["coverage"]
    heuristics = df[~df["exact"].astype(bool)]
    reference._sweep(heuristics, "K", tmp_path, "coverage_vs_K", "coverage against K", None)
    opt_figures = _figures(monkeypatch, optimum)  # Fig. 3 with the optimum: every method, exact ones too
    optimum.optimum_section(df, tmp_path)

    names = {p.rsplit("/", 1)[-1] for p, _, _ in figures + ref_figures + opt_figures}
    assert {"coverage_vs_K_M4_N2.png", "example_routes.png", "gap_distribution.png", "time_to_optimality.png",
            "anytime.png", "coverage_vs_K.png", "paper_opt_vs_N.png"} <= names
    [(_, _, opt_facts)] = opt_figures
    assert set(opt_facts["entries"]) == set(METHODS)  # each method in the optimum figure's legend, in its look
    drawn = {}
    for path, fig, facts in figures + ref_figures + opt_figures:
        assert not any(facts["overlaps"]), f"{path}: a legend covers data"
        assert not (facts["suptitle"] and facts["titles"]), f"{path}: a title above panel titles"
        for m, (color, marker) in facts["entries"].items():
            assert (color, marker) == (look(m).color, look(m).marker), (path, m)
            drawn.setdefault(m, set()).add(path)
    assert set(drawn) == set(METHODS)  # every method appears in some legend with its look
    [cov] = [f for p, f, _ in figures if p.endswith("coverage_vs_K_M4_N2.png")]
    lines = {ln.get_label(): ln for ln in cov.axes[0].get_lines()}
    for m in METHODS:  # the data lines themselves carry the look, and equal values sit apart
        assert (matplotlib.colors.to_hex(lines[m].get_color()), lines[m].get_marker()) == (look(m).color,
                                                                                           look(m).marker)
    xs = {tuple(lines[m].get_xdata()) for m in METHODS}
    assert len(xs) == len(METHODS)


def test_report_header_names_the_results_folder_relative_to_the_report(results, tmp_path):
    """No machine's absolute path in the report: the source is named from the report's folder."""
    import os

    out = tmp_path / "report"
    report.write_report(results, out)
    text = (out / "report.md").read_text()
    assert str(results.resolve()) not in text
    assert f"`results.jsonl` of the results folder `{os.path.relpath(results.resolve(), out.resolve())}`" in text
