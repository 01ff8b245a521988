"""The tolerances every part of the branch-and-price shares."""

TOL = 1e-6  # LP values, bounds and reduced prizes: a difference beyond this counts
EPS = 1e-9  # labels' energies and prizes in the dominance tests: equal within this
