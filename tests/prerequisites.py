"""What the tests need beyond the Python packages, set up by the test run itself: the npm packages
of tests/kiosk/export/js (installed with ``npm ci`` when missing or older than their lock file) and the
Debian packages some tests use (checked: installing them needs root, so a missing one is one
failure line naming the ``apt-get install`` that fixes it).

Why: ``uv run pytest`` on a fresh clone must pass with no manual step (issue 22)."""

from __future__ import annotations

import fcntl
import hashlib
import os
import shutil
import subprocess
from pathlib import Path

import pytest

JS = Path(__file__).parent / "kiosk" / "export" / "js"
#: the hash of the package-lock.json node_modules was last installed from
STAMP = JS / "node_modules" / ".installed-from-lock"
#: serialises installs between test processes sharing this checkout
LOCK = JS / ".npm-install.lock"

#: names the developer's own home once the test run has pointed HOME at a folder of its own
#: (tests/conftest.py): npm keeps its package cache and reads its .npmrc there
DEVELOPER_HOME = "TESTS_DEVELOPER_HOME"

_installed: set[Path] = set()


def _lock_hash(js: Path) -> str:
    return hashlib.sha256((js / "package-lock.json").read_bytes()).hexdigest()


def _up_to_date(js: Path) -> bool:
    stamp = js / "node_modules" / STAMP.name
    return stamp.is_file() and stamp.read_text(encoding="ascii").strip() == _lock_hash(js)


def ensure_npm_packages(js: Path = JS) -> Path:
    """``js``'s node_modules, installed by ``npm ci --no-audit --no-fund`` unless it was already
    installed from the current package-lock.json (a stamp of the lock's hash says so). Safe when
    several processes call it at once: the install runs under an exclusive file lock and is
    re-checked inside it. Fails the calling test with one line when npm is absent or the install
    fails."""
    if js in _installed:
        return js / "node_modules"
    with open(js / LOCK.name, "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        try:
            if not _up_to_date(js):
                npm = shutil.which("npm")
                if npm is None:
                    pytest.fail(
                        f"npm is not installed (the FHIR checkers in {js} need it): sudo apt-get install npm",
                        pytrace=False,
                    )
                done = subprocess.run(
                    [npm, "ci", "--no-audit", "--no-fund"],
                    cwd=js,
                    env=os.environ | {"HOME": os.environ.get(DEVELOPER_HOME) or str(Path.home())},
                    capture_output=True,
                    text=True,
                    check=False,
                )
                if done.returncode != 0:
                    last = (done.stderr.strip() or done.stdout.strip()).splitlines()[-1:] or ["(no output)"]
                    pytest.fail(f"`npm ci` in {js} failed with exit {done.returncode}: {last[0]}", pytrace=False)
                (js / "node_modules").mkdir(exist_ok=True)  # npm makes none for a lock without packages
                (js / "node_modules" / STAMP.name).write_text(_lock_hash(js) + "\n", encoding="ascii")
        finally:
            fcntl.flock(lock, fcntl.LOCK_UN)
    _installed.add(js)
    return js / "node_modules"


def require_debian(package: str, *, command: str | None = None, path: str | None = None) -> None:
    """Fail the calling test with one line naming the Debian package to install when ``command``
    is not on PATH or ``path`` does not exist."""
    missing = (command is not None and shutil.which(command) is None) or (path is not None and not Path(path).exists())
    if missing:
        what = command or path
        pytest.fail(f"{what} is not installed: sudo apt-get install {package} (.ci/run installs it)", pytrace=False)
