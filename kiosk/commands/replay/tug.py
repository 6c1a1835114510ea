"""A scripted Timed Up and Go (a script with ``tug:``): its landmark file played through the real
:class:`~kiosk.core.tug.step.TugStep` and QoS engine on a simulated clock.

Each frame is fed at its own time on the clock (the file's clock is the visit's), "Go" at the
script's ``go_t`` (else the file's), the analysis when the frames end, then staff's decision as
the script says. What comes out: the contexts as the engine saw them (the trace), the QoS summary,
the result; stored in the data directory when there is one. Every problem is ``file:line:col``.
"""

from __future__ import annotations

import json
from functools import cache
from importlib import resources
from pathlib import Path
from typing import Any

from basis import record
from fileio.positions import Problem, parse_file, schema_problems
from kiosk.commands.replay.script import ScriptError
from kiosk.core.clock import SimClock
from kiosk.core.tug.landmarks import PoseFileError, PoseSequence, parse_pose_text
from kiosk.core.tug.step import TugResult, TugSettings, TugStep, TugStepError
from qos import Trace

#: the contexts a TUG publishes: the QoS model replayed must declare them (the CLARC model does)
TUG_CONTEXTS = ("PersonIsNextToChair", "PersonIsSeated", "PersonGetsUp", "Scored")


class TugScriptError(ScriptError):
    """A TUG script or its landmark file is malformed; the message names the file and line."""


@record
class TugScript:
    """What the script says: who, the landmarks (read), when Go, staff's items and decision."""

    source: str
    patient: str
    walk_up: bool
    sequence: PoseSequence
    staff: str
    go_t: float
    decision: str
    decided_by: str
    stopwatch_s: float | None
    get_up_go: int | None
    walking_aid: str | None
    settings: TugSettings


@record
class TugReplay:
    """A replayed TUG: the script, the result, the contexts published (trace rows) and the QoS summary."""

    script: TugScript
    result: TugResult
    #: the contexts as published, one row per batch ({t, set}), and as a QoS trace
    contexts: list[dict[str, Any]]
    trace: Trace
    summary: dict[str, Any]
    stored_id: str | None = None

    def to_dict(self) -> dict[str, Any]:
        r = self.result
        return {
            "script": self.script.source,
            "patient": self.script.patient,
            "tug": {
                "decision": r.decision,
                "decided_by": r.decided_by,
                "confirmed_by": r.confirmed_by,
                "total_s": None if r.total_s is None else round(r.total_s, 3),
                "method": r.method,
                "camera_total_s": None if r.camera_total_s is None else round(r.camera_total_s, 3),
                "phases": {p.name: round(p.duration_s, 3) for p in r.phases},
                "reasons": list(r.reasons),
                "person_share": r.person_share,
                "body_cut_off": r.body_cut_off,
                "turn_seen": r.turn_seen,
                "get_up_go": r.get_up_go,
                "walking_aid": r.walking_aid,
                "wording": r.wording(),
            },
            "contexts": [{"t": round(e["t"], 3), "set": e["set"]} for e in self.contexts],
            "metrics": {name: m["last"] for name, m in self.summary.get("metrics", {}).items()},
            "stored": self.stored_id,
        }

    def human(self) -> str:
        contexts = ", ".join(f"{k}={v} at {e['t']:.2f}" for e in self.contexts for k, v in e["set"].items())
        return f"{self.script.source}: patient {self.script.patient}: {self.result.wording()}\n  contexts: {contexts}"


@cache
def _schema() -> dict[str, Any]:
    return json.loads(resources.files("kiosk.commands").joinpath("tug.schema.json").read_text(encoding="utf-8"))


def is_tug_script(path: str | Path) -> bool:
    """Whether the YAML file at ``path`` is a TUG script (a mapping with ``tug:``); False when unreadable."""
    data, _, _ = parse_file(path)
    return isinstance(data, dict) and "tug" in data


