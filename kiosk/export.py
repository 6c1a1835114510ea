"""What every export of a stored session says, and the CSV exports (FHIR is in :mod:`kiosk.fhir`).

A :class:`Result` is a stored session as an export states it: the answers after a clinician's
corrections (:class:`kiosk.review.Review`), the score recomputed from them (a stored total or
stored points are never trusted), whether it is complete and whether a clinician signed it off.
An incomplete result has no total: exports show the points of the answered items apart, never
as the total.

CSV for researchers (:func:`csv_text` long, one row per practice question, item and total;
:func:`wide_csv_text`, one row per session). Ids are written with a kind tag (``S:`` session,
``P:`` patient, ``K:`` kiosk) so that no reader (pandas, spreadsheets) takes ``00123``,
``8e1234567890``, ``NA`` or ``True`` for a number, a missing value or a boolean; strip the
first two characters to get the id (``kiosk results`` accepts the tagged session id too).
``bom=True`` starts the file with a UTF-8 byte-order mark for spreadsheets that need it.
"""

from __future__ import annotations

import csv
import io
import json
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from kiosk.config import Config, default_kiosk_id
from kiosk.questionnaire import Questionnaire, Score
from kiosk.review import Review, ReviewState
from kiosk.storage import PracticeRecord, StoredSession
from qos.files import write_error, write_private  # the one owner-only writer; exports use it from here too

TOTAL_LINK = "total"
#: the tags that keep ids text in CSV readers; see the module docstring
ID_TAGS = {"session": "S:", "patient": "P:", "kiosk_id": "K:"}


class ExportError(ValueError):
    """A stored session does not fit the questionnaire (unknown item, option or points), a
    review does not fit the session, or an export cannot be written."""


@dataclass(frozen=True)
class ExportSite:
    """Who exports: the site and the kiosk, and the FHIR systems and URLs the site owns.

    The defaults are URNs under ``urn:barthel-kiosk:`` with the site code in them; a hospital
    sets its own (``site``, ``kiosk_id`` and ``fhir:`` in the kiosk's config,
    :func:`site_from_config`).
    """

    site: str = "local"
    kiosk_id: str = field(default_factory=default_kiosk_id)
    #: the system of the patients' pseudonymous ids
    patient_system: str = ""
    #: the canonical URL of the questionnaire; one Questionnaire per language is ``URL-LANG``
    questionnaire_url: str = ""
    #: the system of result identifiers: ``SITE/KIOSK/SESSION`` (+ ``/total`` for the Observation)
    identifier_system: str = ""
    #: the system of kiosk ids (the FHIR Device's identifier)
    device_system: str = ""

    def __post_init__(self) -> None:
        defaults = {"patient_system": f"urn:barthel-kiosk:{self.site}:patient",
                    "questionnaire_url": f"urn:barthel-kiosk:{self.site}:questionnaire:barthel",
                    "identifier_system": "urn:barthel-kiosk:result",
                    "device_system": f"urn:barthel-kiosk:{self.site}:kiosk"}
        for name, value in defaults.items():
            if not getattr(self, name):
                object.__setattr__(self, name, value)

    def result_id(self, session_id: str) -> str:
        """The stable business identifier of a session's result: site + kiosk + session."""
        return f"{self.site}/{self.kiosk_id}/{session_id}"


def site_from_config(config: Config) -> ExportSite:
    """The export site of a :class:`kiosk.config.Config`."""
    return ExportSite(site=config.site, kiosk_id=config.kiosk_id, **dict(config.fhir))


def questionnaire_version(q: Questionnaire) -> str:
    """The questionnaire's version as exports state it: the file's ``version`` and the start of
    its content hash (``1.0-3f2a9c1b7e4d``), so that any edit of the file gives a new version."""
    return f"{q.version}-{q.digest[:12]}" if q.version else q.digest[:12]


def rescore(q: Questionnaire, stored: StoredSession) -> Score:
    """The score recomputed from the stored option numbers (ExportError if they do not fit)."""
    points = {}
    for answer in stored.answers:
        try:
            option = q.item(answer.item_id).option(answer.option)
        except KeyError as exc:
            raise ExportError(f"session {stored.id}: {exc.args[0]}") from None
        if option.points != answer.points:
            raise ExportError(f"session {stored.id}: {answer.item_id} option {answer.option} is worth "
                              f"{option.points} points in {q.id}, but {answer.points} were stored")
        assert option.points is not None
        points[answer.item_id] = option.points
    return q.score(points)


