"""The error of a benchmark run that cannot start or go on (results directory, scheduler, settings)."""

from sarcover.formulations.errors import SarcoverError


class HarnessError(SarcoverError):
    """A benchmark run that cannot start (results directory, scheduler, changed settings)."""
