"""What every export of a stored session states: a :class:`Result` is the session's answers after
a clinician's corrections (:class:`kiosk.core.review.Review`), their score recomputed from the option
numbers (a stored total or stored points are never trusted), whether it is complete and whether a
clinician signed it off. Who exports (:class:`ExportSite`: site, kiosk, FHIR systems) is
:mod:`kiosk.core.site`'s, named here too."""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from dataclasses import field
from pathlib import Path
from typing import Any

from basis import record
from basis.errors import KioskError
from fileio.bounded import write_error, write_private  # the one owner-only writer; exports use it from here too
from kiosk.core.questionnaire import Questionnaire, Score
from kiosk.core.review import Review, ReviewState, review_state
from kiosk.core.staff import entered_values
from kiosk.store.database import PracticeRecord, StoredSession

TOTAL_LINK = "total"


class ExportError(KioskError, ValueError):
    """A stored session does not fit the questionnaire (unknown item, option or points), a
    review does not fit the session, or an export cannot be written."""


def questionnaire_version(q: Questionnaire) -> str:
    """The questionnaire's version as exports state it: the file's ``version`` and the start of
    its content hash (``1.0-3f2a9c1b7e4d``), so that any edit of the file gives a new version."""
    return f"{q.version}-{q.digest[:12]}" if q.version else q.digest[:12]


def _score(q: Questionnaire, session_id: str, options: Mapping[str, int], values: Mapping[str, float]) -> Score:
    """The instrument's own scoring (sum or formula, subscales) of option numbers and entered values."""
    try:
        return q.score_answers(options, values=values)
    except ValueError as exc:
        raise ExportError(f"session {session_id}: {exc}") from None


def rescore(q: Questionnaire, stored: StoredSession, values: Mapping[str, float] | None = None) -> Score:
    """The score recomputed from the stored option numbers (and the numbers staff entered for
    ``input`` items, ``values``; None: those in the session's log); ExportError if they do not fit."""
    options = {}
    for answer in stored.answers:
        try:
            option = q.item(answer.item_id).option(answer.option)
        except KeyError as exc:
            raise ExportError(f"session {stored.id}: {exc.args[0]}") from None
        if option.points != answer.points:
            raise ExportError(
                f"session {stored.id}: {answer.item_id} option {answer.option} is worth "
                f"{option.points} points in {q.id}, but {answer.points} were stored"
            )
        options[answer.item_id] = answer.option
    return _score(q, stored.id, options, values if values is not None else entered_values(q, stored.log))


@record
class Result:
    """A stored session as exports state it: answers after review, their score, where it stands."""

    stored: StoredSession
    review: Review
    #: item id -> option number, after the clinician's corrections
    options: dict[str, int]
    #: the score of ``options`` (complete, total and band only when every item has an answer)
    score: Score
    #: item id -> the number staff entered, for the instrument's ``input`` items
    values: Mapping[str, float] = field(default_factory=dict)

    @property
    def awaiting_staff(self) -> tuple[str, ...]:
        """Staff items still unanswered: the result is incomplete until staff answer them."""
        return self.score.awaiting_staff

    @property
    def pending(self) -> str:
        """Why the result is incomplete, in a clinician's words ('' when complete)."""
        if self.complete:
            return ""
        staff = self.awaiting_staff
        patient = [i for i in self.score.missing if i not in staff]
        parts = [f"not answered: {', '.join(patient)}"] if patient else []
        if staff:
            parts.append(f"incomplete until staff answer {', '.join(staff)}")
        return "; ".join(parts)

    @property
    def complete(self) -> bool:
        """Every item answered (by the patient, or filled by a clinician)."""
        return self.score.complete

    @property
    def final(self) -> bool:
        """Signed off by a clinician (with or without corrections)."""
        return self.review.final

    @property
    def state(self) -> ReviewState:
        """Where the result stands (:func:`kiosk.core.review.review_state`: the one answer the CSV,
        the FHIR response and Observation, and the station's pages all give)."""
        return review_state(self.review, {a.item_id: a.option for a in self.stored.answers})

    @property
    def amended(self) -> bool:
        """Signed off with answers other than the kiosk recorded."""
        return self.state is ReviewState.AMENDED

    @property
    def changed(self) -> bool:
        """Answers other than the kiosk recorded, signed off or not."""
        return self.options != {a.item_id: a.option for a in self.stored.answers}

    @property
    def review_state(self) -> str:
        """``unreviewed``, ``corrected``, ``signed_off`` or ``amended`` (see :attr:`state`)."""
        return self.state.value

    def recorded(self, item_id: str) -> int | None:
        """The option the kiosk stored for an item (None: not answered at the kiosk)."""
        return next((a.option for a in self.stored.answers if a.item_id == item_id), None)

    @property
    def incomplete_words(self) -> str:
        """A result signed off incomplete, in words: what it lacks and the doctor's reason."""
        reason = self.review.incomplete or "no reason recorded (signed off before a reason was required)"
        return f"signed off incomplete ({self.pending}): {reason}"

    @property
    def answered_points(self) -> int:
        """Points of the answered items: the total only when complete."""
        return self.score.total


