"""A run's options follow the user's limit; longer runs get no less effort; explicit settings win."""

from __future__ import annotations

import dataclasses

import pytest

from sarcover.formulations.bp import BPOptions

from bp_cases import random_tiny

LIMITS = [1.0, 10.0, 30.0, 59.0, 60.0, 120.0, 299.0, 300.0, 599.0, 600.0, 3600.0]
DECIDED = ("cut_rounds", "cut_gap", "primal_calls", "enum_share", "enum_labels")  # left None


def _decided(opts: BPOptions) -> tuple:
    return tuple(getattr(opts, f) for f in DECIDED)


def _steps() -> list[float]:
    """The limits (whole seconds up to an hour) at which a default setting turns on or changes
    level, and the first at which enumeration's label cap (in proportion below it) is full."""
    def level(t):
        return _decided(BPOptions.for_time_limit(t))[:-1]

    full = BPOptions.for_time_limit(None).enum_labels
    steps = [t for t in range(2, 3601) if level(t) != level(t - 0.5)]
    return steps + [next(t for t in range(1, 3601) if BPOptions.for_time_limit(t).enum_labels == full)]


def test_longer_limits_never_get_less_effort():
    """Cut rounds, their gate, primal calls, enumeration's share and label cap never shrink as
    the limit grows, and no limit gets the most of each."""
    rows = [_decided(BPOptions.for_time_limit(t)) for t in LIMITS]
    for field in range(len(DECIDED)):
        column = [row[field] for row in rows]
        assert column == sorted(column), DECIDED[field]
    assert _decided(BPOptions.for_time_limit(None)) == _decided(BPOptions.for_time_limit(1e9))


def test_short_runs_skip_cuts_and_enumeration_long_runs_use_them():
    """Cuts and route enumeration slow a short run down: off at 10 s, on without a limit."""
    short, long = BPOptions.for_time_limit(10.0), BPOptions.for_time_limit(None)
    assert short.cut_rounds == 0 and short.enum_share == 0
    assert long.cut_rounds > 0 and long.enum_share > 0 and long.enum_labels > short.enum_labels


@pytest.mark.parametrize("limit", LIMITS + [None])
def test_explicit_settings_win_and_the_rest_follow_the_limit(limit):
    """Options that leave a setting None get it from the run's limit; an explicit one is kept;
    the options are frozen."""
    opts = BPOptions.for_time_limit(limit)
    assert all(v is not None for v in _decided(opts))
    assert BPOptions().with_limit_defaults(limit) == opts
    assert dataclasses.replace(opts, **dict.fromkeys(DECIDED)) == BPOptions()
    assert BPOptions(cut_rounds=2, strong=1).with_limit_defaults(limit).cut_rounds == 2
    with pytest.raises(dataclasses.FrozenInstanceError):
        opts.strong = 1


@pytest.mark.parametrize("limit", [None, 10.0, 300.0])
def test_the_tree_is_built_from_its_options(limit):
    """Whether a run enumerates routes, its label cap, its cut rounds and their gate are those
    of its options: the limit's defaults, or the ones given."""
    from sarcover.formulations.bp.tree import BranchAndPrice

    inst = random_tiny(0, groups=False)
    bp = BranchAndPrice(inst, time_limit=limit)
    opts = BPOptions.for_time_limit(limit)
    assert (bp.enumeration is None) == (opts.enum_share == 0)
    if bp.enumeration is not None:
        assert bp.enumeration.max_labels == opts.enum_labels
    assert (bp.cuts.rounds, bp.cuts.gap) == (opts.cut_rounds, opts.cut_gap)
    given = BPOptions(enum_share=0.5, enum_labels=1000, cut_rounds=2, cut_gap=0.25)
    bp = BranchAndPrice(inst, time_limit=limit, options=given)
    assert bp.enumeration is not None and bp.enumeration.max_labels == 1000
    assert (bp.cuts.rounds, bp.cuts.gap) == (2, 0.25)
    assert BranchAndPrice(inst, time_limit=limit, options=BPOptions(enum_share=0)).enumeration is None


def test_registered_bp_decides_its_options_on_the_users_limit(monkeypatch):
    """The registered bp spends a moment on greedy before solve_bp; at every limit where the
    defaults change, it still passes the options of the user's limit, not of what is left."""
    import sarcover.formulations.bp as bp_package
    from sarcover.benchmarks.registry import METHODS
    from sarcover.formulations.result import Result, Termination

    seen = {}

    def fake_solve_bp(instance, **kw):
        seen.update(kw)
        return Result("bp", Termination.TIME_LIMIT, runtime_s=0.0, reason="stub")

    monkeypatch.setattr(bp_package, "solve_bp", fake_solve_bp)
    steps = _steps()
    assert steps  # the defaults do follow the limit
    for limit in steps:
        METHODS["bp"].run(random_tiny(0, groups=False), time_limit=limit)
        assert seen["time_limit"] < limit
        assert seen["options"] == BPOptions.for_time_limit(limit)
