"""Improving routes by local search from the master's own routes: the cheap pricing heuristic
that runs before the labelling from ``route_search_from`` points on (docs/bp.md, column
generation).

At hundreds of points a heuristic labelling call takes seconds and the restricted LP needs
hundreds of rounds to rise (it is degenerate: it sits at the incumbent's routes while every
call finds improving routes). A route of the LP solution has reduced prize 0 under the LP's
duals, so any move that adds reduced prize within the budget gives an improving route, in
microseconds. :func:`improving_routes` starts from the LP solution's routes and the columns of
highest reduced prize and applies, best first, the moves that raise the route's reduced prize
(insert a point at its cheapest position, drop a point of negative reduced prize, replace a
point in place); when none fits it shortens the route by the best 2-opt reversal and tries
again. Every route passed on the way that beats the threshold is a candidate column. Each
step raises the prize or, at equal prize, lowers the energy, so the search ends.

The routes are elementary and priced exactly (the points' reduced prizes, as the labelling
sums them, against the vehicle dual); the subset-row cuts' duals are not paid here, so the
caller only uses it while the master has no cuts. It proves nothing: when it finds no
improving route the labelling runs as before.
"""

from __future__ import annotations

import numpy as np
from numba import njit

GAIN_TOL = 1e-9


@njit(cache=True)
def _energy(route, n, cost, end):
    e = cost[0, route[0]] if n else cost[0, end]
    for i in range(n - 1):
        e += cost[route[i], route[i + 1]]
    if n:
        e += cost[route[n - 1], end]
    return e


@njit(cache=True)
def _best_prize_move(route, n, cost, prof, allowed, inroute, budget, energy, end):
    """The move that raises the route's reduced prize most within the budget (ties: less
    energy): (kind, position, point, new energy, gain); kind 0 = none, 1 = insert ``point``
    before ``position``, 2 = drop the point at ``position``, 3 = replace it by ``point``."""
    best_kind, best_pos, best_pt = 0, -1, -1
    best_gain, best_e = GAIN_TOL, np.inf
    V2 = prof.shape[0]
    for i in range(n):  # drop a point of negative reduced prize
        v = route[i]
        if -prof[v] > GAIN_TOL:
            a = route[i - 1] if i > 0 else 0
            b = route[i + 1] if i + 1 < n else end
            e = energy - cost[a, v] - cost[v, b] + cost[a, b]
            g = -prof[v]
            if e <= budget and (g > best_gain + GAIN_TOL or (g > best_gain - GAIN_TOL
                                                              and e < best_e)):
                best_kind, best_pos, best_pt, best_gain, best_e = 2, i, v, g, e
    for u in range(1, V2 - 1):
        if not allowed[u] or inroute[u] or prof[u] <= GAIN_TOL:
            continue
        # insert u at its cheapest position
        for i in range(n + 1):
            a = route[i - 1] if i > 0 else 0
            b = route[i] if i < n else end
            e = energy - cost[a, b] + cost[a, u] + cost[u, b]
            g = prof[u]
            if e <= budget and (g > best_gain + GAIN_TOL or (g > best_gain - GAIN_TOL
                                                              and e < best_e)):
                best_kind, best_pos, best_pt, best_gain, best_e = 1, i, u, g, e
        # replace the point at i by u
        for i in range(n):
            v = route[i]
            g = prof[u] - prof[v]
            if g <= GAIN_TOL:
                continue
            a = route[i - 1] if i > 0 else 0
            b = route[i + 1] if i + 1 < n else end
            e = energy - cost[a, v] - cost[v, b] + cost[a, u] + cost[u, b]
            if e <= budget and (g > best_gain + GAIN_TOL or (g > best_gain - GAIN_TOL
                                                              and e < best_e)):
                best_kind, best_pos, best_pt, best_gain, best_e = 3, i, u, g, e
    return best_kind, best_pos, best_pt, best_e, best_gain


