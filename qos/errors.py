"""The errors the QoS engine raises for user mistakes.

Every one is a ``ValueError`` carrying a single sentence that says where (file, line and column of a
model; index of a trace event; name of a context) and what is wrong, so command-line tools can print
it as it is and exit with status 2.
"""

from __future__ import annotations

from basis.errors import KioskError


class QosError(KioskError, ValueError):
    """Base class of every error the engine raises for bad input."""


class ModelError(QosError):
    """A RoQME model is malformed or uses something the engine does not support.

    The message starts with ``FILE:LINE:COLUMN:`` whenever the problem has a place in the file.
    """


class ContextError(QosError):
    """A batch of context updates is invalid (unknown context, wrong type, time going backwards, …).

    Raised before anything of the batch is applied, so the engine is unchanged.
    """


class TraceError(QosError):
    """A context trace is malformed; the message names the file and the index of the bad event."""
