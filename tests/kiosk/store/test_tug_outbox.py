"""A stored Timed Up and Go queues its ``record_tug`` outbox row in the same transaction, only
where a station is configured (docs/station-protocol.md, "Timed Up and Go"): the payload the
station checks, never the landmarks; a result the table refuses queues nothing."""

from __future__ import annotations

import sqlite3
from dataclasses import replace

import pytest

from kiosk.core.tug.step import TugSettings
from kiosk.store.database import DB_NAME, Store
from tests.station._tug import camera_result, outbox, stopwatch_result


def test_a_stored_tug_is_one_outbox_row_with_the_result(tmp_path):
    kept = camera_result()
    with Store.open(tmp_path, outbox=True, export={"site": "hosp-north"}) as store:
        tug_id = store.tug.record("P-0042", kept, visit="order order-1a2b", visit_id="v1", at="2026-11-28T05:00:00Z")
    (row,) = outbox(tmp_path / DB_NAME)
    assert (row.kind, row.session_id) == ("record_tug", tug_id)
    p = row.payload
    assert (p["tug_id"], p["patient_id"], p["visit"], p["visit_id"], p["at"]) == (
        tug_id,
        "P-0042",
        "order order-1a2b",
        "v1",
        "2026-11-28T05:00:00Z",
    )
    assert (p["decision"], p["decided_by"], p["confirmed_by"], p["method"]) == (
        "accepted",
        "dr-lee",
        "nurse-7",
        "camera",
    )
    assert p["total_s"] == kept.total_s and [x["name"] for x in p["phases"]][0] == "sit_to_stand"
    assert (p["get_up_go"], p["walking_aid"], p["simulated"], p["export"]) == (
        3,
        "stick",
        False,
        {"site": "hosp-north"},
    )
    assert "landmarks" not in p


def test_landmarks_kept_by_the_site_never_travel(tmp_path):
    from kiosk.core.tug.families import generate
    from tests.kiosk.core.tug.stepping import go_of, run

    sequence, truth = generate("normal", 3)
    step, _, _ = run(sequence, go_of(sequence, truth.onset_t or 1.0), TugSettings(keep_landmarks=True))
    result = step.decide("rejected", "dr-lee")
    assert result.landmarks is not None
    with Store.open(tmp_path, outbox=True) as store:
        store.tug.record("P-0042", result, visit="staff")
        assert store.tug.all()[0].landmarks_text  # kept at the kiosk
    (row,) = outbox(tmp_path / DB_NAME)
    assert "landmarks" not in row.payload and row.payload["total_s"] is None and row.payload["method"] is None


def test_no_station_no_row_and_a_refused_result_queues_nothing(tmp_path):
    with Store.open(tmp_path / "alone") as store:
        store.tug.record("P-0042", stopwatch_result(), visit="staff")
    assert outbox(tmp_path / "alone" / DB_NAME) == []
    with Store.open(tmp_path / "ward", outbox=True) as store:
        with pytest.raises(sqlite3.IntegrityError):
            store.tug.record("P-0042", replace(stopwatch_result(), get_up_go=9), visit="staff")
        assert store.tug.all() == []
    assert outbox(tmp_path / "ward" / DB_NAME) == []
