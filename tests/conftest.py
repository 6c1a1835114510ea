"""Fixtures every test package may use: the set-up the test run does itself (see
:mod:`tests.prerequisites`), so ``uv run pytest`` passes on a fresh clone."""

from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path

import pytest

from tests.prerequisites import ensure_npm_packages, require_debian

#: the test run's own user cache directory and the XDG_CACHE_HOME it replaced
_CACHE_HOME = pytest.StashKey[tuple[str, str | None]]()


def pytest_configure(config: pytest.Config) -> None:
    """What the code keeps in the user's cache (the QoS grammar's tables, parsed models, passed
    schema checks) goes to a directory of this test run, inherited by the processes tests start,
    never to the user's home; it is removed when the run ends."""
    folder = tempfile.mkdtemp(prefix="kiosk-tests-cache-")
    config.stash[_CACHE_HOME] = (folder, os.environ.get("XDG_CACHE_HOME"))
    os.environ["XDG_CACHE_HOME"] = folder


def pytest_unconfigure(config: pytest.Config) -> None:
    folder, before = config.stash[_CACHE_HOME]
    if before is None:
        os.environ.pop("XDG_CACHE_HOME", None)
    else:
        os.environ["XDG_CACHE_HOME"] = before
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
