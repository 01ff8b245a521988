"""sarcover: exact and heuristic benchmarking for multi-view SAR-UAV coverage path planning."""
