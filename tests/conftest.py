"""Fixtures every test package may use: the set-up the test run does itself (see
:mod:`tests.prerequisites`), so ``uv run pytest`` passes on a fresh clone, and the seal that keeps
the run away from the developer's own kiosk (issue 32)."""

from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path

import pytest

from tests.prerequisites import DEVELOPER_HOME, ensure_npm_packages, require_debian

#: the variables the kiosk, the station, their libraries and libpq read from the environment:
#: a developer's own (a data directory, a station, a Vosk model, a database) must not reach a test
SEALED_PREFIXES = ("KIOSK_", "TEXTUAL", "PG")
#: the tests' own switches, which a developer sets on purpose
KEPT = frozenset({"KIOSK_E2E_SCREENSHOT"})
#: what the run's controller hands its xdist workers (pytest-textual-snapshot's report folder, set
#: in the controller after it cleared the developer's own): kept in a worker, cleared elsewhere
FROM_CONTROLLER = frozenset({"TEXTUAL_SNAPSHOT_TEMPDIR"})
#: the user directories platformdirs (data, configuration, cache, models) and Chromium derive from
USER_DIRS = ("HOME", "XDG_CACHE_HOME", "XDG_CONFIG_HOME", "XDG_DATA_HOME", "XDG_STATE_HOME")

#: the test run's own home folder (removed when the run ends) and the environment it replaced
_SEAL = pytest.StashKey[tuple[str, pytest.MonkeyPatch]]()


def pytest_configure(config: pytest.Config) -> None:
    """Seal the run: every ``KIOSK_*``, ``TEXTUAL*`` and ``PG*`` variable is cleared, and HOME and
    the XDG user directories point into one folder of this run, inherited by the processes tests
    start; what the code keeps in the user's cache (the QoS grammar's tables, parsed models, passed
    schema checks) goes there too, never to the user's home. Done here rather than in a fixture
    because collection imports the code before any fixture runs."""
    folder = tempfile.mkdtemp(prefix="kiosk-tests-home-")
    seal = pytest.MonkeyPatch()
    seal.setenv(DEVELOPER_HOME, os.environ.get(DEVELOPER_HOME) or str(Path.home()))  # xdist's workers inherit it
    kept = KEPT | FROM_CONTROLLER if os.environ.get("PYTEST_XDIST_WORKER") else KEPT
    for name in list(os.environ):
        if name.startswith(SEALED_PREFIXES) and name not in kept:
            seal.delenv(name)
    seal.delenv("XDG_RUNTIME_DIR", raising=False)
    for name in USER_DIRS:
        path = Path(folder) if name == "HOME" else Path(folder) / name.lower()
        path.mkdir(mode=0o700, exist_ok=True)
        seal.setenv(name, str(path))
    seal.setenv("HYPOTHESIS_STORAGE_DIRECTORY", str(Path(folder) / "hypothesis"))  # not ./.hypothesis
    config.stash[_SEAL] = (folder, seal)


def pytest_unconfigure(config: pytest.Config) -> None:
    folder, seal = config.stash[_SEAL]
    seal.undo()
    shutil.rmtree(folder, ignore_errors=True)


@pytest.fixture(scope="session")
def npm_packages() -> Path:
    """tests/kiosk/export/js/node_modules, installed by ``npm ci`` when missing or stale."""
    return ensure_npm_packages()


@pytest.fixture(scope="session")
def chromium() -> str:
    """Debian's Chromium, the browser the page tests drive (fails with one line if absent)."""
    require_debian("chromium", path="/usr/bin/chromium")
    return "/usr/bin/chromium"


@pytest.fixture(scope="session")
def espeak_ng() -> None:
    """espeak-ng, the kiosk's voice out (fails with one line if absent)."""
    require_debian("espeak-ng", command="espeak-ng")
