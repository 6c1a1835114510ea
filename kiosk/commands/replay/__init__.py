"""Scripted patients: run the real session core on a simulated clock (`kiosk replay FILE`).

A script (``recordings/patients/*.yaml``, format in ``recordings/patients/README.md``) says what a
simulated patient does: when they start, what they answer on which attempt and through which
channel, and the incidents (pause/resume, call doctor/continue, person lost/back, repeat). The
driver here feeds those inputs to a real :class:`~kiosk.core.session.Session` with a real QoS engine,
lets the session's own time-outs happen on a :class:`~kiosk.core.clock.SimClock`, and checks that what
the script declared really happened under the session's rules -- an answer declared on attempt 1
that would arrive after attempt 1 timed out is an error, not a silently different session.

Times in a script are relative: an action happens ``after`` seconds counted from the later of
the opening of the attempt it names and the previous action of the same question.
"""

from __future__ import annotations

from kiosk.commands.replay.cli import main
from kiosk.commands.replay.driver import ReplayResult, run_script
from kiosk.commands.replay.script import ANY, UNSURE_CONFIDENCE, Question, Script, ScriptError, Step, load_script

__all__ = [
    "ANY",
    "UNSURE_CONFIDENCE",
    "Question",
    "ReplayResult",
    "Script",
    "ScriptError",
    "Step",
    "load_script",
    "main",
    "run_script",
]
