"""The test suite is sealed (issue 32): with a developer's own kiosk variables set, tests read none
of them, write nothing into the folders they name, and a test that would hang fails instead."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.prerequisites import DEVELOPER_HOME

ROOT = Path(__file__).resolve().parents[1]
#: test files that start the real app, load the configuration, keep a cache and open a station's
#: default folder: each would have read or written a developer's folders before the seal
PROBES = (
    "tests/kiosk/store/test_schema.py",
    "tests/kiosk/test_config.py",
    "tests/fileio/test_cache.py",
)


def _files(folder: Path) -> list[Path]:
    return sorted(p for p in folder.rglob("*") if p.is_file() or p.is_symlink())


@pytest.mark.slow
def test_a_developers_variables_reach_no_test_and_their_folders_stay_empty(tmp_path):
    developer = tmp_path / "developer"
    folders = {
        name: developer / name.lower()
        for name in (
            "HOME",
            "XDG_CACHE_HOME",
            "XDG_CONFIG_HOME",
            "XDG_DATA_HOME",
            "XDG_STATE_HOME",
            "KIOSK_DATA_DIR",
            "KIOSK_STATION_DIR",
            "KIOSK_MODELS_DIR",
        )
    }
    for folder in folders.values():
        folder.mkdir(parents=True)
    config = developer / "config.yaml"  # a developer's own kiosk: Spanish, its own data, a station
    config.write_text(f"language: es\ndata_dir: {developer / 'data-from-config'}\n", encoding="utf-8")
    env = {k: v for k, v in os.environ.items() if k != DEVELOPER_HOME}  # the inner run's is the one below
    env |= {name: str(folder) for name, folder in folders.items()}
    env |= {
        "KIOSK_CONFIG": str(config),
        "KIOSK_LANGUAGE": "fr",
        "KIOSK_STATION_URL": "http://127.0.0.1:9",
        "KIOSK_STATION_TOKEN": "a-developers-token",
        "KIOSK_VOSK_MODEL": str(developer / "no-model"),
    }
    run = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider"]
        + ["--basetemp", str(tmp_path / "basetemp"), "-m", "not slow", "--timeout", "120", *PROBES],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=900,  # the inner run's own per-test limit (pyproject) fails a hang long before this
        check=False,
    )
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-2000:]
    assert " passed" in run.stdout.splitlines()[-1]
    assert [p for p in _files(developer) if p != config] == []
    assert config.read_text(encoding="utf-8").startswith("language: es\n")
