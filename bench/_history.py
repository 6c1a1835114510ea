"""Years of a ward's history, loaded through the station's own code: the benchmark's
``--history`` and the station's history tests.

One recorded session (the real kiosk's outbox rows, :func:`bench._station_client.record_patient`)
is cloned under new session ids, patients and days, and each clone is stored by
:func:`station.sync.intake` (the kiosk API's own use case, many sessions per transaction) and
signed off by :func:`station.validation.sign_off_in` (the doctor's, many in one transaction), a
day after each was taken.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable
from datetime import UTC, datetime, timedelta
from typing import Any

from sqlalchemy.engine import Engine

from bench._station_client import Row
from station import auth, sync, validation


def clone(
    template: list[Row], session_id: str, patient_id: str, when: datetime, first_seq: int
) -> list[dict[str, Any]]:
    """The template's rows as a session of ``patient_id`` started at ``when``, numbered from
    ``first_seq`` (the same definition, answers and timings)."""
    start = datetime.fromisoformat(template[0].at.replace("Z", "+00:00"))
    events = []
    for n, row in enumerate(template):
        at = when + (datetime.fromisoformat(row.at.replace("Z", "+00:00")) - start)
        payload = row.payload  # shared: intake never changes a payload it is given
        if row.kind == "create_session":
            payload = payload | {"session_id": session_id, "patient_id": patient_id, "started_at": when.isoformat()}
        elif row.kind == "finish_session":
            payload = payload | {"finished_at": at.isoformat()}
        events.append(
            {"seq": first_seq + n, "kind": row.kind, "session_id": session_id, "at": at.isoformat(), "payload": payload}
        )
    return events


def load_history(
    engine: Engine,
    template: list[Row],
    *,
    results: int,
    patients: int,
    years: float,
    kiosks: list[str],
    doctor: str = "history.doctor",
    signed_fraction: float = 0.97,
    now: datetime | None = None,
    per_transaction: int = 25,
    progress: Callable[[int], None] | None = None,
) -> dict[str, Any]:
    """Store ``results`` finished sessions of ``patients`` patients spread over ``years`` before
    ``now`` on ``kiosks`` (their seqs continue after what each has stored), and sign off the
    oldest ``signed_fraction`` of them a day after each was taken. Returns what was loaded."""
    now = now or datetime.now(UTC)
    span = timedelta(days=365.25 * years)
    with contextlib.suppress(ValueError):  # already there: the loader signs as them
        auth.add_user(engine, doctor, "doctor", "history-password-1")
    by = auth.User(doctor, "doctor")
    seqs = {k: 10**9 for k in kiosks}  # far above any live kiosk's seqs
    signed, loaded = 0, 0
    pending: list[tuple[str, list[dict[str, Any]]]] = []
    to_sign: list[tuple[str, datetime]] = []

    def flush() -> None:
        with engine.begin() as connection:
            for kiosk, events in pending:
                sync.intake(connection, kiosk, sync.parse({"events": events}))
        pending.clear()

    for n in range(results):
        when = now - span + span * (n / max(results, 1))
        kiosk = kiosks[n % len(kiosks)]
        session_id = f"history-{n:07d}"
        events = clone(template, session_id, f"NHC-{n % patients:07d}", when, seqs[kiosk])
        seqs[kiosk] += len(events)
        pending.append((kiosk, events))
        if n < results * signed_fraction:
            to_sign.append((session_id, when + timedelta(days=1)))
        if len(pending) >= per_transaction:
            flush()
        loaded += 1
        if progress and loaded % 1000 == 0:
            progress(loaded)
    if pending:
        flush()
    for start in range(0, len(to_sign), per_transaction):
        with engine.begin() as connection:
            for session_id, at in to_sign[start : start + per_transaction]:
                validation.sign_off_in(
                    connection,
                    session_id,
                    by,
                    at.isoformat(timespec="milliseconds"),
                    incomplete="synthetic history: items left unanswered as generated",
                )
                signed += 1
    return {"results": loaded, "signed_off": signed, "patients": min(patients, results), "years": years}


# -- measuring the staff pages and the month's export on a station holding that history ---------


def rss_mib(pid: int) -> float:
    """The process's resident memory now (MiB)."""
    for line in open(f"/proc/{pid}/status"):
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    return 0.0


