"""Route-based exact method ``bp``: column generation and branch-and-price on HiGHS."""

from sarcover.formulations.bp.branch_price import solve_bp
from sarcover.formulations.bp.options import BPOptions

__all__ = ["BPOptions", "solve_bp"]
