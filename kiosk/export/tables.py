"""CSV for researchers: :func:`csv_text` (long: rows per practice question, item and total) and
:func:`wide_csv_text` (one row per session).

Ids are written with a kind tag (``S:`` session, ``P:`` patient, ``K:`` kiosk) so that no reader
(pandas, spreadsheets) takes ``00123``, ``8e1234567890``, ``NA`` or ``True`` for a number, a
missing value or a boolean; strip the first two characters to get the id (``kiosk results``
accepts the tagged session id too). ``complete`` and ``simulated`` (a scripted patient's session,
from ``kiosk replay``) are ``true``/``false``. ``bom=True`` starts the
text with a UTF-8 byte-order mark for spreadsheets that need it.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Sequence
from typing import Any

from kiosk.core.answerers import answerer_of
from kiosk.core.questionnaire import Questionnaire, result_words
from kiosk.core.review import Review
from kiosk.core.site import ExportSite
from kiosk.core.staff import number_text
from kiosk.core.visits import visit_of
from kiosk.export.result import (
    TOTAL_LINK,
    Result,
    practice_outcomes,
    questionnaire_version,
    results,
)
from kiosk.store.database import StoredSession

#: the tags that keep ids text in CSV readers; see the module docstring
ID_TAGS = {"session": "S:", "patient": "P:", "kiosk_id": "K:"}


#: The long CSV: ``kind`` tells rows apart: "practice" (one per practice question, first, in the
#: order asked; ``checks`` says what it checks; never scored), "item" (one per questionnaire item, in
#: order: the option after review; ``recorded_option`` the kiosk's own when a clinician changed it,
#: ``corrected_by`` who did) and "total" (last: ``points`` the total, blank when incomplete, with
#: ``label`` saying what it waits for, "No total: not answered: Grooming (N points from K of M
#: items)" or "No total yet: waiting for staff: Weight (kg) (...)"; its band and ``band_set``, the set that
#: gave it: "severe" is 21-60 in Shah's set but 20-35 in the Spanish one). Every row carries the
#: session's columns (ids tagged, see the module docstring); ``review_state`` is
#: :func:`kiosk.core.review.review_state`'s (unreviewed, corrected, signed_off, amended), as in FHIR.
CSV_COLUMNS = [
    "session",
    "patient",
    "started_at",
    "status",
    "language",
    "item",
    "option",
    "label",
    "points",
    "attempt",
    "channel",
    "answered_by",
    "t",
    "band_set",
    "kind",
    "checks",
    "finished_at",
    "questionnaire_version",
    "complete",
    "review_state",
    "kiosk_id",
    "recorded_option",
    "corrected_by",
    "simulated",
    "visit",
    # last, so the columns before keep their places: which instrument (the versions tell edits apart)
    "questionnaire",
    # how the person who answered for the patient is related to them (kiosk.core.answerers)
    "answerer",
    # a number staff entered (an ``input:`` item) as entered, and its UCUM unit
    "value",
    "unit",
    # a result signed off with items unanswered: the doctor's reason (blank otherwise)
    "incomplete_reason",
]


def tag(kind: str, value: str) -> str:
    """An id as the CSV writes it (``S:``, ``P:`` or ``K:`` before it)."""
    return ID_TAGS[kind] + value


def _band(q: Questionnaire, r: Result) -> str:
    return r.score.band.id if r.score.band else ""


def _session_columns(q: Questionnaire, r: Result, site: ExportSite) -> dict[str, object]:
    stored = r.stored
    return {
        "session": tag("session", stored.id),
        "patient": tag("patient", stored.patient_id),
        "kiosk_id": tag("kiosk_id", site.kiosk_id),
        "started_at": stored.started_at,
        "finished_at": stored.finished_at or "",
        "status": stored.status,
        "language": stored.language,
        "answered_by": stored.answered_by.value,
        "questionnaire": q.id,
        "questionnaire_version": questionnaire_version(q),
        "complete": "true" if r.complete else "false",
        "review_state": r.review_state,
        "simulated": "true" if stored.simulated else "false",
        # how the visit began (kiosk.core.visits): "order <id>", "staff", "walk-up"; blank before visits existed
        "visit": visit_of(stored.log) or "",
        "answerer": who.display if (who := answerer_of(stored.log)) is not None else "",
        "incomplete_reason": r.review.incomplete if r.final and not r.complete else "",
    }


def _writer(out: io.StringIO, columns: list[str]) -> csv.DictWriter:
    writer = csv.DictWriter(out, columns, lineterminator="\n", extrasaction="ignore")
    writer.writeheader()
    return writer


def csv_text(
    q: Questionnaire,
    sessions: Sequence[StoredSession],
    reviews: Sequence[Review] | None = None,
    site: ExportSite | None = None,
    *,
    bom: bool = False,
) -> str:
    """The long CSV (see :data:`CSV_COLUMNS`) of sessions with their reviews (None: unreviewed)."""
    return result_rows(q, results(q, sessions, reviews), site, bom=bom)


def result_rows(q: Questionnaire, rs: Sequence[Result], site: ExportSite | None = None, *, bom: bool = False) -> str:
    """The long CSV of :class:`Result`s (what :func:`csv_text` writes, and the station for a
    result it described with the numbers staff entered there)."""
    site = site or ExportSite()
    out = io.StringIO()
    writer = _writer(out, CSV_COLUMNS)
    for r in rs:
        stored = r.stored
        common = _session_columns(q, r, site)
        for record, outcome in zip(stored.practice, practice_outcomes(q, stored)):
            writer.writerow(
                common
                | {
                    "item": record.question_id,
                    "option": record.option or "",
                    "label": outcome.result,
                    "channel": record.channel.value if record.channel else "",
                    "t": f"{record.t:g}",
                    "kind": "practice",
                    "checks": record.checks,
                }
            )
        answers = {a.item_id: a for a in stored.answers}
        corrections = {c.item_id: c for c in r.review.corrections}
        for item in q.items:
            row = common | {"item": item.id, "kind": "item", "answered_by": ""}
            number = r.options.get(item.id)
            if item.entry is not None and item.id in r.values:
                unit = item.entry.unit or ""
                text = number_text(r.values[item.id])
                writer.writerow(
                    row | {"label": f"{text} {unit}".strip(), "value": text, "unit": unit, "answered_by": "staff"}
                )
                continue
            if number is None:
                writer.writerow(row | {"label": "not answered"})
                continue
            row |= {
                "option": number,
                "label": item.option(number).label_in(stored.language),
                "points": item.option(number).points,
            }
            a = answers.get(item.id)
            if a is not None and a.option == number:
                row |= {
                    "attempt": a.attempt,
                    "channel": a.channel.value,
                    "answered_by": a.answered_by.value,
                    "t": f"{a.t:g}",
                }
            elif item.id in corrections:
                row |= {"recorded_option": a.option if a else "", "corrected_by": corrections[item.id].author}
            writer.writerow(row)
        score = r.score
        label = (
            _band(q, r)
            if score.complete
            else f"{result_words(q, score)} ({score.total} points from {len(score.answered)} of {len(q.items)} items)"
        )
        writer.writerow(
            common
            | {
                "item": TOTAL_LINK,
                "label": label,
                "points": score.total if score.complete else "",
                "band_set": score.band_set,
                "kind": "total",
            }
        )
    return ("\ufeff" if bom else "") + out.getvalue()


def wide_columns(q: Questionnaire) -> list[str]:
    """The wide CSV's columns: the session's, then each item's option number and points (for a
    number staff enter, its ``_value`` as entered)."""
    return [
        "session",
        "patient",
        "kiosk_id",
        "started_at",
        "finished_at",
        "status",
        "language",
        "answered_by",
        "questionnaire",
        "questionnaire_version",
        "complete",
        "review_state",
        "signed_by",
        "signed_at",
        "simulated",
        "visit",
        "answerer",
        "total",
        "answered_points",
        "missing",
        "band",
        "band_set",
        "incomplete_reason",
    ] + [
        f"{item.id}_{part}"
        for item in q.items
        for part in (("value",) if item.entry is not None else ("option", "points"))
    ]


def wide_csv_text(
    q: Questionnaire,
    sessions: Sequence[StoredSession],
    reviews: Sequence[Review] | None = None,
    site: ExportSite | None = None,
    *,
    bom: bool = False,
) -> str:
    """One row per session (see :func:`wide_columns`): ``total`` only when complete, the points of
    the answered items apart in ``answered_points`` and the unanswered items in ``missing``."""
    return wide_rows(q, results(q, sessions, reviews), site, bom=bom)


def wide_rows(q: Questionnaire, rs: Sequence[Result], site: ExportSite | None = None, *, bom: bool = False) -> str:
    """The wide CSV of :class:`Result`s (see :func:`wide_csv_text`)."""
    site = site or ExportSite()
    out = io.StringIO()
    writer = _writer(out, wide_columns(q))
    for r in rs:
        row: dict[str, Any] = _session_columns(q, r, site) | {
            "signed_by": r.review.signed_by or "",
            "signed_at": r.review.signed_at or "",
            "total": r.score.total if r.complete else "",
            "answered_points": r.answered_points,
            "missing": " ".join(r.score.missing),
            "band": _band(q, r),
            "band_set": r.score.band_set,
        }
        for item in q.items:
            number = r.options.get(item.id)
            if item.entry is not None and item.id in r.values:
                row[f"{item.id}_value"] = number_text(r.values[item.id])
            elif number is not None:
                row |= {f"{item.id}_option": number, f"{item.id}_points": item.option(number).points}
        writer.writerow(row)
    return ("\ufeff" if bom else "") + out.getvalue()
