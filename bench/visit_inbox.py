"""The inbox of visits at scale (issue 36): how long a page of visits takes with a history of
results of which a share are batteries (three sessions of one order), against the old inbox's
cost for a page of results (the same 50 newest results read by :func:`station.results.results_of`).

The history is loaded through the station's intake and sign-off (``bench/_history.py``); its
sessions are then grouped three by three into orders (a ``visits`` row each, as the intake
writes for an ordered session) for ``--battery-share`` of them. Prints JSON: ms p50/p95 per page.

    uv run python bench/visit_inbox.py [--results 1500] [--database sqlite|postgresql] [--rounds 10]
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from datetime import UTC, datetime
from pathlib import Path

import sqlalchemy as sa

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bench._history import load_history
from bench._postgres import create_database, pg_bin, start_postgres
from bench._station_client import PATIENTS, record_patient
from kiosk.core.questionnaire import load_questionnaire
from station import db, results, visit_inbox


def _ms(run, rounds: int) -> dict[str, float]:
    times = []
    for _ in range(rounds):
        started = time.perf_counter()
        run()
        times.append((time.perf_counter() - started) * 1000)
    times.sort()
    return {
        "p50": round(times[len(times) // 2], 1),
        "p95": round(times[min(len(times) - 1, int(0.95 * len(times)))], 1),
    }


def _batteries(engine, share: float) -> int:
    """Group the newest ``share`` of the sessions, three consecutive ones at a time, into orders."""
    with engine.begin() as connection:
        ids = list(connection.execute(sa.select(db.sessions.c.id).order_by(db.sessions.c.finished_at.desc())).scalars())
        grouped = ids[: int(len(ids) * share) // 3 * 3]
        rows = [{"session_id": s, "kind": "order", "order_id": f"order-b{n // 3:07d}"} for n, s in enumerate(grouped)]
        connection.execute(db.visits.delete().where(db.visits.c.session_id.in_(grouped)))
        if rows:
            connection.execute(db.visits.insert(), rows)
    return len(rows) // 3


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--results", type=int, default=1500)
    parser.add_argument("--battery-share", type=float, default=0.6)
    parser.add_argument("--database", choices=["sqlite", "postgresql"], default="sqlite")
    parser.add_argument("--rounds", type=int, default=10)
    args = parser.parse_args()
    stop = None
    with tempfile.TemporaryDirectory() as directory:
        if args.database == "postgresql":
            server, stop = start_postgres(pg_bin())
            url = create_database(server, "visit_inbox")
        else:
            url = db.sqlite_url(Path(directory) / "station")
        try:
            engine = db.open_database(url)
            started = time.monotonic()
            template = record_patient(PATIENTS / "barthel5.yaml")
            loaded = load_history(
                engine,
                template,
                results=args.results,
                patients=max(1, args.results // 10),
                years=5,
                kiosks=["ward3-bed2", "ward3-bed3"],
                signed_fraction=0.9,
                now=datetime(2026, 11, 20, tzinfo=UTC),
            )
            batteries = _batteries(engine, args.battery_share)
            load_s = round(time.monotonic() - started, 1)
            q = load_questionnaire()

            def tenth_page(state: str) -> None:
                after = ""
                for _ in range(10):
                    after = visit_inbox.inbox(engine, q, state=state, after=after).after
                    if not after:
                        break

            with engine.connect() as connection:
                newest = connection.execute(
                    sa.select(db.sessions.c.id).order_by(db.sessions.c.finished_at.desc()).limit(50)
                ).all()
            pages = {
                "visits waiting, first page": lambda: visit_inbox.inbox(engine, q, state="waiting"),
                "visits signed, first page": lambda: visit_inbox.inbox(engine, q, state="signed"),
                "visits all, first page": lambda: visit_inbox.inbox(engine, q, state="all"),
                "visits signed, pages 1-10": lambda: tenth_page("signed"),
                "results of 50 sessions (the old inbox page's reads)": lambda: results.results_of(engine, q, newest),
            }
            out = {
                "date": datetime.now(UTC).isoformat(timespec="seconds"),
                "database": args.database,
                "history": loaded | {"batteries": batteries, "load_s": load_s},
                "ms": {name: _ms(run, args.rounds) for name, run in pages.items()},
            }
            engine.dispose()
        finally:
            if stop is not None:
                stop()
    print(json.dumps(out, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
