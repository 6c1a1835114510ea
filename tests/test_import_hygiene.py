"""The dependency arrows point one way: screens -> session -> qos. Neither the QoS engine nor the
session core may drag Textual in, so they run the same under the UI, in replays and in tests."""

from __future__ import annotations

import pkgutil
import subprocess
import sys

import pytest

import qos

#: the pure-Python parts of the kiosk (imported by module name; missing ones are an error)
PURE_KIOSK_MODULES = [
    "kiosk.core.channels",
    "kiosk.cli",
    "kiosk.core.clock",
    "kiosk.core.questionnaire",
    "kiosk.core.session",
    "kiosk.core.adaptation",
    "kiosk.store.database",
    "kiosk.commands.replay",
    "kiosk.config",
    "kiosk.export.opening",
    "kiosk.export",
    "kiosk.commands.results",
    "kiosk.commands.validate",
    "kiosk.ui.controller",
    "fileio.positions",
]


def _modules_of(package) -> list[str]:
    names = [package.__name__]
    names += [
        m.name
        for m in pkgutil.walk_packages(package.__path__, package.__name__ + ".")
        if not m.name.endswith("__main__")
    ]
    return names


def _imported_after(modules: list[str]) -> set[str]:
    code = (
        "import importlib, sys\n"
        f"for name in {modules!r}: importlib.import_module(name)\n"
        "print('\\n'.join(sorted(sys.modules)))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return set(out.stdout.split())


@pytest.mark.slow  # a subprocess
def test_qos_never_imports_textual_or_kiosk():
    loaded = _imported_after(_modules_of(qos))
    assert "textual" not in loaded
    assert not any(name == "kiosk" or name.startswith("kiosk.") for name in loaded)


@pytest.mark.slow  # a subprocess
def test_session_core_never_imports_textual():
    loaded = _imported_after(PURE_KIOSK_MODULES)
    assert "textual" not in loaded


@pytest.mark.slow  # a subprocess
def test_channels_never_import_textual():
    """Speech and remote readers run on their own threads: they hand inputs to a sink, never to widgets."""
    import kiosk.remote
    import kiosk.speech

    loaded = _imported_after(_modules_of(kiosk.speech) + _modules_of(kiosk.remote) + ["kiosk.commands.devices"])
    assert "textual" not in loaded
