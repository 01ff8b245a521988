"""Errors raised on bad input. Their message is one line that names the problem."""


class SarcoverError(Exception):
    """Base of every error caused by user input; the CLI prints it on one line, exit code 2."""


class InstanceError(SarcoverError, ValueError):
    """An instance (or instance file) that cannot be used; the message names the field."""
