"""What the station makes of the lifecycle rows the kiosk sends for interrupted tests."""

from __future__ import annotations

from station.sessions import Row, status_of


def rows(*kinds: str) -> list[Row]:
    payloads = {
        "create_session": {"patient_id": "P-AAAAAA", "started_at": "2026-11-23T15:00:00+00:00"},
        "mark_interrupted": {"reason": "its kiosk vm (process 42) stopped"},
    }
    return [Row(seq, kind, payloads.get(kind, {}), "2026-11-23T15:00:00Z") for seq, kind in enumerate(kinds)]


def test_an_interrupted_test_continued_by_staff_runs_again_and_one_ended_is_abandoned():
    assert status_of(rows("create_session", "mark_interrupted"))["status"] == "interrupted"
    assert status_of(rows("create_session", "mark_interrupted", "continue_session"))["status"] == "running"
    assert status_of(rows("create_session", "mark_interrupted", "abandon"))["status"] == "abandoned"
    assert status_of(rows("create_session", "continue_session"))["status"] == "running"