def logged_in(url: str, user: str, password: str) -> Any:
    import re

    import httpx

    http = httpx.Client(base_url=url, timeout=120)
    token = re.search(r'name="csrf" content="([^"]+)"', http.get("/login").text).group(1)
    http.post("/login", data={"csrf": token, "name": user, "password": password})
    return http


def staff_pages(loaded: dict[str, Any]) -> dict[str, str]:
    """Every staff page (name -> path) on a history of ``loaded``'s shape."""
    session = f"history-{loaded['results'] - 1:07d}"  # the newest, still waiting
    return {
        "ward": "/",
        "inbox_waiting": "/inbox",
        "inbox_signed": "/inbox?state=signed",
        "inbox_all": "/inbox?state=all",
        "inbox_fragment": "/fragments/inbox",
        "ward_results_fragment": "/fragments/results",
        "orders": "/orders",
        "search_prefix": "/patients?q=NHC-00001",
        "patient": "/patients/NHC-0000001",
        "session": f"/sessions/{session}",
        "sign_off_step": f"/sessions/{session}/sign-off",
        "session_fhir": f"/sessions/{session}/export.json",
    }


def time_pages(http: Any, pages: dict[str, str], rounds: int) -> dict[str, dict[str, float | None]]:
    """Each page ``rounds`` times, in turn: p50/p95/max in ms (and any status but 200/303)."""
    import time

    took: dict[str, list[float]] = {name: [] for name in pages}
    bad: dict[str, int] = {}
    for _ in range(rounds):
        for name, path in pages.items():
            start = time.perf_counter()
            response = http.get(path)
            took[name].append((time.perf_counter() - start) * 1000)
            if response.status_code not in (200, 303):
                bad[name] = response.status_code
    out: dict[str, dict[str, float | None]] = {}
    for name, values in took.items():
        ordered = sorted(values)
        out[name] = {
            "p50": round(ordered[len(ordered) // 2], 1),
            "p95": round(ordered[min(len(ordered) - 1, int(0.95 * len(ordered)))], 1),
            "max": round(ordered[-1], 1),
        } | ({"status": float(bad[name])} if name in bad else {})
    return out


def month_export(http: Any, pid: int, today: datetime) -> dict[str, Any]:
    """Download the signed-off Bundle of the 30 days up to ``today`` (streamed); its time, size,
    entries and the station's memory growth while it ran (resident memory sampled every 20 ms)."""
    import json
    import threading
    import time

    first, last = today - timedelta(days=30), today
    before = rss_mib(pid)
    peak = [before]
    done = threading.Event()

    def sample() -> None:
        while not done.wait(0.02):
            peak[0] = max(peak[0], rss_mib(pid))

    sampler = threading.Thread(target=sample, daemon=True)
    sampler.start()
    start = time.perf_counter()
    body = bytearray()
    with http.stream("GET", f"/exports/signed-off.json?from={first.date()}&to={last.date()}") as response:
        status = response.status_code
        for chunk in response.iter_bytes():
            body += chunk
    took = time.perf_counter() - start
    done.set()
    sampler.join()
    entries = json.loads(body).get("entry", []) if status == 200 else []
    return {
        "period": f"{first.date()} to {last.date()}",
        "status": status,
        "seconds": round(took, 2),
        "bytes": len(body),
        "responses": sum(1 for e in entries if e["resource"]["resourceType"] == "QuestionnaireResponse"),
        "station_rss_before_mib": round(before, 1),
        "station_rss_growth_mib": round(peak[0] - before, 1),
        "goal_met": status == 200 and took <= 10 and peak[0] - before <= 200,
    }
