"""Route-based exact method ``bp``: column generation and branch-and-price on HiGHS."""

from formulations.bp.branch_price import solve_bp

__all__ = ["solve_bp"]
