"""Timed Up and Go results out of the station, through the kiosk's own export code
(:mod:`kiosk.export.tug`): the same Observation (LOINC 89423-8, in s, the method camera or
stopwatch, the phases as components) and the same CSV the kiosk's ``kiosk results`` gives, under
the identity the kiosk recorded it with, so a hospital importing both gets one result. A rejected
test has no time and exports nothing.
"""

from __future__ import annotations

from collections.abc import Sequence
from datetime import date, timedelta
from typing import Any

import sqlalchemy as sa
from sqlalchemy.engine import Connection

from kiosk.core.site import ExportSite, site_from_identity
from kiosk.export.tug import tug_csv, tug_entries
from station.db import tug_results
from station.tugs import StationTug, of_row


def site_of(tug: StationTug) -> ExportSite:
    """The identity the kiosk recorded the result under (its kiosk id: the one that sent it)."""
    identity = dict(tug.export)
    return site_from_identity(identity, identity.get("kiosk_id") or tug.kiosk_id)


def entries(tugs: Sequence[StationTug]) -> list[dict[str, Any]]:
    """Transaction Bundle entries (conditional creates) of the results that have a time."""
    found = []
    for tug in tugs:
        time = tug.time()
        if time is not None:
            found += tug_entries([time], site_of(tug))
    return found


def bundle(tugs: Sequence[StationTug]) -> dict[str, Any]:
    """A transaction Bundle of ``tugs`` (no entry when none has a time)."""
    found = entries(tugs)
    return {"resourceType": "Bundle", "type": "transaction", **({"entry": found} if found else {})}


def csv_text(tugs: Sequence[StationTug]) -> str:
    """The kiosk's TUG CSV (a row for the total, one per phase) of the results that have a time."""
    return tug_csv([t for t in (tug.time() for tug in tugs) if t is not None])


def in_period(connection: Connection, first: date, last: date) -> list[StationTug]:
    """The results taken from ``first`` to ``last`` (UTC days, both included), oldest first."""
    start, end = first.isoformat(), (last + timedelta(days=1)).isoformat()
    query = (
        sa.select(tug_results)
        .where(tug_results.c.at >= start, tug_results.c.at < end, tug_results.c.total_s.is_not(None))
        .order_by(tug_results.c.at, tug_results.c.id)
    )
    return [of_row(r) for r in connection.execute(query)]
