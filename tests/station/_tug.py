"""Timed Up and Go results as a kiosk sends them: real TugSteps over generated landmark
sequences, stored in a real kiosk Store with a station configured, read back from its outbox."""

from __future__ import annotations

import json
import sqlite3
from pathlib import Path

from kiosk.core.tug.families import generate
from kiosk.core.tug.step import TugResult
from kiosk.store.database import DB_NAME, Store
from tests.kiosk.core.tug.stepping import go_of, run
from tests.station.helpers import Row


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
