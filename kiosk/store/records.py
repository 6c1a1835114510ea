"""What the session database gives back: plain frozen records (see :class:`kiosk.store.database.Store`)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import field
from typing import Any

from basis import record
from kiosk.core.channels import Channel
from kiosk.core.session import Answer, AnsweredBy


@record
class SessionSummary:
    """One line of the session list (``status``: running, finished, abandoned or interrupted)."""

    id: str
    patient_id: str
    started_at: str
    finished_at: str | None
    status: str
    language: str
    answered: int
    not_answered: int
    #: stored by `kiosk replay` (a scripted patient): never offered, marked in every listing and export
    simulated: bool = False
    #: why a session with status "interrupted" stopped ("its kiosk ward3 (process 4242) stopped")
    interrupted_reason: str | None = None
    #: the instrument it ran (a battery's sessions list side by side)
    questionnaire_id: str = ""

    @property
    def label(self) -> str:
        """The status as staff should read it ("interrupted, simulated")."""
        return self.status + (", simulated" if self.simulated else "")


@record
class MetricSample:
    """The QoS metrics after one update, and what fired."""

    t: float
    metrics: Mapping[str, float]
    fired: tuple[str, ...]


@record
class AdaptationRecord:
    """An adaptation switched on or off during a session."""

    t: float
    name: str
    active: bool
    reason: str


@record
class PracticeRecord:
    """How one familiarisation question went: it checks whether the patient can hear, read or choose."""

    question_id: str
    #: "hear", "read" or "select"
    checks: str
    #: "right", "wrong", "not_answered" or "skipped"
    outcome: str
    #: the option chosen (None when not answered or skipped)
    option: int | None
    channel: Channel | None
    t: float
    #: the input's detail for an answer; why it was skipped ("no voice out")
    detail: str = ""


@record
class LogEntry:
    """A line of the session log (start, pause, ignored input, ...)."""

    t: float
    kind: str
    detail: str


@record
class StoredSession:
    """Everything stored about one session."""

    id: str
    patient_id: str
    questionnaire_id: str
    language: str
    answered_by: AnsweredBy
    timing: Mapping[str, float]
    started_at: str
    status: str
    finished_at: str | None
    answers: tuple[Answer, ...]
    not_answered: tuple[str, ...]
    #: the context trace: [{"t":..., "set": {...}, "emit": [...]}] in recording order
    trace: tuple[dict[str, Any], ...]
    metrics: tuple[MetricSample, ...]
    adaptations: tuple[AdaptationRecord, ...]
    log: tuple[LogEntry, ...]
    #: the familiarisation's outcomes, in the order they happened (empty without practice)
    practice: tuple[PracticeRecord, ...] = ()
    #: stored by `kiosk replay` (a scripted patient), not by a patient at the kiosk
    simulated: bool = False
    #: why an "interrupted" session stopped, and when (ISO 8601 UTC)
    interrupted_reason: str | None = None
    interrupted_at: str | None = None
    #: the instrument definition the session ran, as captured (canonical JSON, kiosk.core.questionnaire.definition);
    #: None only for a session read from a source that never had one
    definition: Mapping[str, Any] | None = None
    #: its content address (SHA-256 of the canonical JSON)
    definition_sha256: str = ""
    #: the definition was attached when the database was upgraded, not captured as the session started
    definition_attached_later: bool = False
    #: the identity the session was recorded under: site, kiosk_id and FHIR systems (ExportSite's fields)
    identity: Mapping[str, str] = field(default_factory=dict)
    #: the identity was attached when the database was upgraded, from the configuration then
    identity_attached_later: bool = False
