"""Who answers an ordered visit for the patient (issue 35), against a real `kiosk station`
process on SQLite and on PostgreSQL: staff choose the answerer's relationship on the order form,
the order's page and audit trail say it, and the kiosk's poll carries ``relationship`` (and, for
"other", ``relationship_text``) as protocol §4 says, which the kiosk's own reader takes. A code
not on the list or words too long are refused with one message and nothing is stored; a database
from before the columns upgrades, its orders saying nothing."""

from __future__ import annotations

from urllib.parse import parse_qs, urlsplit

import pytest
import sqlalchemy as sa
from alembic import command
from alembic.config import Config

from kiosk.core.answerers import Answerer
from kiosk.core.visits import parse_orders
from station import db
from station.db import orders as orders_table
from tests.station.conftest import make_ward, new_kiosk
from tests.station.helpers import KioskClient, Staff

pytestmark = pytest.mark.slow


def order(staff: Staff, kiosk: str, patient: str, **extra: str):
    """Several patients queue on one kiosk here: each order confirmed past the double-booking warning."""
    return staff.post(
        "/orders", patient_id=patient, kiosk=kiosk, instrument="barthel", language="en", anyway="yes", **extra
    )


def stored(db_url: str) -> list[tuple]:
    engine = db.make_engine(db_url)
    try:
        with engine.connect() as connection:
            return [
                tuple(r)
                for r in connection.execute(
                    sa.select(
                        orders_table.c.patient_id, orders_table.c.relationship, orders_table.c.relationship_text
                    ).order_by(orders_table.c.patient_id)
                )
            ]
    finally:
        engine.dispose()


@pytest.mark.parametrize("database", ["sqlite", "postgres"])
def test_the_answerers_relationship_goes_from_the_form_to_the_kiosks_poll(database, request, station_factory):
    db_url = request.getfixturevalue("sqlite_url" if database == "sqlite" else "pg_url")
    ward = make_ward(db_url)
    station = station_factory(db_url)
    kiosk = KioskClient(station.url, ward.token, ward.kiosk_id)
    nurse = Staff(station.url, "nurse.kim", "nurse")

    form = nurse.http.get("/orders").text
    for name in ("spouse", "daughter", "paid carer", "other"):
        assert f'<option value="{name}">{name}</option>' in form
    daughter = order(nurse, ward.kiosk_id, "NHC-0000001", relationship="daughter")  # implies a relative answers
    lodger = order(
        nurse, ward.kiosk_id, "NHC-0000002", relative="yes", relationship="other", relationship_text="lodger"
    )
    alone = order(nurse, ward.kiosk_id, "NHC-0000003")
    assert [r.status_code for r in (daughter, lodger, alone)] == [303, 303, 303]
    page = nurse.http.get(lodger.headers["location"]).text
    assert '<span id="order-answerer">other: lodger</span>' in page
    assert "related: other: lodger" in page  # the audit trail
    assert '<span id="order-answerer">their daughter</span>' in nurse.http.get(daughter.headers["location"]).text

    polled = {o["patient_id"]: o for o in kiosk.orders()["orders"]}
    assert polled["NHC-0000001"]["relationship"] == "daughter"
    assert polled["NHC-0000001"]["answered_by"] == "relative"
    assert "relationship_text" not in polled["NHC-0000001"]
    assert (polled["NHC-0000002"]["relationship"], polled["NHC-0000002"]["relationship_text"]) == ("other", "lodger")
    assert "relationship" not in polled["NHC-0000003"] and polled["NHC-0000003"]["answered_by"] == "patient"
    taken, problems = parse_orders({"orders": list(polled.values())}, ["barthel"], ["en"])
    assert problems == []
    assert {o.patient_id: o.answerer for o in taken} == {
        "NHC-0000001": Answerer("daughter"),
        "NHC-0000002": Answerer("other", "lodger"),
        "NHC-0000003": None,
    }
    kiosk.close()


@pytest.mark.parametrize(
    ("fields", "message"),
    [
        ({"relationship": "cousin"}, "'cousin' is not one of spouse, daughter"),
        ({"relationship": "other", "relationship_text": "x" * 61}, "one line of at most 60 characters"),
        ({"relationship": "other"}, 'say in words how they are related to the patient (for "other")'),
        ({"relationship": "son", "relationship_text": "eldest"}, 'words are only for "other"'),
        ({"relationship_text": "lodger"}, 'choose "other" to describe'),
    ],
)
def test_a_relationship_off_the_list_or_too_long_is_refused_with_its_message(fields, message, shared_station):
    station, ward = shared_station
    name, _ = new_kiosk(ward.db_url)
    nurse = Staff(station.url, "nurse.kim", "nurse")
    refused = order(nurse, name, "NHC-0000099", **fields)
    assert refused.status_code == 303 and refused.headers["location"].startswith("/orders?error=")
    error = parse_qs(urlsplit(refused.headers["location"]).query)["error"][0]
    assert error.startswith("who answers for the patient: ") and message in error
    page = nurse.http.get(refused.headers["location"]).text
    assert page.count('id="order-error"') == 1
    assert not [row for row in stored(ward.db_url) if row[0] == "NHC-0000099"]  # nothing stored


@pytest.mark.parametrize("database", ["sqlite", "postgres"])
def test_orders_from_before_the_relationship_upgrade_saying_nothing(database, request, station_factory):
    db_url = request.getfixturevalue("sqlite_url" if database == "sqlite" else "pg_url")
    engine = db.make_engine(db_url)
    config = Config()
    config.set_main_option("script_location", str(db.MIGRATIONS))
    with engine.begin() as connection:
        config.attributes["connection"] = connection
        command.upgrade(config, "0007_known_definitions")
        connection.execute(
            sa.text(
                "INSERT INTO orders (id, kiosk_id, patient_id, instruments, language, answered_by, code, state,"
                " ordered_by, ordered_at, updated_at) VALUES ('order-0ld0rder0000', 'ward3-bed2', 'NHC-0000007',"
                " '[\"barthel\"]', 'en', 'relative', '1234', 'ordered', 'nurse.kim', '2026-01-01T00:00:00.000+00:00',"
                " '2026-01-01T00:00:00.000+00:00')"
            )
        )
    engine.dispose()
    ward = make_ward(db_url)  # opens (migrates) the database to the newest revision
    assert stored(db_url) == [("NHC-0000007", None, None)]
    station = station_factory(db_url)
    kiosk = KioskClient(station.url, ward.token, ward.kiosk_id)
    (old,) = kiosk.orders()["orders"]
    assert old["answered_by"] == "relative" and "relationship" not in old and "relationship_text" not in old
    nurse = Staff(station.url, "nurse.kim", "nurse")
    assert '<span id="order-answerer">a relative</span>' in nurse.http.get("/orders/order-0ld0rder0000").text
    kiosk.close()
