"""Route-based exact method ``bp``: column generation and branch-and-price on HiGHS."""

from sarcover.formulations.bp.branch_price import default_cut_gap, default_cut_rounds, solve_bp

__all__ = ["default_cut_gap", "default_cut_rounds", "solve_bp"]
