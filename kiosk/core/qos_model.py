"""The QoS model a kiosk runs: the bundled CLARC model, or a QoS engineer's own (``qos_model:`` in
the configuration).

A model the kiosk runs must take every context batch a session publishes (the CLARC context
table, see ``kiosk.core.session``): a model that lacks one of those contexts, or declares it with
another type or without one of the literals the kiosk sets, would fail in the middle of a
patient's test, so it is refused at start with the model file's name and what is missing.
Models that declare ``QuestionAsked`` (an eventtype) also get it when a question is asked.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

from kiosk.core.session.publishing import QUESTION_ASKED
from qos import ContextError, Model, ModelError, bundled_models, load_model
from qos.batches import check_batch

#: the model a kiosk runs unless configured otherwise
DEFAULT_MODEL = "clarc"

#: every context value a session publishes, as (set, emit) batches to check a model against
KIOSK_BATCHES: tuple[tuple[Mapping[str, object], Sequence[str]], ...] = (
    *(({"PersonDetected": value}, []) for value in (True, False)),
    *(({"TestState": state}, []) for state in ("STARTED", "PAUSED", "RESTARTED", "REPEATING", "FINISHED")),
    *(({name: value}, []) for name in ("FirstAttemptAnswered", "SecondAttemptAnswered") for value in (True, False)),
    *(({"UserInteraction": literal}, []) for literal in ("VOICE_RECOGNITION", "TOUCH_SCREEN", "REMOTE_CONTROL")),
    ({}, ["CallingDoctor"]),
)


def resolve_model(value: str, folder: Path | None = None) -> str:
    """What ``qos_model:`` names: a bundled model's name (``clarc``, ``kiosk_pace``; also written
    ``kiosk_pace.roqme`` when there is no such file), else a .roqme file's absolute path, relative
    paths counted from ``folder`` (the configuration file's). A bare name is returned as it is:
    the caller says when no bundled model has it."""
    if "/" not in value and not value.endswith(".roqme"):
        return value
    path = Path(value).expanduser()
    if not path.is_absolute() and folder is not None:
        path = folder / path
    if "/" not in value and not path.exists() and value[: -len(".roqme")] in bundled_models():
        return value[: -len(".roqme")]
    return str(path)


def load_kiosk_model(name_or_path: str | Path = DEFAULT_MODEL) -> Model:
    """Load the model and check that it takes everything a session publishes.

    Raises :class:`~qos.ModelError`: ``file:line:col: problem`` for a malformed model, and the
    model file and the missing context for one the kiosk cannot run.
    """
    model = load_model(name_or_path)
    # QuestionAsked is optional, but a model declaring it must take it as the session emits it
    optional: list[tuple[Mapping[str, object], Sequence[str]]] = (
        [({}, [QUESTION_ASKED])] if QUESTION_ASKED in model.contexts else []
    )
    for values, emitted in (*KIOSK_BATCHES, *optional):
        try:
            check_batch(model, values, emitted)
        except ContextError as exc:
            what = ", ".join(f"{name} = {value}" for name, value in values.items()) or f"the event {emitted[0]}"
            raise ModelError(
                f"{model.source}:1:1: the kiosk cannot run this model: it publishes {what}, "
                f'and {exc} (import "clarc.roqme" to declare the kiosk\'s contexts)'
            ) from None
    return model
