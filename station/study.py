"""A validation study: how well the kiosk's results agree with clinicians' own results of the same
instrument (issue 36, part 8).

A study is what ward staff would name it by: **an instrument and a period** (the days the kiosk's
results were taken, UTC, both included). Its patients are those with a finished kiosk result of
that instrument in the period and a clinician's result entered for it (:mod:`station.reference`);
each patient counts once, with their latest such result, so no patient weighs twice.

What is compared: the kiosk's answers **as the kiosk recorded them** (a staff correction would
measure the staff, not the kiosk) against the clinician's answers; numbers staff entered (weight,
height) are the same on both sides. Per item, weighted kappa with quadratic weights over the
patients both answered; on totals (where both are complete), ICC(2,1) and Bland-Altman, the
difference taken as kiosk − clinician (:mod:`station.agreement` says how, and with which
intervals). Reference: telephone against face-to-face Barthel, ICC 0.89 (Korner-Bitensky & Wood-
Dauphinee 1995).
"""

from __future__ import annotations

import csv
import io
from datetime import date, timedelta

import sqlalchemy as sa
from sqlalchemy.engine import Engine

from basis import record
from kiosk.core.questionnaire import Questionnaire
from kiosk.core.staff import every_entered
from kiosk.export import ExportError
from station import validation
from station.agreement import (
    AgreementError,
    BlandAltman,
    Estimate,
    Icc,
    bland_altman,
    icc_2_1,
    table_of,
    weighted_kappa,
)
from station.db import definitions, reference_results, sessions
from station.definitions import parsed, questionnaire_for
from station.reference import FINISHED, answers_in, asked
from station.sessions import RESULT_KINDS, load_many

#: the longest study period (a bounded read however long the ward has kept results)
MAX_DAYS = 3 * 366


class StudyError(ValueError):
    """A study the station cannot read (message names the field and why)."""


@record
class Pair:
    """One patient's kiosk result and the clinician's, side by side."""

    session_id: str
    patient_id: str
    started_at: str
    kiosk: dict[str, int]
    clinician: dict[str, int]
    #: the totals, where the answers are complete (None otherwise)
    kiosk_total: int | None
    clinician_total: int | None


@record
class ItemAgreement:
    """Weighted kappa of one item over the patients both sides answered."""

    item_id: str
    text: str
    n: int
    kappa: Estimate | None
    #: why there is no kappa ("" when there is one)
    problem: str


@record
class Study:
    instrument: str
    title: str
    first: date
    last: date
    pairs: list[Pair]
    items: list[ItemAgreement]
    #: pairs with both totals complete
    totals: int
    icc: Icc | None
    icc_problem: str
    limits: BlandAltman | None
    limits_problem: str


def period(start: str, end: str, today: date) -> tuple[date, date]:
    """``from`` and ``to`` (YYYY-MM-DD) as dates; the last year up to ``today`` when both are empty."""
    if not start and not end:
        return today - timedelta(days=365), today
    days = []
    for name, value in (("from", start), ("to", end)):
        try:
            days.append(date.fromisoformat(value.strip()))
        except ValueError:
            raise StudyError(f"{name}: {value[:40]!r} is not a day; give it as YYYY-MM-DD") from None
    if days[1] < days[0]:
        raise StudyError(f"to ({days[1]}) is before from ({days[0]})")
    if (days[1] - days[0]).days > MAX_DAYS:
        raise StudyError(f"a study covers at most {MAX_DAYS} days; this one covers {(days[1] - days[0]).days + 1}")
    return days[0], days[1]


def instruments(engine: Engine) -> list[tuple[str, str]]:
    """The instruments some clinician's result was entered for, with the title staff read (the
    page's choice): (id, title), by title."""
    with engine.connect() as connection:
        query = sa.select(reference_results.c.questionnaire_id).distinct()
        ids = list(connection.execute(query).scalars())
        shas = dict(
            connection.execute(
                sa.select(definitions.c.questionnaire_id, sa.func.max(definitions.c.sha256))
                .where(definitions.c.questionnaire_id.in_(ids))
                .group_by(definitions.c.questionnaire_id)
            ).all()
        )
        found = parsed(connection, shas.values())
    titles = {}
    for instrument in ids:
        q = found[shas[instrument]].questionnaire if instrument in shas and shas[instrument] in found else None
        titles[instrument] = (q.title.get("en") or next(iter(q.title.values()), instrument)) if q else instrument
    return sorted(titles.items(), key=lambda pair: pair[1].lower())


def _chosen(engine: Engine, instrument: str, first: date, last: date) -> list[str]:
    """Each patient's latest finished session of ``instrument`` in the period with a clinician's result."""
    with engine.connect() as connection:
        query = (
            sa.select(sessions.c.id, sessions.c.patient_id, sessions.c.started_at)
            .where(
                sessions.c.id.in_(
                    sa.select(reference_results.c.session_id).where(reference_results.c.questionnaire_id == instrument)
                ),
                sessions.c.status == FINISHED,
                sessions.c.started_at >= first.isoformat(),
                sessions.c.started_at < (last + timedelta(days=1)).isoformat(),
            )
            .order_by(sessions.c.started_at)
        )
        latest = {r.patient_id: r.id for r in connection.execute(query)}
    return list(latest.values())


