"""The route master's rows and columns: visit counts, branching decisions, groups, cuts, its MILP."""

from __future__ import annotations

import numpy as np
import pytest

from bp_cases import top_instance


def test_ng_route_columns_count_visits():
    """A repeated point counts twice in its node row (never integer-feasible); routes that stop
    being ng-routes when the ng sets grow are excluded from the master."""
    from sarcover.formulations.bp.graph import NodeState
    from sarcover.formulations.bp.master import Master
    from sarcover.formulations.bp.ng_sets import add_to_ng, nearest_ng

    m = Master(4, np.ones(4), [(0, 1)], 2)
    m.add_routes([(1, 2, 3, 1), (1, 2), (3, 4)])
    assert m.repeated == [0]
    assert list(m.node_visits(np.array([1.0, 0.0, 0.0]))[1:5]) == [2.0, 1.0, 1.0, 0.0]
    assert m.milp(5.0) is not None and (1, 2, 3, 1) not in m.milp(5.0)
    cost = np.abs(np.subtract.outer(np.arange(6.0), np.arange(6.0)))
    ng = nearest_ng(cost, 1)  # each point remembers only itself: the cycle 1-2-3-1 is an ng-route
    assert m.kill_non_ng(ng) == 0
    add_to_ng(ng, 2, 1)
    add_to_ng(ng, 3, 1)  # now 1 is remembered at 2 and 3: revisiting it is forbidden
    assert m.kill_non_ng(ng) == 1
    assert list(m.incompatible(NodeState())) == [True, False, False]


def test_branching_decisions_exclude_exactly_the_conflicting_routes():
    """Master.incompatible against its definition, route by route (repeated visits included):
    a route is out iff it visits a forbidden point, uses a forbidden arc, or leaves the tail of a
    forced arc (not the start) or enters its head (not the end) by another arc."""
    from sarcover.formulations.bp.graph import NodeState
    from sarcover.formulations.bp.master import Master

    rng = np.random.default_rng(3)
    V, end = 7, 8
    m = Master(V, np.ones(V), [], 3)
    routes = {tuple(int(p) for p in rng.choice(np.arange(1, V + 1), size=rng.integers(1, 6)))
              for _ in range(300)}  # random, some with repeated points
    m.add_routes(sorted(routes))
    assert m.repeated
    arcs_of = [list(zip([0, *r], [*r, end])) for r in m.routes]

    def out(r, st):
        arcs = arcs_of[r]
        return (any(p in st.forbidden_nodes for p in m.routes[r])
                or any(a in st.forbidden_arcs for a in arcs)
                or any((a == fa and fa != 0 and b != fb) or (b == fb and fb != end and a != fa)
                       for fa, fb in st.forced_arcs for a, b in arcs))

    pts = list(range(0, V + 2))
    shared = 0  # states where two forced arcs leave the same point (or enter the same one)
    for _ in range(200):
        pick = lambda: (int(rng.choice(pts[:-1])), int(rng.choice(pts[1:])))  # noqa: E731
        st = NodeState(forbidden_nodes=frozenset(int(p) for p in rng.choice(
                           np.arange(1, V + 1), size=rng.integers(0, 2))),
                       forbidden_arcs=frozenset(pick() for _ in range(rng.integers(0, 3))),
                       forced_arcs=frozenset(pick() for _ in range(rng.integers(0, 5))))
        tails = [a for a, _ in st.forced_arcs if a != 0]
        heads = [b for _, b in st.forced_arcs if b != end]
        shared += len(set(tails)) < len(tails) or len(set(heads)) < len(heads)
        got = m.incompatible(st)
        assert list(got) == [out(r, st) for r in range(m.n_routes)]
    assert shared > 0
    m.hide_repeated = True
    assert all(m.incompatible(NodeState())[m.repeated])


def test_group_bounds_set_the_group_rows():
    """A node's bounds on a group's visits become the group row's bounds (the cover row's lower
    bound 1 stays the floor), bind in the LP, count in the Lagrangian bound, and go when the
    master is set to a node without them."""
    from sarcover.formulations.bp.graph import NodeState
    from sarcover.formulations.bp.master import Master

    m = Master(4, np.ones(4), [(0, 1, 2), (3,)], 4)  # group 0: points 1-3, group 1: point 4
    m.add_routes([(1,), (2,), (3,), (4,)])
    row = 1 + m.V  # group 0's row
    values = {}
    for hi in (np.inf, 2.0, 1.0):
        st = NodeState().child(group_bounds=[(0, -np.inf, hi)])
        m.apply(st)
        assert (m.cur_lo[row], m.cur_hi[row]) == (1.0, hi)
        value, x, xa, y = m.solve()
        assert xa.max() < 1e-9 and m.group_visits(x)[0] == pytest.approx(min(hi, 3.0))
        # nothing left to price: the certificate is the LP value
        assert m.lagrangian_bound(y, 0.0) == pytest.approx(value)
        values[hi] = value
    assert values == {np.inf: 4.0, 2.0: 3.0, 1.0: 2.0}
    m.apply(NodeState().child(group_bounds=[(0, 2.0, np.inf)]))
    assert (m.cur_lo[row], m.cur_hi[row]) == (2.0, np.inf)
    m.apply(NodeState())
    assert (m.cur_lo[row], m.cur_hi[row]) == (1.0, np.inf) and m.solve()[0] == pytest.approx(4.0)