def load_tug_script(path: str | Path, site: TugSettings | None = None) -> TugScript:
    """Read and check a TUG script and its landmark file; :class:`TugScriptError` for the first problem.
    ``site``: the configuration's settings, which the script's ``threshold_s``/``keep_landmarks`` override."""
    site = site or TugSettings()
    name = str(path)
    data, positions, problems = parse_file(path)
    if positions is None or not isinstance(data, dict):
        first = problems[0] if problems else Problem(name, 1, 1, "a script is a mapping (patient:, tug:)")
        raise TugScriptError(str(first))

    def add(p: tuple[Any, ...], message: str, *, key: bool = False) -> None:
        line, col = positions.of(p, key=key)
        problems.append(Problem(name, line, col, message))

    schema_problems(data, _schema(), positions, add)
    if problems:
        raise TugScriptError(str(min(problems, key=lambda p: (p.line, p.column))))
    tug = data["tug"]
    if (tug["decision"] == "stopwatch") != ("stopwatch_s" in tug):
        add(("tug", "decision"), "a stopwatch time (stopwatch_s) goes with decision: stopwatch, and only with it")
        raise TugScriptError(str(problems[0]))
    file = Path(name).parent / tug["landmarks"]
    try:
        sequence = parse_pose_text(file.read_text(encoding="utf-8"), str(file))
    except (OSError, UnicodeDecodeError) as exc:
        line, col = positions.of(("tug", "landmarks"))
        raise TugScriptError(f"{name}:{line}:{col}: the landmark file {file} cannot be read ({exc})") from None
    except PoseFileError as exc:
        raise TugScriptError(str(exc)) from None
    go_t = tug.get("go_t", sequence.go_t)
    if go_t is None:
        line, col = positions.of(("tug",), key=True)
        raise TugScriptError(f"{name}:{line}:{col}: the landmark file has no go_t: say when the kiosk says Go (go_t:)")
    return TugScript(
        source=name,
        patient=data["patient"],
        walk_up=bool(data.get("walk_up", False)),
        sequence=sequence,
        staff=tug["staff"],
        go_t=float(go_t),
        decision=tug["decision"],
        decided_by=tug["decided_by"],
        stopwatch_s=tug.get("stopwatch_s"),
        get_up_go=tug.get("get_up_go"),
        walking_aid=tug.get("walking_aid"),
        settings=TugSettings(
            threshold_s=tug.get("threshold_s", site.threshold_s),
            keep_landmarks=tug.get("keep_landmarks", site.keep_landmarks),
        ),
    )


def run_tug_script(
    script: TugScript, *, store: Any = None, model: str = "clarc", visit: str | None = None
) -> TugReplay:
    """Play ``script`` through a :class:`TugStep` and the QoS engine of ``model`` on a simulated clock
    (store the result in ``store`` when given, as a visit that began as ``visit`` says: an order's
    ``order <id>``, else staff's). TugScriptError when the step refuses (a walk-up visit)."""
    from kiosk.core.qos_model import load_kiosk_model
    from qos import Engine, replay

    loaded = load_kiosk_model(model)
    if missing := [name for name in TUG_CONTEXTS if name not in loaded.contexts]:
        raise TugScriptError(
            f"{script.source}:1:1: the QoS model {model} has no context {missing[0]}: replay with clarc"
        )
    engine, clock, trace = Engine(loaded), SimClock(), []

    def publish(t: float, values: Any) -> None:
        engine.update(t, set=dict(values))
        trace.append({"t": t, "set": dict(values)})

    sequence = script.sequence
    try:
        step = TugStep(clock, publish, walk_up=script.walk_up, settings=script.settings, fps=sequence.fps)
        clock.set(sequence.frames[0].t)
        step.confirm_staff(script.staff)
        for frame in sequence.frames:
            if step.go_t is None and frame.t >= script.go_t:
                clock.set(script.go_t)
                step.go()
            clock.set(frame.t)
            step.frame(frame.t, frame.landmarks, sequence.width, sequence.height)
        if step.go_t is None:
            raise TugStepError(f"go_t {script.go_t:g} is after the last frame ({sequence.frames[-1].t:g})")
        step.finish()
        step.rate(script.get_up_go, script.walking_aid)
        clock.advance(1.0)  # staff read the result before deciding
        result = step.decide(script.decision, script.decided_by, script.stopwatch_s)
    except TugStepError as exc:
        raise TugScriptError(f"{script.source}:1:1: {exc}") from None
    events = Trace.from_events(model, trace, description=f"Timed Up and Go of {script.source}")
    summary = replay(events, model=loaded) if trace else {}
    stored = store.tug.record(script.patient, result, visit=visit or "staff") if store is not None else None
    return TugReplay(script, result, trace, events, summary, stored)
