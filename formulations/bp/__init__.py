"""Route-based exact method ``bp``: branch-and-price for the team orienteering problem with group
cover, on HiGHS.

Every branch-and-bound node solves the route master (:mod:`.master`: set packing with group
cover, subset-row cuts, a certified Lagrangian bound every round) by column generation
(:mod:`.colgen`) with the labelling pricing (:mod:`.pricing`, called through :mod:`.pricer`):
heuristic pricing first, then exact pricing over ng-routes, which gives the bound. With integer
prizes a bound only matters rounded down to the prize lattice (multiples of the prizes' gcd), so
below the root the exact pricing is targeted at the next lattice point that matters, and a node
is pruned as soon as its floored bound does not exceed the incumbent.

The parts, one idea a module:

- :mod:`.branch_price`: :func:`solve_bp`, the front door (a :class:`Result`);
- :mod:`.options`: :class:`BPOptions`, the tunable settings and the time-limit defaults;
- :mod:`.tree`: the branch-and-bound driver (node queue, the root's extra steps, final bound);
- :mod:`.search`: the state every part shares (problem, clock, master, incumbent, lattice);
- :mod:`.node`: a node's branching decisions and the pricing graph they leave;
- :mod:`.colgen`: column generation at a node (targeted pricing, ng set growth);
- :mod:`.cuts`: limited-memory subset-row cut rounds at the root;
- :mod:`.elimination`: reduced-cost arc elimination and MILP column filter under the root's duals;
- :mod:`.incumbent`: plans: dives, the MILP over the generated routes, the caller's heuristic;
- :mod:`.branching`: branching candidates and strong branching;
- :mod:`.stats`: what a run counts and reports in ``Result.info``.

The method's description in full, with its measurements and what was tried and dropped, is in
``docs/bp.md``.
"""

from sarcover.formulations.bp.branch_price import solve_bp
from sarcover.formulations.bp.options import BPOptions

__all__ = ["BPOptions", "solve_bp"]
