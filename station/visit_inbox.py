"""The inbox of visits and a patient's visits (issue 36): one row per visit, with each of its
instruments' total, band and review state.

A visit is the sessions of one order (a battery: one session per instrument); a session no order
started is a visit of its own (:mod:`station.printing` groups the print view the same way). The
inbox pages by keyset over each visit's *anchor*, its newest finished session in the filter's
review states: one index range a page, whatever the history, and no visit is listed twice or lost
when its instruments fall on either side of a page's end.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any
from urllib.parse import quote

import sqlalchemy as sa
from sqlalchemy.engine import Engine

from basis import record
from kiosk.core.questionnaire import Questionnaire
from station.db import sessions, visits
from station.results import Result, results_of

#: the review states of a result waiting for a doctor's sign-off
WAITING = ("unreviewed", "corrected")
#: inbox filters: which review states each shows
INBOX_STATES: dict[str, tuple[str, ...] | None] = {"waiting": WAITING, "signed": ("signed_off", "amended"), "all": None}
INBOX_LIMIT = 50


def visit_key(session_id: str, order_id: str | None) -> str:
    """The visit a session belongs to: its order, else the session itself."""
    return order_id or session_id


def visit_href(key: str) -> str:
    """The visit's page (``key``: an order id, or any session id of the visit)."""
    return f"/visits/{quote(key, safe='')}"


@record
class VisitRow:
    """One visit as a row of a list: its instruments' results, in the order they began."""

    key: str
    results: list[Result]

    @property
    def first(self) -> Result:
        return self.results[0]

    @property
    def href(self) -> str:
        return visit_href(self.key)

    @property
    def started_at(self) -> str:
        return min((r.started_at or "" for r in self.results), default="")

    @property
    def finished_at(self) -> str:
        return max((r.finished_at or "" for r in self.results), default="")

    @property
    def waiting(self) -> int:
        """How many of its results wait for a doctor's sign-off."""
        return sum(r.status == "finished" and r.review in WAITING for r in self.results)


def group(found: Iterable[Result]) -> list[VisitRow]:
    """Results grouped by visit, in the order each visit is first met; each visit's results in
    the order they began."""
    grouped: dict[str, list[Result]] = {}
    for result in found:
        grouped.setdefault(visit_key(result.session_id, result.order_id), []).append(result)
    return [
        VisitRow(key, sorted(members, key=lambda r: (r.started_at or "", r.session_id)))
        for key, members in grouped.items()
    ]


@record
class Page:
    """One page of the inbox, newest visit first, and where the next (older) one starts."""

    visits: list[VisitRow]
    #: the ``after`` of the next page ("" when this is the last)
    after: str = ""

    @property
    def results(self) -> list[Result]:
        """Every result of the page's visits, visit by visit."""
        return [r for v in self.visits for r in v.results]


def _listed(table: Any, state: str, kiosk_id: str | None) -> list[Any]:
    """The conditions a session of ``table`` meets to anchor a visit in the inbox."""
    where = [table.c.status == "finished"]
    if kiosk_id:
        where.append(table.c.kiosk_id == kiosk_id)
    if state == "waiting":
        where.append(table.c.signed_at.is_(None))
    elif state == "signed":
        where.append(table.c.signed_at.is_not(None))
    return where


def anchor_query(state: str, kiosk_id: str | None, after: str, limit: int) -> Any:
    """The inbox page's anchors: each listed visit's newest session in the filter, newest first."""
    later, sibling, mine = sessions.alias("later"), visits.alias("sibling"), visits.alias("mine")
    # one table scanned in the inbox's order (the index on status, finish time and id), each row
    # kept unless a later session of its order is in the filter: a few primary-key and order-id
    # lookups a row, and the scan stops at the page's end
    newer_of_its_order = sa.exists(
        sa.select(sa.literal(1))
        .select_from(
            mine.join(sibling, sibling.c.order_id == mine.c.order_id).join(later, later.c.id == sibling.c.session_id)
        )
        .where(
            mine.c.session_id == sessions.c.id,
            *_listed(later, state, kiosk_id),
            sa.tuple_(later.c.finished_at, later.c.id) > sa.tuple_(sessions.c.finished_at, sessions.c.id),
        )
    )
    order_of = (
        sa.select(visits.c.order_id).where(visits.c.session_id == sessions.c.id).scalar_subquery().label("order_id")
    )
    anchors = (
        sa.select(sessions.c.id, sessions.c.finished_at, order_of)
        .where(*_listed(sessions, state, kiosk_id), ~newer_of_its_order)
        .order_by(sessions.c.finished_at.desc(), sessions.c.id.desc())
        .limit(limit + 1)
    )
    finished_at, _, session_id = after.partition("|")
    if finished_at:
        anchors = anchors.where(sa.tuple_(sessions.c.finished_at, sessions.c.id) < sa.tuple_(finished_at, session_id))
    return anchors


def inbox(
    engine: Engine,
    q: Questionnaire,
    *,
    state: str = "waiting",
    kiosk_id: str | None = None,
    after: str = "",
    limit: int = INBOX_LIMIT,
) -> Page:
    """Visits with a finished result in the review states of ``state`` (:data:`INBOX_STATES`), of
    one kiosk or all, newest first, each with every instrument it has so far (running ones too).
    Keyset pages: ``after`` is the previous page's last anchor (finish time, id), so the hundredth
    page costs what the first does (an index range, never an OFFSET); the database picks the
    anchors (a later finished session of the same order in the filter makes a session none), so
    its order of rows, not Python's, decides what a page holds."""
    anchors = anchor_query(state, kiosk_id, after, limit)
    with engine.connect() as connection:
        rows = connection.execute(anchors).all()
        more = len(rows) > limit
        rows = rows[:limit]
        orders = [r.order_id for r in rows if r.order_id]
        members: dict[str, list[str]] = {}
        if orders:
            query = (
                sa.select(visits.c.order_id, visits.c.session_id)
                .select_from(visits.join(sessions, sessions.c.id == visits.c.session_id))
                .where(visits.c.order_id.in_(orders), sessions.c.status != "pending")
            )
            for order_id, member in connection.execute(query):
                members.setdefault(order_id, []).append(member)
    ids = [s for r in rows for s in (members.get(r.order_id, [r.id]) if r.order_id else [r.id])]
    by_key = {v.key: v for v in group(results_of(engine, q, [_Id(i) for i in dict.fromkeys(ids)]))}
    listed = [by_key[k] for k in dict.fromkeys(visit_key(r.id, r.order_id) for r in rows) if k in by_key]
    return Page(listed, f"{rows[-1].finished_at}|{rows[-1].id}" if more else "")


@record
class _Id:
    """A session id as :func:`station.results.results_of` takes rows."""

    id: str


def patient_visits(found: list[Result]) -> list[VisitRow]:
    """A patient's course (:func:`station.results.course`) as visits, newest first."""
    return sorted(group(found), key=lambda v: (v.started_at, v.key), reverse=True)
