"""The sync client against a real HTTP server speaking the protocol (tests/kiosk/sync/ward.py): the
outbox written with each change, delivered in order and alerts first, idempotently, through a
station that is down, drops connections after storing, answers 500 or refuses a row."""

from __future__ import annotations

import itertools
import sqlite3
import threading

import pytest

from kiosk.store.database import Store
from kiosk.sync import SyncClient
from tests.kiosk.core.helpers import Rig, at_first_question

from .ward import TOKEN, Server

KIOSK = "ward3-bed2"


def outbox_rows(store: Store) -> list[tuple[int, str, str]]:
    return [
        (seq, kind, json) for seq, kind, json in store._db.execute("SELECT seq, kind, payload FROM outbox ORDER BY seq")
    ]


def session_with_incidents(store: Store) -> Rig:
    """A session that answers, calls the doctor, is continued, and answers again."""
    rig = at_first_question(store, patient_id="P-SYNC01")
    session = rig.session
    rig.answer(2)
    rig.at(session.now() + 3)
    session.call_doctor()
    rig.at(session.now() + 20)
    session.clinician_continue()
    rig.run_until(session.now() + 30)
    rig.answer(1)
    return rig


def waiting(store: Store) -> list[tuple[int, str | None]]:
    """The outbox rows as another connection sees them: (seq, parked)."""
    with sqlite3.connect(store.path) as other:
        return other.execute("SELECT seq, parked FROM outbox ORDER BY seq").fetchall()


def client(store: Store, server: Server, **kwargs) -> SyncClient:
    sync = SyncClient(store.path, url=server.url, token=TOKEN, kiosk_id=KIOSK, backoff=(0.02, 0.2), **kwargs)
    store.on_outbox = sync.wake
    return sync


def test_without_a_station_nothing_is_queued(tmp_path):
    store = Store.open(tmp_path)
    session_with_incidents(store)
    assert outbox_rows(store) == []
    assert not [t for t in threading.enumerate() if t.name.startswith("station")]


def test_every_change_is_queued_in_its_transaction_with_the_store_methods_arguments(tmp_path):
    store = Store.open(tmp_path, outbox=True)
    rig = session_with_incidents(store)
    rows = outbox_rows(store)
    kinds = [kind for _, kind, _ in rows]
    stored = store.session(rig.session.id)
    assert kinds.count("create_session") == 1
    assert kinds.count("record_answer") == len(stored.answers) == 2
    assert kinds.count("record_context") == len(stored.trace)
    assert kinds.count("record_metrics") == len(stored.metrics)
    assert kinds.count("record_event") == len(stored.log)
    assert [s for s, _, _ in rows] == sorted(s for s, _, _ in rows)
    alerts = [json for _, kind, json in rows if kind == "record_event" and "doctor" in json]
    assert '"kind": "doctor_called"' in alerts[0] and '"kind": "doctor_continued"' in alerts[1]


def test_a_station_down_then_up_gets_everything_once_with_the_alerts_first(tmp_path):
    store = Store.open(tmp_path, outbox=True)
    server = Server()  # not started: the station is down
    sync = client(store, server)
    sync.start()
    try:
        session_with_incidents(store)  # the kiosk keeps working meanwhile
        everything = {seq for seq, _, _ in outbox_rows(store)}
        alerts = {seq for seq, kind, json in outbox_rows(store) if kind == "record_event" and "doctor_" in json}
        assert len(alerts) == 2
        server.start()
        server.until(lambda w: {s for _, s in w.stored} == everything, "every row")
        # the alerts went first, in requests of their own: one, or two when the delivery thread
        # read the outbox between the two alerts and reached the station only once it was up (a
        # busy machine does that; which happens depends on scheduling, what matters does not)
        leading = list(itertools.takewhile(lambda request: set(request) <= alerts, server.ward.requests))
        assert leading and set().union(*map(set, leading)) == alerts, server.ward.requests
        assert all(seq in everything for request in server.ward.requests for seq in request)
        assert len(server.ward.stored) == len(everything)
        server.until(lambda w: not waiting(store), "the outbox emptied")
    finally:
        sync.stop()
        server.stop()


