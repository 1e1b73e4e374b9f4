"""Exceptions raised by hdi_tribology: one class per kind of error of the Rust crate.

Every exception keeps the crate's message as ``str(e)`` and its parts as attributes.
"""

from typing import Optional


class HdiError(Exception):
    """Base class of every error raised by hdi_tribology."""

    def __init__(self, message: str, *, reason: Optional[str] = None, **parts: str) -> None:
        super().__init__(message)
        #: Why it failed (for InvalidInputError: the value seen, in the unit of the field).
        self.reason = reason if reason is not None else message
        for k, v in parts.items():
            setattr(self, k, v)


class InvalidInputError(HdiError, ValueError):
    """A value out of its valid range: ``field`` names it as written (dotted scene path or
    argument name), ``reason`` says why."""

    field: str


class SceneError(HdiError, ValueError):
    """A scene file or text that cannot be read or parsed: ``origin`` is the file name or
    ``<string>``, ``reason`` the parser's message (naming the field where it can)."""

    origin: str


class NoConvergenceError(HdiError, ArithmeticError):
    """A numerical procedure did not reach its tolerance: ``what`` (the procedure), ``reason``
    and ``kind`` (the failure's name, e.g. ``IntervalBudget``)."""

    what: str
    kind: str


class AnalysisError(HdiError):
    """An analysis cannot produce its result for this scene: ``what`` (the analysis),
    ``reason`` and ``kind`` (the failure's name, e.g. ``NoTakeOff``)."""

    what: str
    kind: str


class SolverError(HdiError, ArithmeticError):
    """The ODE stepper failed; ``reason`` says at which time and why."""


class FileError(HdiError, OSError):
    """Reading or writing a file failed: ``path`` and ``reason``."""

    path: str


class DataFileError(HdiError, ValueError):
    """A bad measurement file for ``fit``: ``file``, ``line`` and ``column`` (1-based, or
    None), ``column_name`` and ``reason`` (with the value as written)."""

    file: str
