"""Total formulas run away from the serving process, under time and size budgets.

A definition's total formula (FHIRPath) comes from whoever wrote the definition, and a kiosk
sends the definition with every session. Evaluated in the station's own process, one formula
with a catastrophic regular expression froze the whole station (``re`` holds the interpreter
lock: ``/healthz`` timed out, SIGTERM went unheard for half an hour). So here:

- a formula runs only in :mod:`station.formula_worker`, a child process, which answers within
  :data:`TIMEOUT_S` or is killed (SIGKILL) and started again for the next; its memory is capped;
- a formula longer than :data:`EXPRESSION_MAX` characters is not run at all;
- a definition whose formula once ran out of time is not run again by this process;
- a definition the station does not know (not shipped, not registered by staff, not approved by
  a doctor: :mod:`station.known`) has its formula run by nobody: its results show no total, and
  say that the definition waits for a doctor's approval.

:class:`GuardedQuestionnaire` is the questionnaire the station scores such a definition with:
every scoring of the station (pages, lists, exports) goes through its :meth:`score_answers`.
"""

from __future__ import annotations

import atexit
import json
import os
import select
import subprocess
import sys
import threading
from collections.abc import Mapping
from dataclasses import replace
from pathlib import Path
from typing import Any

from basis import record
from kiosk.core.questionnaire import Questionnaire, Score

#: the longest a formula may take on one response (seconds, wall clock; ``--formula-timeout``)
TIMEOUT_S = 2.0
#: the longest formula the station runs (characters)
EXPRESSION_MAX = 4096
#: the longest answer the worker may give (bytes)
REPLY_MAX = 65536
#: how long the worker may take to start (importing the FHIRPath engine)
START_S = 60.0
ROOT = Path(__file__).resolve().parent.parent


class _Worker:
    """One child process evaluating formulas, one request at a time."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._process: subprocess.Popen[bytes] | None = None
        #: definitions the current process has been sent
        self._told: set[str] = set()
        #: definitions whose formula ran out of time once: never run again here
        self.slow: set[str] = set()

    def _started(self) -> subprocess.Popen[bytes]:
        if self._process is None or self._process.poll() is not None:
            env = os.environ | {"PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))}
            self._process = subprocess.Popen(
                [sys.executable, "-m", "station.formula_worker"],
                stdin=subprocess.PIPE,
                stdout=subprocess.PIPE,
                stderr=subprocess.DEVNULL,
                cwd=ROOT,
                env=env,
            )
            self._told = set()
        return self._process

    def stop(self) -> None:
        """Kill the worker (the station is stopping, or the worker ran out of time)."""
        process, self._process = self._process, None
        if process is not None and process.poll() is None:
            process.kill()
            process.wait()

    def total(
        self, sha: str, definition: Mapping[str, Any], options: Mapping[str, int], values: Mapping[str, float]
    ) -> tuple[int | None, str]:
        """The formula's total on these answers, or None and why not."""
        if sha in self.slow:
            return None, f"the total formula took longer than {TIMEOUT_S:g} s once: it is not run again"
        with self._lock:
            process = self._started()
            request: dict[str, Any] = {"sha": sha, "options": dict(options), "values": dict(values)}
            if sha not in self._told:
                request["definition"] = definition
            first = len(self._told) == 0 and process.poll() is None
            assert process.stdin is not None and process.stdout is not None
            try:
                process.stdin.write(json.dumps(request).encode() + b"\n")
                process.stdin.flush()
            except OSError:
                self.stop()
                return None, "the formula process stopped: the total is not evaluated"
            # the first answer of a new worker includes its start (importing the FHIRPath engine)
            ready, _, _ = select.select([process.stdout], [], [], TIMEOUT_S + (START_S if first else 0.0))
            if not ready:
                self.stop()
                self.slow.add(sha)
                return None, f"the total formula took longer than {TIMEOUT_S:g} s: it is not evaluated"
            line = process.stdout.readline(REPLY_MAX)
            self._told.add(sha)
        try:
            reply = json.loads(line)
        except ValueError:
            self.stop()
            return None, "the formula process gave no answer: the total is not evaluated"
        if isinstance(reply.get("total"), int):
            return reply["total"], ""
        return None, str(reply.get("problem", "the total formula gave no total"))[:500]


WORKER = _Worker()
atexit.register(WORKER.stop)


@record
class GuardedQuestionnaire(Questionnaire):
    """A questionnaire with a total formula, scored by :data:`WORKER` (and only when its
    definition is known to the station)."""

    #: the definition's SHA-256 and its canonical body (what the worker rebuilds it from)
    sha: str = ""
    body: Mapping[str, Any] | None = None
    #: the station knows the definition (shipped, registered by staff, approved by a doctor)
    known: bool = False

    def score_answers(
        self, options: Mapping[str, int], band_set: str | None = None, *, values: Mapping[str, float] | None = None
    ) -> Score:
        if self.formula is None:
            return super().score_answers(options, band_set, values=values)
        # checked and summed as any questionnaire (no formula involved), then the total's formula
        plain = Questionnaire.score_answers(replace(self, formula=None), options, band_set, values=values)
        score = replace(plain, min_total=self.min_total, max_total=self.max_total)
        if not score.complete:
            return score
        problem = ""
        total: int | None = None
        if not self.known:
            problem = (
                f"the total formula of {self.id} is not run: its definition ({self.sha[:12]}) is not one "
                "this station knows; a doctor can approve it on this page"
            )
        elif len(self.formula.expression) > EXPRESSION_MAX:
            problem = f"the total formula of {self.id} is longer than {EXPRESSION_MAX} characters: it is not run"
        else:
            total, problem = WORKER.total(self.sha, self.body or {}, options, values or {})
        if total is None:
            return replace(score, complete=False, band=None, problem=problem)
        return replace(score, total=total, band=self.bands_named(band_set).band_for(total))


def guarded(q: Questionnaire, sha: str, body: Mapping[str, Any], known: bool) -> Questionnaire:
    """``q`` as the station scores it: itself without a formula, else a :class:`GuardedQuestionnaire`."""
    if q.formula is None:
        return q
    fields = {name: getattr(q, name) for name in q.__dataclass_fields__}
    return GuardedQuestionnaire(**fields, sha=sha, body=body, known=known)