@njit(cache=True)
def _best_reversal(route, n, cost, energy, end):
    """The 2-opt reversal of route[i..j] that saves most energy: (i, j, new energy); i = -1:
    none saves any."""
    best_i, best_j, best_e = -1, -1, energy - 1e-7
    for i in range(n - 1):
        a = route[i - 1] if i > 0 else 0
        inner = 0.0  # what reversing the arcs inside route[i..j] changes, grown with j
        for j in range(i + 1, n):
            b = route[j + 1] if j + 1 < n else end
            inner += cost[route[j], route[j - 1]] - cost[route[j - 1], route[j]]
            # arcs a -> route[i] ... route[j] -> b become a -> route[j] ... route[i] -> b
            e = energy - cost[a, route[i]] - cost[route[j], b] + cost[a, route[j]] + \
                cost[route[i], b] + inner
            if e < best_e:
                best_i, best_j, best_e = i, j, e
    return best_i, best_j, best_e


@njit(cache=True)
def _search(start, cost, prof, allowed, budget, min_gain, max_moves, out, out_len, out_val,
            n_out):
    """Local search from one route (``start``); writes every route passed whose reduced
    prize beats ``min_gain`` into ``out`` from row ``n_out`` on and returns the new row
    count."""
    V2 = prof.shape[0]
    end = V2 - 1
    cap = out.shape[1]
    route = np.zeros(cap, dtype=np.int64)
    inroute = np.zeros(V2, dtype=np.bool_)
    n = start.shape[0]
    for i in range(n):
        route[i] = start[i]
        inroute[start[i]] = True
    energy = _energy(route, n, cost, end)
    val = 0.0
    for i in range(n):
        val += prof[route[i]]
    for _ in range(max_moves):
        kind, pos, pt, e, g = _best_prize_move(route, n, cost, prof, allowed, inroute, budget,
                                               energy, end)
        if kind == 0:
            i, j, e = _best_reversal(route, n, cost, energy, end)
            if i < 0:
                break
            route[i : j + 1] = route[i : j + 1][::-1].copy()
            energy = e
            continue
        if kind == 1:
            if n >= cap:
                break
            route[pos + 1 : n + 1] = route[pos:n].copy()
            route[pos] = pt
            inroute[pt] = True
            n += 1
        elif kind == 2:
            inroute[route[pos]] = False
            route[pos : n - 1] = route[pos + 1 : n].copy()
            n -= 1
        else:
            inroute[route[pos]] = False
            route[pos] = pt
            inroute[pt] = True
        energy = e
        val += g
        if val > min_gain and n_out < out.shape[0]:
            out[n_out, :n] = route[:n]
            out_len[n_out] = n
            out_val[n_out] = val
            n_out += 1
    return n_out


def improving_routes(starts, cost: np.ndarray, prof: np.ndarray, allowed: np.ndarray,
                     budget: float, min_gain: float, n_cols: int,
                     max_moves: int = 200) -> list[tuple[int, ...]]:
    """Up to ``n_cols`` distinct elementary routes whose reduced prize (``prof`` summed over
    their points, as the labelling counts it) beats ``min_gain`` (the vehicle dual, for an
    improving route), best first, found by local search from each route of ``starts`` (tuples
    of solver points without start and end; a repeated point is kept once). ``cost``: the
    node's arc energies (removed arcs at inf), ``allowed``: its points."""
    starts = [tuple(dict.fromkeys(r)) for r in starts if r]
    if not starts:
        return []
    longest = max(len(r) for r in starts)
    cap = longest + max_moves
    per_start = min(max_moves, 50)  # routes kept from one start
    rows = len(starts) * per_start
    out = np.zeros((rows, cap), dtype=np.int64)
    out_len = np.zeros(rows, dtype=np.int64)
    out_val = np.zeros(rows)
    prof = np.asarray(prof, dtype=np.float64)
    allowed = np.asarray(allowed, dtype=np.bool_)
    n_out = 0
    for r in starts:
        limit = n_out + per_start
        n_out = _search(np.asarray(r, dtype=np.int64), cost, prof, allowed, budget, min_gain,
                        max_moves, out[:limit], out_len[:limit], out_val[:limit], n_out)
    found: dict[tuple[int, ...], float] = {}
    for k in np.argsort(-out_val[:n_out], kind="stable"):
        route = tuple(int(p) for p in out[k, : out_len[k]])
        if route not in found:
            found[route] = out_val[k]
            if len(found) >= n_cols:
                break
    return list(found)
