"""Timed Up and Go results as a kiosk sends them: real TugSteps over generated landmark
sequences, stored in a real kiosk Store with a station configured, read back from its outbox."""

from __future__ import annotations

import json
import sqlite3
from dataclasses import dataclass, replace
from datetime import UTC, datetime
from pathlib import Path

from sqlalchemy.engine import Engine

from bench._history import clone
from kiosk.core.tug.families import generate
from kiosk.core.tug.step import TugResult
from kiosk.store.database import DB_NAME, Store
from station import auth, orders, sync
from tests.kiosk.core.tug.stepping import go_of, run
from tests.station.helpers import PATIENTS, Row, record_patient


def camera_result(seed: int = 11) -> TugResult:
    """A normal course the camera timed, accepted by staff, with the staff items."""
    sequence, truth = generate("normal", seed)
    assert truth.onset_t is not None
    step, _, _ = run(sequence, go_of(sequence, truth.onset_t))
    step.rate(get_up_go=3, walking_aid="stick")
    return step.decide("accepted", "dr-lee")


def stopwatch_result(seconds: float = 15.5) -> TugResult:
    """Legs cut off in the picture: staff entered their stopwatch's time."""
    sequence, _ = generate("legs_cut", 4)
    step, _, _ = run(sequence, 1.0)
    return step.decide("stopwatch", "nurse-7", stopwatch_s=seconds)


def outbox(path: Path) -> list[Row]:
    """The kiosk database's outbox rows, as the protocol sends them."""
    with sqlite3.connect(path) as db:
        rows = db.execute("SELECT seq, kind, session_id, payload, at FROM outbox ORDER BY seq").fetchall()
    return [Row(seq, kind, session_id, json.loads(payload), 0.0, at) for seq, kind, session_id, payload, at in rows]


def tug_rows(
    data_dir: Path,
    results: list[tuple[str, TugResult, str]],
    *,
    visit: str | None = "staff",
    visit_id: str | None = None,
) -> list[Row]:
    """Store ``results`` ((patient, result, at) each) in a kiosk store with an outbox at
    ``data_dir``; the outbox rows it queued (only theirs when the store was new)."""
    export = {"site": "hosp-north", "kiosk_id": "ward3-bed2"}
    with Store.open(data_dir, outbox=True, export=export) as store:
        for patient, result, at in results:
            store.tug.record(patient, result, at=at, visit=visit, visit_id=visit_id)
    return [r for r in outbox(data_dir / DB_NAME) if r.kind == "record_tug"]


#: when the ordered visit's Barthel began
BARTHEL_AT = datetime(2026, 11, 20, 10, 15, tzinfo=UTC)


@dataclass
class TugVisits:
    """A patient's visits with Timed Up and Go results, stored through the station's own code."""

    patient_id: str
    order_id: str
    barthel: str
    #: the ordered visit's TUG (camera, accepted) and an earlier staff visit's (stopwatch)
    camera: str
    stopwatch: str


def store_tug_visits(engine: Engine, tmp_path: Path, patient: str = "NHC-0034100") -> TugVisits:
    """On a ward made by :func:`tests.station.conftest.make_ward` (kiosk ward3-bed2): a staff
    visit's stopwatch TUG (15.5 s, above the threshold) on 2026-11-02, then an ordered visit of a
    Barthel and a camera TUG (about 10.6 s) on 2026-11-20, each from a real kiosk store's outbox."""
    kiosk = "ward3-bed2"
    order = orders.create(
        engine,
        kiosk_id=kiosk,
        patient_id=patient,
        instruments=["barthel", "tug"],
        language="en",
        relative=False,
        by=auth.User("nurse.kim", "nurse"),
        known_instruments=["barthel", "tug"],
        languages=["en"],
    )
    with engine.begin() as connection:
        assert orders.start(connection, kiosk, order.code) is not None
    visit = f"order {order.id}"
    early = tug_rows(tmp_path / "k-early", [(patient, stopwatch_result(), "2026-11-02T08:00:00Z")], visit="staff")
    template = record_patient(PATIENTS / "barthel1.yaml", patient=patient, visit=visit)
    barthel = clone(template, f"tug-barthel-{patient}", patient, BARTHEL_AT, len(early) + 1)
    late = tug_rows(tmp_path / "k-late", [(patient, camera_result(), "2026-11-20T10:40:00Z")], visit=visit)
    late = [replace(r, seq=len(early) + len(barthel) + 1 + i) for i, r in enumerate(late)]
    with engine.begin() as connection:
        events = [*[r.event() for r in early], *barthel, *[r.event() for r in late]]
        sync.intake(connection, kiosk, sync.parse({"events": events}))
    return TugVisits(patient, order.id, barthel[0]["session_id"], late[0].session_id, early[0].session_id)
