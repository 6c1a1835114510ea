"""Fixtures of the FHIR/CSV export tests: real replays in a real SQLite store (the checkers are in
:mod:`tests.kiosk.export.standard`)."""

from __future__ import annotations

from pathlib import Path

import pytest

from kiosk.commands.replay import load_script, run_script
from kiosk.export import ExportSite, export_identity
from kiosk.store.database import Store, StoredSession

ROOT = Path(__file__).resolve().parents[3]
PATIENTS = sorted((ROOT / "recordings/patients").glob("*.yaml"))
#: the identity the replayed sessions are recorded under (a kiosk's site, kiosk id and FHIR systems)
RECORDED_AT = export_identity(
    ExportSite(
        site="hosp-north",
        kiosk_id="ward3-bed2",
        questionnaire_url="https://hosp-north.example/fhir/Questionnaire/barthel",
    )
)


@pytest.fixture(scope="session")
def replay_dir(tmp_path_factory) -> Path:
    """A data directory whose real SQLite store holds every scripted patient of
    recordings/patients/ replayed through the real session (English, Spanish, French)."""
    data = tmp_path_factory.mktemp("fhir") / "data"
    # recorded at hosp-north on ward3-bed2: the identity every export of these sessions carries
    with Store.open(data, export=RECORDED_AT) as store:
        for path in PATIENTS:
            run_script(load_script(path), store=store)
    return data


@pytest.fixture(scope="session")
def replayed(replay_dir) -> dict[str, StoredSession]:
    """The replayed sessions, by patient id."""
    with Store.open(replay_dir, create=False) as store:
        return {s.patient_id: store.session(s.id) for s in store.sessions()}
