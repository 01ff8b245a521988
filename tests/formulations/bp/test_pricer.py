"""The pricer lays each exact call out for the labels of the one before it."""

from __future__ import annotations

from sarcover.formulations.bp import solve_bp


def test_exact_pricing_is_laid_out_for_the_previous_exact_calls_labels(monkeypatch):
    """The search's exact calls pass the dominance layout sized by the previous exact call's
    label count (the first call, and every heuristic one, the default)."""
    import sarcover.formulations.bp.pricer as pricer_mod
    from sarcover.formulations.bp.labelling import sub_buckets
    from sarcover.formulations.generate import generate
    from sarcover.formulations.instance import to_top
    from sarcover.formulations.result import Termination

    seen = []
    real = pricer_mod.price

    def spy(*args, **kw):
        res = real(*args, **kw)
        seen.append((kw["heuristic"], kw["nsub"], res.n_labels, args[0].shape[0]))
        return res

    monkeypatch.setattr(pricer_mod, "price", spy)
    res = solve_bp(to_top(generate(8, 3, 2, 3)), time_limit=20)
    assert res.termination == Termination.OPTIMAL
    exact = [(nsub, labels, n) for heuristic, nsub, labels, n in seen if not heuristic]
    assert len(exact) >= 2
    assert all(nsub is None for heuristic, nsub, _, _ in seen if heuristic)
    assert exact[0][0] == sub_buckets(exact[0][2])
    for (_, before, _), (nsub, _, n) in zip(exact, exact[1:]):
        assert nsub == sub_buckets(n, before)