def result(
    q: Questionnaire, stored: StoredSession, review: Review | None = None, values: Mapping[str, float] | None = None
) -> Result:
    """A stored session with its review applied (ExportError if either does not fit ``q``), scored
    as the instrument says (sum or formula, subscales); ``values`` are the numbers staff entered
    for its ``input`` items (None: those in the session's log, :mod:`kiosk.core.staff`)."""
    review = review or Review.unreviewed()
    if stored.questionnaire_id != q.id:
        raise ExportError(
            f"session {stored.id} was answered on questionnaire {stored.questionnaire_id!r}, "
            f"not on {q.id!r} ({q.source}): export it with that questionnaire"
        )
    values = dict(values if values is not None else entered_values(q, stored.log))  # staff's numbers, from the log
    rescore(q, stored, values)  # the stored answers must fit the questionnaire before anything is said about them
    options = review.options({a.item_id: a.option for a in stored.answers})
    for item_id, number in options.items():
        try:
            q.item(item_id).option(number)
        except KeyError as exc:
            raise ExportError(f"session {stored.id}: review: {exc.args[0]}") from None
    return Result(stored, review, options, _score(q, stored.id, options, values), values)


def results(
    q: Questionnaire, sessions: Sequence[StoredSession], reviews: Sequence[Review | None] | None = None
) -> list[Result]:
    """Each session with its review (``reviews`` in the same order; None: all unreviewed)."""
    if reviews is not None and len(reviews) != len(sessions):
        raise ExportError(f"{len(sessions)} sessions but {len(reviews)} reviews: give one review per session")
    return [result(q, stored, review) for stored, review in zip(sessions, reviews or [None] * len(sessions))]


#: what each kind of practice question checks, as a clinician reads it
PRACTICE_CHECKS = {"hear": "hearing", "read": "reading", "select": "selecting"}


@record
class PracticeOutcome:
    """How one practice question went, in a clinician's words: "hearing: wrong (chose Chair)"."""

    #: what it checks: "hearing", "reading" or "selecting"
    what: str
    #: "right", "wrong", "not answered" or "skipped"
    outcome: str
    #: the option chosen for a wrong answer ("chose Chair"), why it was skipped ("no voice out"), or ""
    detail: str = ""

    @property
    def result(self) -> str:
        """The outcome with its detail: "wrong (chose Chair)", "skipped (no voice out)", "right"."""
        return f"{self.outcome} ({self.detail})" if self.detail else self.outcome

    def __str__(self) -> str:
        return f"{self.what}: {self.result}"


def practice_outcome(q: Questionnaire, record: PracticeRecord, language: str) -> PracticeOutcome:
    """A stored practice record in a clinician's words (a wrong answer names the option chosen)."""
    what = PRACTICE_CHECKS.get(record.checks, record.checks)
    if record.outcome == "wrong":
        question = next((p for p in q.familiarisation if p.id == record.question_id), None)
        chosen = (
            question.option(record.option).label_in(language)
            if question is not None and record.option is not None and 1 <= record.option <= len(question.options)
            else f"option {record.option}"
        )
        return PracticeOutcome(what, "wrong", f"chose {chosen}")
    if record.outcome == "skipped":
        return PracticeOutcome(what, "skipped", record.detail)
    return PracticeOutcome(what, record.outcome.replace("_", " "))


def practice_outcomes(q: Questionnaire, stored: StoredSession) -> list[PracticeOutcome]:
    """The session's practice questions in the order they happened (empty without familiarisation)."""
    return [practice_outcome(q, record, stored.language) for record in stored.practice]


def write_export(path: str | Path, text: str) -> None:
    """Write an export owner-only; ExportError ``cannot write PATH: reason`` when the path is unusable."""
    try:
        write_private(path, text)
    except OSError as exc:
        raise ExportError(write_error(path, exc)) from None


def write_json(path: str | Path, resource: dict[str, Any]) -> None:
    """Write a FHIR resource as JSON, owner-only (ExportError when the path is unusable)."""
    write_export(path, json.dumps(resource, indent=2, ensure_ascii=False) + "\n")
