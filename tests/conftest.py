"""Fixtures every test package may use: the set-up the test run does itself (see
:mod:`tests.prerequisites`), so ``uv run pytest`` passes on a fresh clone."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.prerequisites import ensure_npm_packages, require_debian


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