@dataclass(frozen=True)
class Result:
    """A stored session as exports state it: answers after review, their score, where it stands."""

    stored: StoredSession
    review: Review
    #: item id -> option number, after the clinician's corrections
    options: dict[str, int]
    #: the score of ``options`` (complete, total and band only when every item has an answer)
    score: Score

    @property
    def complete(self) -> bool:
        """Every item answered (by the patient, or filled by a clinician)."""
        return self.score.complete

    @property
    def final(self) -> bool:
        """Signed off by a clinician (with or without corrections)."""
        return self.review.final

    @property
    def review_state(self) -> str:
        """``unreviewed``, ``signed_off`` or ``amended``."""
        return ReviewState(self.review.state).value

    def recorded(self, item_id: str) -> int | None:
        """The option the kiosk stored for an item (None: not answered at the kiosk)."""
        return next((a.option for a in self.stored.answers if a.item_id == item_id), None)

    @property
    def answered_points(self) -> int:
        """Points of the answered items: the total only when complete."""
        return self.score.total


def result(q: Questionnaire, stored: StoredSession, review: Review | None = None) -> Result:
    """A stored session with its review applied (ExportError if either does not fit ``q``)."""
    review = review or Review.unreviewed()
    rescore(q, stored)  # the stored answers must fit the questionnaire before anything is said about them
    options = review.options({a.item_id: a.option for a in stored.answers})
    points = {}
    for item_id, number in options.items():
        try:
            option = q.item(item_id).option(number)
        except KeyError as exc:
            raise ExportError(f"session {stored.id}: review: {exc.args[0]}") from None
        assert option.points is not None
        points[item_id] = option.points
    return Result(stored, review, options, q.score(points))


#: what each kind of practice question checks, as a clinician reads it
PRACTICE_CHECKS = {"hear": "hearing", "read": "reading", "select": "selecting"}


@dataclass(frozen=True)
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
        chosen = (question.option(record.option).label_in(language)
                  if question is not None and record.option is not None
                  and 1 <= record.option <= len(question.options) else f"option {record.option}")
        return PracticeOutcome(what, "wrong", f"chose {chosen}")
    if record.outcome == "skipped":
        return PracticeOutcome(what, "skipped", record.detail)
    return PracticeOutcome(what, record.outcome.replace("_", " "))


def practice_outcomes(q: Questionnaire, stored: StoredSession) -> list[PracticeOutcome]:
    """The session's practice questions in the order they happened (empty without familiarisation)."""
    return [practice_outcome(q, record, stored.language) for record in stored.practice]


#: The long CSV: ``kind`` tells rows apart: "practice" (one per practice question, first, in the
#: order asked; ``checks`` says what it checks; never scored), "item" (one per questionnaire item, in
#: order: the option after review; ``recorded_option`` the kiosk's own when a clinician changed it,
#: ``corrected_by`` who did) and "total" (last: ``points`` the total, blank when incomplete, with
#: ``label`` "incomplete (N points from K of M items)"; its band and ``band_set``, the set that
#: gave it: "severe" is 21-60 in Shah's set but 20-35 in the Spanish one). Every row carries the
#: session's columns (ids tagged, see the module docstring).
CSV_COLUMNS = ["session", "patient", "started_at", "status", "language", "item", "option", "label", "points",
               "attempt", "channel", "answered_by", "t", "band_set", "kind", "checks", "finished_at",
               "questionnaire_version", "complete", "review_state", "kiosk_id", "recorded_option", "corrected_by"]


def tag(kind: str, value: str) -> str:
    """An id as the CSV writes it (``S:``, ``P:`` or ``K:`` before it)."""
    return ID_TAGS[kind] + value


def _band(q: Questionnaire, r: Result) -> str:
    return r.score.band.id if r.score.band else ""


def _session_columns(q: Questionnaire, r: Result, site: ExportSite) -> dict[str, str]:
    stored = r.stored
    return {"session": tag("session", stored.id), "patient": tag("patient", stored.patient_id),
            "kiosk_id": tag("kiosk_id", site.kiosk_id), "started_at": stored.started_at,
            "finished_at": stored.finished_at or "", "status": stored.status, "language": stored.language,
            "answered_by": stored.answered_by.value, "questionnaire": q.id,
            "questionnaire_version": questionnaire_version(q), "complete": "true" if r.complete else "false",
            "review_state": r.review_state}