def test_milp_start_plan_is_a_floor():
    """The MILP takes a plan as its first solution: with only that plan's routes allowed it
    returns that plan, under any time limit it returns nothing worse, and a start that is not
    made of generated routes is ignored (p2.2.k)."""
    from sarcover.formulations.bp.graph import NodeState
    from sarcover.formulations.bp.tree import BranchAndPrice

    inst = top_instance("p2.2.k")
    bp = BranchAndPrice(inst, time_limit=30)
    bp.colgen.solve(NodeState(), np.inf)
    m = bp.search.master
    value = lambda routes: sum(m.route_prize[m.routes.index(r)] for r in routes)  # noqa: E731
    best = m.milp(20.0)
    start = sorted(best, key=len)[1:]  # a worse plan: the best without its shortest route
    assert value(start) < value(best)
    only = m.milp(5.0, np.zeros(m.n_routes, dtype=bool), start=start)
    assert sorted(only) == sorted(start)
    quick = m.milp(0.05, None, start=start)
    assert quick is not None and value(quick) >= value(start) - 1e-9
    unknown = [tuple(range(1, inst.n_nodes + 1))]  # not a generated route
    assert m.milp(5.0, np.zeros(m.n_routes, dtype=bool), start=unknown) in (None, [])


def test_lm_coefficient_counts_pairs_and_forgets_outside_memory():
    """Pairs of visits to the triple; an unpaired visit is forgotten at a point outside the
    memory, so the coefficient never exceeds floor(visits / 2) (the full cut's)."""
    from sarcover.formulations.bp.master import _lm_coefficient

    S, full = (1, 2, 3), frozenset(range(10))
    assert _lm_coefficient((1, 5, 2), S, full) == 1
    assert _lm_coefficient((1, 5, 2), S, frozenset({1, 2, 3})) == 0  # 5 makes it forget 1
    assert _lm_coefficient((1, 5, 2), S, frozenset({1, 2, 3, 5})) == 1
    assert _lm_coefficient((1, 2, 3), S, frozenset(S)) == 1
    assert _lm_coefficient((4, 6), S, full) == 0
    assert _lm_coefficient((1, 2, 1, 2), S, full) == 2  # an ng-route's repeated visits count


def test_master_cut_rows_hold_lm_coefficients():
    """Cut rows get the limited-memory coefficient of routes generated before and after the
    cut; separation finds a violated triple in a fractional LP and its memory keeps it violated."""
    from sarcover.formulations.bp.master import Master, _lm_coefficient

    m = Master(6, np.ones(6), [], 3)
    m.add_routes([(1, 2), (2, 3), (1, 3)])  # each x = 1/2 violates the cut on {1, 2, 3}: 3/2 > 1
    x = np.full(3, 0.5)
    cuts = m.separate_cuts(x, 4)
    assert [S for S, _ in cuts] == [(1, 2, 3)]
    assert m.add_cuts(cuts) == 1 and m.cuts == [(1, 2, 3)]
    m.add_routes([(1, 4, 2), (4, 5)])
    lp = m.h.getLp()
    a = lp.a_matrix_
    row = m.base_rows
    got = {}
    for j in range(m.n_routes):
        col = m.n_art + j
        lo, hi = a.start_[col], a.start_[col + 1]
        coef = dict(zip(a.index_[lo:hi], a.value_[lo:hi]))
        got[m.routes[j]] = coef.get(row, 0.0)
        assert got[m.routes[j]] == _lm_coefficient(m.routes[j], (1, 2, 3), m.memories[0])
    assert got[(1, 2)] == 1 and got[(4, 5)] == 0
    value, xs, xa, y = m.solve()
    assert sum(got[r] * xs[j] for j, r in enumerate(m.routes)) <= 1.0 + 1e-9  # the cut holds
    # memory {1, 2, 3}: (1, 4, 2) forgets 1 at 4 and pays nothing, so the LP uses it at 1/2
    assert got[(1, 4, 2)] == 0 and value == pytest.approx(4.5)
    assert m.cut_duals(y).shape == (1,)


