"""Errors a user can act on: one line naming the field, the value and what is allowed."""

__all__ = ["DrakecreepError", "InputError"]


class DrakecreepError(Exception):
    """Base class of errors whose message is meant for the user (the CLI prints it and exits 2)."""


class InputError(DrakecreepError, ValueError):
    """A bad input value.

    Parameters
    ----------
    field : str
        Dotted name of the offending field (e.g. ``screw.lead``) or CLI option (``--feed``).
    value : object
        The value that was given.
    allowed : str
        What would have been accepted (e.g. ``"> 0"``, ``"one of coulomb, stribeck, lugre"``).
    """

    def __init__(self, field, value, allowed):
        self.field = field
        self.value = value
        self.allowed = allowed
        super().__init__(f"{field}: got {value!r}; allowed: {allowed}")
