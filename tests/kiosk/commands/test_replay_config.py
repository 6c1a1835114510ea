"""`kiosk replay` scores with the configured questionnaire and band set, as the kiosk does: the band
it prints, the band it stores and the band `kiosk results` shows for that session are one band."""

from __future__ import annotations

import json
import os
import sqlite3
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
#: a 75-point patient: "mild" in the Spanish band set, "moderate" in the default (Shah 1989)
SCRIPT = ROOT / "recordings/patients/spanish_voice.yaml"


def kiosk(*args: str, env: dict[str, str]) -> subprocess.CompletedProcess:
    done = subprocess.run([sys.executable, "-m", "kiosk", *args], capture_output=True, text=True, env=env, timeout=300)
    assert done.returncode == 0, done.stderr
    return done


def test_replay_stores_and_prints_the_configured_band_that_results_shows(tmp_path):
    config = tmp_path / "config.yaml"
    config.write_text("bands: spanish\n")
    data = tmp_path / "data"
    env = dict(os.environ, KIOSK_CONFIG=str(config), HOME=str(tmp_path))
    default_env = {key: value for key, value in env.items() if key != "KIOSK_CONFIG"}

    printed = json.loads(kiosk("replay", str(SCRIPT), "--json", "--data-dir", str(data), env=env).stdout)
    unconfigured = json.loads(kiosk("replay", str(SCRIPT), "--json", env=default_env).stdout)
    assert (printed["score"]["total"], printed["score"]["band"]) == (75, "mild")
    assert unconfigured["score"]["band"] == "moderate", "the two band sets must disagree for this test to mean much"

    with sqlite3.connect(data / "kiosk.sqlite3") as db:
        ((session, stored),) = db.execute("SELECT id, band FROM sessions").fetchall()
    assert stored == "mild"
    shown = kiosk("results", str(session), "--data-dir", str(data), env=env).stdout
    assert "total 75/100 (complete); Mild dependence (bands: spanish" in shown

    # --config names the file as `kiosk run --config` does
    explicit = kiosk("replay", str(SCRIPT), "--json", "--config", str(config), env=default_env).stdout
    assert json.loads(explicit)["score"]["band"] == "mild"
