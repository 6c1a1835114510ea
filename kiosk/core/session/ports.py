"""What the session needs of the QoS engine and of the store (``qos.Engine``, ``kiosk.store.database.Store``)."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from contextlib import AbstractContextManager
from typing import Any, Protocol


class QosEngine(Protocol):
    """What the session needs of ``qos.Engine``."""

    model: Any

    @property
    def t(self) -> float | None:
        """The engine's time: the last batch's or advance's (None before the first)."""

    def update(self, t: float, set: Mapping[str, Any] | None = None, emit: list[str] | None = None) -> Any:
        """Apply one batch of context changes at ``t``; the result has ``.metrics`` and ``.fired``."""

    def advance(self, t: float) -> list[Any]:
        """Let time pass up to ``t``: the model's timers and time windows due by then run."""

    def next_due(self) -> float | None:
        """When a timer or time window next needs the engine (engine time), or None."""

    def subscribe(self, callback: Callable[[Any], object]) -> Callable[[], None]:
        """Call ``callback(result)`` after every batch the engine runs, its own included."""


class SessionStore(Protocol):
    """What the session needs of ``kiosk.store.database.Store`` (each call commits before returning)."""

    def create_session(
        self,
        *,
        session_id: str,
        patient_id: str,
        questionnaire_id: str,
        language: str,
        answered_by: str,
        started_at: str,
        timing: Mapping[str, float],
        definition: Mapping[str, Any] | None = None,
    ) -> None: ...
    def record_answer(
        self,
        session_id: str,
        *,
        item_id: str,
        option: int,
        points: int,
        attempt: int,
        channel: str,
        answered_by: str,
        t: float,
        at: str,
        detail: str = "",
    ) -> None: ...
    def withdraw_answer(self, session_id: str, *, item_id: str, t: float, at: str, reason: str) -> None: ...
    def record_not_answered(self, session_id: str, *, item_id: str, t: float, at: str) -> None: ...
    def record_practice(
        self,
        session_id: str,
        *,
        question_id: str,
        checks: str,
        outcome: str,
        option: int | None,
        channel: str | None,
        t: float,
        at: str,
        detail: str = "",
    ) -> None: ...
    def record_context(self, session_id: str, *, t: float, set: Mapping[str, Any], emit: list[str]) -> None: ...
    def record_metrics(self, session_id: str, *, t: float, metrics: Mapping[str, float], fired: list[str]) -> None: ...
    def record_adaptation(self, session_id: str, *, t: float, name: str, active: bool, reason: str) -> None: ...
    def record_event(self, session_id: str, *, t: float, kind: str, detail: str = "") -> None: ...
    def finish_session(
        self, session_id: str, *, finished_at: str, total: int, complete: bool, band: str | None
    ) -> None: ...
    def abandon(self, session_id: str) -> None: ...
    def transaction(self) -> AbstractContextManager[None]: ...