def study(engine: Engine, fallback: Questionnaire, instrument: str, first: date, last: date) -> Study:
    """The study of ``instrument`` over the period: its pairs and their agreement (one read)."""
    ids = _chosen(engine, instrument, first, last)
    with engine.connect() as connection:
        loaded = load_many(connection, ids, RESULT_KINDS)
        trails = validation.trails_in(connection, ids)
        clinician = answers_in(connection, ids)
    pairs, questionnaires = [], []
    for session_id in ids:
        if session_id not in loaded:
            continue
        _, stored = loaded[session_id]
        try:
            q = questionnaire_for(stored, fallback=fallback)
        except ExportError:
            continue
        if q.id != instrument:
            continue
        questionnaires.append(q)
        kiosk = {a.item_id: a.option for a in stored.answers if a.item_id in {i.id for i in q.items}}
        theirs = {item_id: answer.option for item_id, answer in clinician.get(session_id, {}).items()}
        values = every_entered(q, stored.log, trails[session_id])
        pairs.append(
            Pair(
                session_id,
                stored.patient_id or "",
                stored.started_at or "",
                kiosk,
                theirs,
                _total(q, kiosk, values),
                _total(q, {**{i: o for i, o in kiosk.items() if _staff(q, i)}, **theirs}, values),
            )
        )
    shown = questionnaires[0] if questionnaires else (fallback if fallback.id == instrument else None)
    title = (shown.title.get("en") or shown.id) if shown else instrument
    items = [_item(shown, item.id, pairs) for item in asked(shown)] if shown else []
    return Study(instrument, title, first, last, pairs, items, *_totals(pairs))


def _staff(q: Questionnaire, item_id: str) -> bool:
    """An item staff answer at the kiosk too: the same on both sides of the comparison."""
    return q.item(item_id).staff


def _total(q: Questionnaire, options: dict[str, int], values: dict[str, float]) -> int | None:
    try:
        score = q.score_answers(options, values=values)
    except (ValueError, KeyError):
        return None
    return score.total if score.complete else None


def _item(q: Questionnaire, item_id: str, pairs: list[Pair]) -> ItemAgreement:
    item = q.item(item_id)
    both = [(p.kiosk[item_id], p.clinician[item_id]) for p in pairs if item_id in p.kiosk and item_id in p.clinician]
    text = item.text.get("en") or next(iter(item.text.values()), item_id)
    try:
        kappa = weighted_kappa(table_of(both, len(item.options)))
    except AgreementError as exc:
        return ItemAgreement(item_id, text, len(both), None, str(exc))
    return ItemAgreement(item_id, text, len(both), kappa, "")


def _totals(pairs: list[Pair]) -> tuple[int, Icc | None, str, BlandAltman | None, str]:
    both = [
        (p.kiosk_total, p.clinician_total) for p in pairs if p.kiosk_total is not None and p.clinician_total is not None
    ]
    icc: Icc | None = None
    limits: BlandAltman | None = None
    icc_problem = limits_problem = ""
    try:
        icc = icc_2_1([[float(k), float(c)] for k, c in both])
    except AgreementError as exc:
        icc_problem = str(exc)
    try:
        limits = bland_altman([float(k) for k, _ in both], [float(c) for _, c in both])
    except AgreementError as exc:
        limits_problem = str(exc)
    return len(both), icc, icc_problem, limits, limits_problem


CSV_HEADER = ["statistic", "item", "n", "estimate", "ci_low", "ci_high", "method"]
KAPPA_METHOD = "weighted kappa, quadratic weights; 95% CI kappa ± 1.96 SE (Fleiss, Cohen & Everitt 1969)"
ICC_METHOD = "ICC(2,1) two-way random, absolute agreement, single measures; 95% CI McGraw & Wong 1996"
LIMITS_METHOD = "kiosk minus clinician; 95% CI Bland & Altman 1999 (t, n-1 df)"


def _cells(e: Estimate | None) -> list[str]:
    """An estimate and its interval as CSV cells (4 decimals; empty when there is none)."""
    return ["", "", ""] if e is None else [f"{e.value:.4f}", f"{e.low:.4f}", f"{e.high:.4f}"]


def csv_text(found: Study) -> str:
    """The study's statistics as CSV: one row per statistic (items' kappas, the ICC, the bias and
    the two limits), empty cells and the reason in ``method`` where there is none; then one row
    per patient with both totals."""
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\r\n")
    writer.writerow(["instrument", found.instrument, "from", found.first.isoformat(), "to", found.last.isoformat()])
    writer.writerow(CSV_HEADER)
    for item in found.items:
        writer.writerow(
            ["kappa", item.item_id, item.n, *_cells(item.kappa), KAPPA_METHOD if item.kappa else item.problem]
        )
    icc = found.icc.estimate if found.icc else None
    writer.writerow(["icc_2_1", "total", found.totals, *_cells(icc), ICC_METHOD if icc else found.icc_problem])
    for name in ("bias", "lower", "upper"):
        e: Estimate | None = getattr(found.limits, name) if found.limits else None
        writer.writerow(
            [f"bland_altman_{name}", "total", found.totals, *_cells(e), LIMITS_METHOD if e else found.limits_problem]
        )
    writer.writerow([])
    writer.writerow(["session", "patient", "started_at", "kiosk_total", "clinician_total"])
    for p in found.pairs:
        writer.writerow([p.session_id, p.patient_id, p.started_at, p.kiosk_total, p.clinician_total])
    return out.getvalue()
