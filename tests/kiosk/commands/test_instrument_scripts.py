"""The scripted patient of each shipped instrument (recordings/patients/instruments/) replays in a
real `kiosk replay` with its configuration and gets the total and band its header promises."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from kiosk.store.database import Store

ROOT = Path(__file__).resolve().parents[3]
SCRIPTS = ROOT / "recordings/patients/instruments"


@pytest.mark.parametrize(
    ("name", "language", "total", "maximum", "band"),
    [
        ("lawton", "en", 4, 8, "total_only"),
        ("gds15", "de", 7, 15, "suggests_depression"),
        ("sarc_f", "es", 4, 10, "suggests_sarcopenia"),
    ],
)
def test_each_shipped_instrument_has_a_scripted_patient(tmp_path, name, language, total, maximum, band):
    done = subprocess.run(
        [sys.executable, "-m", "kiosk", "replay", str(SCRIPTS / f"{name}.yaml"), "--json"]
        + ["--config", str(SCRIPTS / f"{name}.config.yaml"), "--data-dir", str(tmp_path / "data")],
        capture_output=True,
        text=True,
        env=dict(os.environ, HOME=str(tmp_path)),
        timeout=300,  # a guard against a hang, not a timing assertion
    )
    assert done.returncode == 0, done.stderr
    result = json.loads(done.stdout)
    assert result["language"] == language
    assert (result["score"]["total"], result["score"]["band"], result["score"]["complete"]) == (total, band, True)
    assert result["score"]["max_total"] == maximum
    # the stored result keeps the translation it ran in: its source and whether it is validated
    with Store.open(tmp_path / "data", create=False) as store:
        (stored,) = [store.session(s.id) for s in store.sessions()]
    translation = stored.definition["translations"][language]
    assert translation["validated"] is (language == "en") and translation["source"].strip()
