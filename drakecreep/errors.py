"""Errors a user can act on: one line naming the field, the value and what is allowed."""

import reprlib

__all__ = ["DrakecreepError", "InputError", "Terminated", "name_list", "renaming", "short_repr"]

#: longest value shown in a message: a value from a file may be huge (a YAML alias bomb expands to
#: billions of items) and its whole ``repr()`` would hang the program before it could print one line
MAX_VALUE_CHARS = 120

_REPR = reprlib.Repr()
_REPR.maxlevel, _REPR.maxdict, _REPR.maxlist, _REPR.maxtuple, _REPR.maxset = 3, 4, 6, 6, 6
_REPR.maxstring, _REPR.maxother, _REPR.maxlong = MAX_VALUE_CHARS, MAX_VALUE_CHARS, 40


def short_repr(value, limit=MAX_VALUE_CHARS):
    """``repr(value)`` bounded in work and length (at most ``limit`` characters, ``...`` marks a cut)."""
    try:
        text = _REPR.repr(value)
    except Exception:  # noqa: BLE001 - a value whose repr fails still gets a message
        text = f"<{type(value).__name__}>"
    return text if len(text) <= limit else text[: limit - 3] + "..."


class Terminated(KeyboardInterrupt):
    """A ``SIGTERM`` (``kill``, ``timeout``, a job scheduler, ``docker stop``) handled as a Ctrl-C: what runs stops
    and keeps what was computed, and the command line exits 143 (128 + 15). Without it Python ended at once:
    no partial results, the pool's workers left to notice, a ``resource_tracker`` warning of leaked semaphores."""


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

    The message shows at most :data:`MAX_VALUE_CHARS` characters of the value (:func:`short_repr`).
    """

    def __init__(self, field, value, allowed):
        self.field = field
        self.value = value
        self.allowed = allowed
        super().__init__(f"{short_repr(field, 200) if not isinstance(field, str) else field[:200]}: "
                         f"got {short_repr(value)}; allowed: {str(allowed)[:600]}")

    def __reduce__(self):
        # rebuilt from its three parts, not from the message: a worker process's error reaches the parent whole
        # (unpickling InputError(message) failed and broke the process pool: 'BrokenProcessPool', exit 1)
        import pickle

        value = self.value
        try:
            pickle.dumps(value)
        except Exception:  # noqa: BLE001 - an unpicklable value travels as its bounded repr
            value = short_repr(value)
        return type(self), (self.field, value, self.allowed)

    def renamed(self, field):
        """The same error naming ``field`` instead: a caller names the option or the file the value came from
        (``--conformity`` for the model's ``conformity``, ``run.yaml: params.screw.lead`` for ``screw.lead``)."""
        return type(self)(field, self.value, self.allowed)

    @classmethod
    def unknown_field(cls, field, known):
        """A key that names no field of a mapping whose fields are ``known`` (the value is not echoed)."""
        return cls(field, "an unknown field", "one of the known fields " + ", ".join(sorted(known)))


def renaming(field, build, *args, **kwargs):
    """``build(*args, **kwargs)``; an :class:`InputError` it raises goes on as ``err.renamed(field(err.field))``, so the
    caller names where the value came from (a file, a sweep spec's key) around a builder that knows only the field."""
    try:
        return build(*args, **kwargs)
    except InputError as err:
        raise err.renamed(field(err.field)) from None


def name_list(value, field):
    """``value``, a sequence of names (effects, parameter paths), as a tuple; an :class:`InputError` naming ``field``
    for one string (its letters were taken for the names: 'effects: got 's'') or a name given twice (fitted twice)."""
    if isinstance(value, (str, bytes)):
        raise InputError(field, value, f"a list of names (one name goes in a list: [{value!r}])")
    try:
        names = tuple(value)
    except TypeError:
        raise InputError(field, value, "a list of names") from None
    twice = sorted({str(n) for n in names if names.count(n) > 1})
    if twice:
        raise InputError(field, value, f"each name once ({', '.join(twice)} given twice)")
    return names
