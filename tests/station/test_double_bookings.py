"""Double bookings (issue 36), through the station's own use case on SQLite and PostgreSQL: the
same patient twice on one kiosk is refused; the same patient on another kiosk, or another
patient on a kiosk with an open visit, is ordered only when staff confirm ("order anyway"), and
the trail says what they confirmed. A closed visit books nothing."""

from __future__ import annotations

import pytest
import sqlalchemy as sa

from station import auth, db, orders
from station.db import audit

NURSE = auth.User("nurse.kim", "nurse")


def _order(engine, kiosk: str, patient: str, anyway: bool = False) -> orders.Order:
    return orders.create(
        engine,
        kiosk_id=kiosk,
        patient_id=patient,
        instruments=["barthel"],
        language="en",
        relative=False,
        by=NURSE,
        known_instruments=["barthel"],
        languages=["en"],
        anyway=anyway,
    )


@pytest.mark.parametrize("database", ["sqlite", "postgres"])
def test_double_bookings_are_refused_or_confirmed(database, request):
    engine = db.open_database(request.getfixturevalue("sqlite_url" if database == "sqlite" else "pg_url"))
    for kiosk in ("bed1", "bed2"):
        auth.add_kiosk(engine, kiosk)
    first = _order(engine, "bed1", "NHC-0036101")

    for same in ("NHC-0036101", "nhc-0036101"):  # the same visit twice: refused, even with "anyway"
        with pytest.raises(orders.OrderError, match="already has an open visit on kiosk bed1") as refused:
            _order(engine, "bed1", same, anyway=True)
        assert not isinstance(refused.value, orders.DoubleBooking)

    with pytest.raises(orders.DoubleBooking) as elsewhere:
        _order(engine, "bed2", "NHC-0036101")
    (warning,) = elsewhere.value.warnings
    assert "NHC-0036101 already has an open visit on kiosk bed1 (waiting to start" in warning
    assert "a patient can be at one kiosk at a time" in warning
    with pytest.raises(orders.DoubleBooking, match="kiosk bed1 already has 1 open visit of other patients"):
        _order(engine, "bed1", "NHC-0036102")
    assert [o.id for o in orders.listing(engine)] == [first.id]  # nothing was ordered unconfirmed

    moved = _order(engine, "bed2", "NHC-0036101", anyway=True)
    queued = _order(engine, "bed1", "NHC-0036102", anyway=True)
    assert moved.state == queued.state == "ordered"
    with engine.connect() as connection:
        reasons = connection.execute(sa.select(audit.c.reason).where(audit.c.session_id == moved.id)).scalars().all()
    assert any("ordered anyway: NHC-0036101 already has an open visit on kiosk bed1" in r for r in reasons)

    # closed visits book nothing: once both of bed1's are cancelled, its next patient is simply ordered
    orders.cancel(engine, first.id, NURSE, "ordered twice")
    orders.cancel(engine, queued.id, NURSE, "ordered twice")
    assert _order(engine, "bed1", "NHC-0036103").state == "ordered"
    engine.dispose()