def _writer(out: io.StringIO, columns: list[str]) -> csv.DictWriter:
    writer = csv.DictWriter(out, columns, lineterminator="\n", extrasaction="ignore")
    writer.writeheader()
    return writer


def csv_text(q: Questionnaire, sessions: Iterable[StoredSession | Result], site: ExportSite | None = None,
             *, bom: bool = False) -> str:
    """The long CSV (see :data:`CSV_COLUMNS`); sessions are stored sessions (unreviewed) or results."""
    site = site or ExportSite()
    out = io.StringIO()
    writer = _writer(out, CSV_COLUMNS)
    for r in (s if isinstance(s, Result) else result(q, s) for s in sessions):
        stored = r.stored
        common = _session_columns(q, r, site)
        for record, outcome in zip(stored.practice, practice_outcomes(q, stored)):
            writer.writerow(common | {"item": record.question_id, "option": record.option or "", "label": outcome.result,
                                      "channel": record.channel.value if record.channel else "",
                                      "t": f"{record.t:g}", "kind": "practice", "checks": record.checks})
        answers = {a.item_id: a for a in stored.answers}
        corrections = {c.item_id: c for c in r.review.corrections}
        for item in q.items:
            row = common | {"item": item.id, "kind": "item", "answered_by": ""}
            number = r.options.get(item.id)
            if number is None:
                writer.writerow(row | {"label": "not answered"})
                continue
            row |= {"option": number, "label": item.option(number).label_in(stored.language),
                    "points": item.option(number).points}
            a = answers.get(item.id)
            if a is not None and a.option == number:
                row |= {"attempt": a.attempt, "channel": a.channel.value, "answered_by": a.answered_by.value,
                        "t": f"{a.t:g}"}
            elif item.id in corrections:
                row |= {"recorded_option": a.option if a else "", "corrected_by": corrections[item.id].author}
            writer.writerow(row)
        score = r.score
        label = _band(q, r) if score.complete else (
            f"incomplete ({score.total} points from {len(score.answered)} of {len(q.items)} items)")
        writer.writerow(common | {"item": TOTAL_LINK, "label": label, "points": score.total if score.complete else "",
                                  "band_set": score.band_set, "kind": "total"})
    return ("\ufeff" if bom else "") + out.getvalue()


def wide_columns(q: Questionnaire) -> list[str]:
    """The wide CSV's columns: the session's, then each item's option number and points."""
    return ["session", "patient", "kiosk_id", "started_at", "finished_at", "status", "language", "answered_by",
            "questionnaire", "questionnaire_version", "complete", "review_state", "signed_by", "signed_at",
            "total", "answered_points", "missing", "band", "band_set"] + [
        f"{item.id}_{part}" for item in q.items for part in ("option", "points")]


def wide_csv_text(q: Questionnaire, sessions: Iterable[StoredSession | Result], site: ExportSite | None = None,
                  *, bom: bool = False) -> str:
    """One row per session (see :func:`wide_columns`): ``total`` only when complete, the points of
    the answered items apart in ``answered_points`` and the unanswered items in ``missing``."""
    site = site or ExportSite()
    out = io.StringIO()
    writer = _writer(out, wide_columns(q))
    for r in (s if isinstance(s, Result) else result(q, s) for s in sessions):
        row: dict[str, Any] = _session_columns(q, r, site) | {
            "signed_by": r.review.signed_by or "", "signed_at": r.review.signed_at or "",
            "total": r.score.total if r.complete else "", "answered_points": r.answered_points,
            "missing": " ".join(r.score.missing), "band": _band(q, r), "band_set": r.score.band_set}
        for item in q.items:
            number = r.options.get(item.id)
            if number is not None:
                row |= {f"{item.id}_option": number, f"{item.id}_points": item.option(number).points}
        writer.writerow(row)
    return ("\ufeff" if bom else "") + out.getvalue()

def write_export(path: str | Path, text: str) -> None:
    """Write an export owner-only; ExportError ``cannot write PATH: reason`` when the path is unusable."""
    try:
        write_private(path, text)
    except OSError as exc:
        raise ExportError(write_error(path, exc)) from None


def write_json(path: str | Path, resource: dict[str, Any]) -> None:
    """Write a FHIR resource as JSON, owner-only (ExportError when the path is unusable)."""
    write_export(path, json.dumps(resource, indent=2, ensure_ascii=False) + "\n")
