"""Route-based exact method ``bp``: branch-and-price for the team orienteering problem with group
cover, on HiGHS.

Every branch-and-bound node solves the route master (:mod:`.master`: set packing with group
cover, subset-row cuts, a certified Lagrangian bound every round) by column generation
(:mod:`.colgen`) with the labelling pricing (:mod:`.labelling`, called through :mod:`.pricer`):
heuristic pricing first, then exact pricing over ng-routes, which gives the bound. With integer
prizes a bound only matters rounded down to the prize lattice (multiples of the prizes' gcd), so
below the root the exact pricing is targeted at the next lattice point that matters, and a node
is pruned as soon as its floored bound does not exceed the incumbent.

The parts, one idea a module. The search:

- :mod:`.branch_price`: :func:`solve_bp`, the front door (a :class:`Result`);
- :mod:`.options`: :class:`BPOptions`, the tunable settings and the time-limit defaults;
- :mod:`.tree`: the branch-and-bound driver (builds the parts, node queue, final bound);
- :mod:`.root`: the root's policy (dives, the caller's heuristic, cuts, arc elimination);
- :mod:`.search`: the state every part shares: the problem (:mod:`.problem`: the instance in
  solver points, the prize lattice), the clock (:mod:`.clock`), and the run's state (master,
  ng sets, incumbent, statistics);
- :mod:`.constants`: the tolerances;
- :mod:`.graph`: a node's branching decisions and the pricing graph they leave;
- :mod:`.ng_sets`: what each point remembers in the labelling;
- :mod:`.colgen`: column generation at a node (targeted pricing, ng set growth);
- :mod:`.pricer`: the labelling as the search calls it (timed, counted, its direction);
- :mod:`.cuts`: limited-memory subset-row cut rounds at the root;
- :mod:`.elimination`: reduced-cost arc elimination and MILP column filter under the root's duals;
- :mod:`.enumeration`: closing the root gap or a node by route enumeration and a MILP over its routes;
- :mod:`.enumerated_lp`: the LP over the enumerated routes, with full-memory cuts;
- :mod:`.incumbent`: plans: dives, the MILP over the generated routes, the caller's heuristic;
- :mod:`.branching`: branching candidates and strong branching;
- :mod:`.master`: the route master on HiGHS; :mod:`.highs`: the HiGHS helpers;
- :mod:`.stats`: what a run counts and reports in ``Result.info``.

The kernels (numba):

- :mod:`._label_store`: the label store the labelling and the enumeration share;
- :mod:`.cut_duals`: the cuts' duals as the kernels pay them;
- :mod:`.bounds`: the completion bound and the suffix tables;
- :mod:`.labelling`: the pricing's labelling, one-way or bidirectional;
- :mod:`.arc_bounds`: the best route through each arc, for arc elimination;
- :mod:`.enumeration_kernel`: every elementary route above a threshold;
- :mod:`.compile`: :func:`warm_up`, which compiles them all before a run starts its clock.

The method's description is in ``docs/bp.md``; its measurements, and what was tried and
dropped, in ``docs/bp-log.md``.
"""

from sarcover.formulations.bp.branch_price import solve_bp
from sarcover.formulations.bp.compile import warm_up
from sarcover.formulations.bp.options import BPOptions

__all__ = ["BPOptions", "solve_bp", "warm_up"]