def test_purged_cuts_leave_the_lp_and_free_their_bits():
    """Purging drops exactly the cuts of zero dual: same LP value, the rows and bitsets of the
    kept cuts renumbered, and routes and cuts added afterwards get the right coefficients."""
    from sarcover.formulations.bp.master import Master, _lm_coefficient

    m = Master(6, np.ones(6), [], 6)
    m.add_routes([(1, 2), (2, 3), (1, 3), (4,), (5,), (6,)])
    idle = ((4, 5, 6), frozenset({4, 5, 6}))  # no route visits two of them: zero dual
    assert m.add_cuts([idle, ((1, 2, 3), frozenset({1, 2, 3}))]) == 2
    value, _, _, y = m.solve()
    assert value == pytest.approx(5.0)  # one route of the triangle + the three singles
    assert m.cut_duals(y)[0] == 0 and m.cut_duals(y)[1] > 0
    assert m.purge_cuts(y) == 1
    assert m.cuts == [(1, 2, 3)] and m.n_rows == m.base_rows + 1
    assert m.h.getNumRow() == m.n_rows and len(m.row_lo) == len(m.row_hi) == m.n_rows
    assert [int(b) for b in m.cut_members[1:7]] == [1, 1, 1, 0, 0, 0]
    assert m.solve()[0] == pytest.approx(value)
    m.add_routes([(1, 2, 3)])  # pays 1 in the kept cut's row (now row base_rows)
    a = m.h.getLp().a_matrix_
    col = m.n_art + m.n_routes - 1
    coef = dict(zip(a.index_[a.start_[col] : a.start_[col + 1]], a.value_[a.start_[col] : a.start_[col + 1]]))
    assert coef.get(m.base_rows) == _lm_coefficient((1, 2, 3), (1, 2, 3), m.memories[0]) == 1
    assert m.solve()[0] == pytest.approx(6.0)
    assert m.add_cuts([idle]) == 1 and int(m.cut_members[4]) == 2  # the next free bit


def test_removed_cuts_leave_the_lp_whatever_their_dual():
    """remove_cuts drops the cuts asked for, even one the LP leans on: the LP gets weaker by
    exactly that row, and the kept cuts' rows and bits are renumbered."""
    from sarcover.formulations.bp.master import Master

    m = Master(6, np.ones(6), [], 6)
    m.add_routes([(1, 2), (2, 3), (1, 3), (4,), (5,), (6,)])
    idle = ((4, 5, 6), frozenset({4, 5, 6}))
    assert m.add_cuts([((1, 2, 3), frozenset({1, 2, 3})), idle]) == 2
    value, _, _, y = m.solve()
    assert value == pytest.approx(5.0) and m.cut_duals(y)[0] > 0
    assert m.remove_cuts([0]) == 1
    assert m.cuts == [(4, 5, 6)] and m.n_rows == m.base_rows + 1 == m.h.getNumRow()
    assert [int(b) for b in m.cut_members[1:7]] == [0, 0, 0, 1, 1, 1]
    assert m.solve()[0] == pytest.approx(6.0)  # the triangle at 1/2 each again
    assert m.remove_cuts([]) == 0 and m.cuts == [(4, 5, 6)]


def test_primal_simplex_master_solves_the_same_lp():
    """The route master with HiGHS's primal simplex (``primal_simplex_from``) gives the same LP
    value as with the default simplex, after columns are added to a solved LP."""
    from sarcover.formulations.bp.master import Master
    from sarcover.formulations.generate import generate
    from sarcover.formulations.instance import to_top

    inst = to_top(generate(6, 3, 2, 5))
    rng = np.random.default_rng(0)
    batches = [[tuple(int(p) for p in rng.choice(np.arange(1, inst.n_nodes + 1), 4, replace=False))
                for _ in range(15)] for _ in range(3)]
    values = {}
    for primal in (False, True):
        m = Master(inst.n_nodes, inst.prizes, inst.groups, inst.n_vehicles, primal_simplex=primal)
        got = []
        for batch in batches:
            m.add_routes(batch)
            got.append(m.solve()[0])
        values[primal] = got
        strategy = m.h.getOptionValue("simplex_strategy")
        strategy = strategy[1] if isinstance(strategy, tuple) else strategy  # (status, value)
        assert strategy == (4 if primal else 1)
    assert values[True] == pytest.approx(values[False])
