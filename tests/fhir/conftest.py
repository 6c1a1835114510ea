"""Fixtures of the FHIR/CSV export tests: real replays in a real SQLite store (the checkers are in
:mod:`tests.fhir.standard`)."""

from __future__ import annotations

from pathlib import Path

import pytest

from kiosk.replay import load_script, run_script
from kiosk.storage import Store, StoredSession

ROOT = Path(__file__).resolve().parents[2]
PATIENTS = sorted((ROOT / "recordings/patients").glob("*.yaml"))


@pytest.fixture(scope="session")
def replay_dir(tmp_path_factory) -> Path:
    """A data directory whose real SQLite store holds every scripted patient of
    recordings/patients/ replayed through the real session (English, Spanish, French)."""
    data = tmp_path_factory.mktemp("fhir") / "data"
    with Store.open(data) as store:
        for path in PATIENTS:
            run_script(load_script(path), store=store)
    return data


@pytest.fixture(scope="session")
def replayed(replay_dir) -> dict[str, StoredSession]:
    """The replayed sessions, by patient id."""
    with Store.open(replay_dir, create=False) as store:
        return {s.patient_id: store.session(s.id) for s in store.sessions()}
