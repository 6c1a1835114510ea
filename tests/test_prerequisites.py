"""The test run's own set-up (tests/prerequisites.py) with the real npm, on a package of its own
without dependencies (nothing is downloaded): installed once per lock file, again when the lock
changes, and one failure line naming what to install when npm is missing."""

from __future__ import annotations

import json

import pytest

from tests import prerequisites
from tests.prerequisites import STAMP, ensure_npm_packages, require_debian


def _package(folder, version: str):
    folder.mkdir()
    (folder / "package.json").write_text(json.dumps({"name": "p", "version": version, "private": True}))
    (folder / "package-lock.json").write_text(
        json.dumps(
            {
                "name": "p",
                "version": version,
                "lockfileVersion": 3,
                "requires": True,
                "packages": {"": {"name": "p", "version": version}},
            }
        )
    )
    return folder


def test_npm_ci_runs_when_the_lock_is_new_or_changed_and_not_otherwise(tmp_path, monkeypatch):
    js = _package(tmp_path / "js", "1.0.0")
    stamp = js / "node_modules" / STAMP.name
    assert ensure_npm_packages(js) == js / "node_modules" and stamp.is_file()
    monkeypatch.setattr(prerequisites, "_installed", set())  # a new test run
    monkeypatch.setenv("PATH", str(tmp_path))  # no npm: up to date, so it is not needed
    ensure_npm_packages(js)
    (js / "package-lock.json").write_text((js / "package-lock.json").read_text().replace("1.0.0", "1.0.1"))
    monkeypatch.setattr(prerequisites, "_installed", set())
    with pytest.raises(pytest.fail.Exception) as failed:  # stale: npm is needed, and missing
        ensure_npm_packages(js)
    assert str(failed.value) == f"npm is not installed (the FHIR checkers in {js} need it): sudo apt-get install npm"
    monkeypatch.undo()
    monkeypatch.setattr(prerequisites, "_installed", set())
    ensure_npm_packages(js)  # with npm again: installed from the new lock
    assert stamp.read_text().strip() == prerequisites._lock_hash(js)


def test_a_missing_debian_package_is_one_line_naming_it(tmp_path):
    with pytest.raises(pytest.fail.Exception) as failed:
        require_debian("espeak-ng", command="no-such-command-here")
    assert (
        str(failed.value)
        == "no-such-command-here is not installed: sudo apt-get install espeak-ng (.ci/run installs it)"
    )
    with pytest.raises(pytest.fail.Exception):
        require_debian("chromium", path=str(tmp_path / "chromium"))
    require_debian("coreutils", command="ls")  # present: nothing happens
