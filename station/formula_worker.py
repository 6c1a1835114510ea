"""The process that evaluates total formulas for the station (:mod:`station.formulas`), so that
nothing a kiosk sent ever runs in the serving process: a FHIRPath formula's regular expression
can take exponential time, and Python's ``re`` holds the interpreter lock while it does.

One request per line on stdin (JSON: ``sha``, ``definition`` the first time a hash is asked,
``options``, ``values``), one answer per line on stdout (``{"total": N}`` or ``{"problem": "..."}``).
It keeps the questionnaires it rebuilt by hash; its parent kills it when an answer is late and
it dies with its parent (``PR_SET_PDEATHSIG``).
"""

from __future__ import annotations

import json
import sys
from typing import Any

MEMORY_BYTES = 1 << 30


def _limit() -> None:
    """At most :data:`MEMORY_BYTES` of memory, and die with the parent (Linux)."""
    import contextlib
    import resource
    import signal

    with contextlib.suppress(ValueError, OSError):
        resource.setrlimit(resource.RLIMIT_AS, (MEMORY_BYTES, MEMORY_BYTES))
    with contextlib.suppress(OSError, AttributeError):
        import ctypes

        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG


def answer(request: dict[str, Any], kept: dict[str, Any]) -> dict[str, Any]:
    from kiosk.core.questionnaire.definition import questionnaire_from
    from kiosk.core.questionnaire.scoring import ScoringError, formula_total, response_items

    sha = request["sha"]
    if sha not in kept:
        if "definition" not in request:
            return {"need": sha}
        kept[sha] = questionnaire_from(request["definition"])
    q = kept[sha]
    if q.formula is None:
        return {"problem": f"{q.id} has no total formula"}
    try:
        total = formula_total(q, q.formula, {"item": response_items(q, request["options"], request["values"])})
    except ScoringError as exc:
        return {"problem": str(exc)}
    return {"total": total}


def main() -> int:
    _limit()
    kept: dict[str, Any] = {}
    for line in sys.stdin:
        try:
            reply = answer(json.loads(line), kept)
        except MemoryError:
            reply = {"problem": "the total formula needed more memory than it may use"}
        except Exception as exc:  # a definition or formula this process cannot read: said, not fatal
            reply = {"problem": f"the total formula cannot be evaluated: {type(exc).__name__}: {exc}"[:500]}
        sys.stdout.write(json.dumps(reply) + "\n")
        sys.stdout.flush()
    return 0


if __name__ == "__main__":
    sys.exit(main())