def test_a_doctor_call_does_not_wait_for_a_routine_batch_the_station_is_slow_to_store(tmp_path):
    """Under load a batch of 500 rows can take the station seconds; the call goes meanwhile."""
    store = Store.open(tmp_path, outbox=True)
    server = Server().start()
    server.ward.hold_kind = "create_session"  # the first routine batch hangs at the station
    sync = client(store, server)
    sync.start()
    try:
        rig = at_first_question(store, patient_id="P-SYNC02")
        server.until(lambda w: w.held, "the routine batch arrive")
        rig.answer(2)
        rig.at(rig.session.now() + 3)
        rig.session.call_doctor()
        call = next(seq for seq, kind, json in outbox_rows(store) if kind == "record_event" and "doctor_called" in json)
        server.until(lambda w: (KIOSK, call) in w.stored, "the doctor call while the batch was held")
        # stored while the routine batch was still held, its request not given up (the client's
        # request timeout is 15 s; before the alerts' own lane the call went only after it)
        assert (len(server.ward.held), server.ward.abandoned) == (1, 0)
        everything = {seq for seq, _, _ in outbox_rows(store)}
        server.ward.release.set()
        server.until(lambda w: {s for _, s in w.stored} >= everything, "every row once the station caught up")
        sent = [seq for request in server.ward.requests for seq in request]
        assert sent.count(call) == 1  # the call went once, on its own lane
        server.until(lambda w: not waiting(store), "the outbox emptied")
    finally:
        server.ward.release.set()
        sync.stop()
        server.stop()


@pytest.mark.parametrize("fault", ["dropped after storing", "500s"])
def test_a_connection_cut_after_the_station_stored_or_a_500_loses_and_duplicates_nothing(tmp_path, fault):
    store = Store.open(tmp_path, outbox=True)
    server = Server().start()
    if fault == "500s":
        server.ward.fail_500 = 3
    else:
        server.ward.drop_after_store = 2
    sync = client(store, server)
    sync.start()
    try:
        session_with_incidents(store)
        everything = {seq for seq, _, _ in outbox_rows(store)} | {s for _, s in server.ward.stored}
        server.until(
            lambda w: {s for _, s in w.stored} >= everything and not w.drop_after_store and not w.fail_500,
            "every row after the faults",
        )
        sent = [seq for request in server.ward.requests for seq in request]
        assert len(sent) > len(set(sent))  # the batches cut short were sent again...
        assert sorted(s for _, s in server.ward.stored) == sorted(everything)  # ...and stored once
        server.until(lambda w: not waiting(store), "the outbox emptied")
    finally:
        sync.stop()
        server.stop()


def test_a_row_the_station_refuses_is_parked_and_the_rest_delivered(tmp_path):
    store = Store.open(tmp_path, outbox=True)
    session_with_incidents(store)
    rows = outbox_rows(store)
    bad = rows[len(rows) // 2][0]
    server = Server().start()
    server.ward.refuse = {bad}
    sync = client(store, server)
    sync.start()
    try:
        server.until(lambda w: {s for _, s in w.stored} == {s for s, _, _ in rows} - {bad}, "all but the bad row")
        server.until(lambda w: len(waiting(store)) == 1, "the outbox keeping only the bad row")
    finally:
        sync.stop()
        server.stop()
    assert waiting(store) == [(bad, f"422: seq {bad}: refused")]  # kept, with why; never dropped


def test_the_live_status_goes_on_each_change(tmp_path):
    store = Store.open(tmp_path, outbox=True)
    server = Server().start()
    sync = client(store, server)
    sync.start()
    try:
        sync.set_status(
            {
                "session_id": "abc",
                "phase": "questions",
                "question": 3,
                "of": 10,
                "paused": False,
                "person_away": False,
                "doctor_called": True,
                "simulated": False,
            }
        )
        server.until(lambda w: any(s.get("doctor_called") for s in w.statuses), "the doctor call in the status")
        status = next(s for s in server.ward.statuses if s.get("doctor_called"))
        assert (status["kiosk_id"], status["question"], status["session_id"]) == (KIOSK, 3, "abc")
        # this process among the kiosk's (two browser tabs are two processes: station.ward)
        other = SyncClient(store.path, url=server.url, token=TOKEN, kiosk_id=KIOSK)
        assert status["instance"] == sync.instance and sync.instance != other.instance
    finally:
        sync.stop()
        server.stop()
