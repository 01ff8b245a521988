"""The progress line (benchmarks/progress.py)."""

import io

from sarcover.benchmarks.progress import Progress


def test_progress_bar_counts_and_eta():
    """The progress bar prints count, percentage and an ETA; errors and time limits are tallied."""


    stream = io.StringIO()
    bar = Progress(4, "bench t", stream=stream)
    for status in ("feasible", "error", "time_limit", "optimal"):
        bar.update(status)
    last = stream.getvalue().strip().splitlines()[-1]
    assert "4/4" in last and "100%" in last and "ETA 0:00" in last and "1 error" in last and "1 time_limit" in last
