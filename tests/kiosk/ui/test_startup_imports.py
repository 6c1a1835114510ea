"""The welcome comes first: what the first screen does not need is not imported before it is drawn
(issue 24, part 8; the time it takes is measured by bench/startup.py, never here).

Each check runs a fresh interpreter, as `kiosk run` starts, so modules other tests loaded do not hide
an import; it is the kiosk's second start, the first having filled its cache (the QoS grammar's
tables, the parsed QoS model, the questionnaire's passed schema check, the parsed YAML files: fileio.cache)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from typing import Any

import pytest

pytestmark = pytest.mark.slow  # fresh interpreters

#: loaded only when staff open a result, export, plot, or the kiosk talks to a station
NOT_BEFORE_THE_WELCOME = (
    # every export: the store is opened with the site's identity (kiosk.core.site), results are
    # exported later; a continued test reads its captured questionnaire when it is continued
    "kiosk.export",
    "kiosk.core.review",
    "kiosk.ui.screens.session_detail",
    "kiosk.ui.screens.clinician_home",
    "kiosk.ui.widgets.metrics_plot",
    # the patient's later screens and their widgets load when first shown (kiosk.ui.stage)
    "kiosk.ui.screens.familiarisation",
    "kiosk.ui.screens.explanation",
    "kiosk.ui.screens.question",
    "kiosk.ui.screens.summary",
    "kiosk.ui.screens.paused",
    "kiosk.ui.screens.doctor_called",
    "kiosk.ui.screens.out_of_order",
    "kiosk.ui.screens.visit_ready",
    "kiosk.ui.screens.pin",  # when staff ask for the PIN pad
    "kiosk.ui.widgets.keypad",  # with the PIN pad or the visit code pad
    "kiosk.ui.widgets.answer_button",
    "kiosk.ui.widgets.change_answer",
    "kiosk.ui.widgets.confirm_panel",
    "kiosk.ui.widgets.question_panel",
    "kiosk.sync",
    "kiosk.commands.devices",
    "kiosk.commands.pin",
    "kiosk.commands.qos",
    "kiosk.commands.replay",
    "kiosk.commands.results",
    "kiosk.commands.validate",
    "qos.trace",
    "qos.parser",  # the QoS model is read back as kept at the last start (qos.kept)
    "qos.grammar",
    "lark",
    "jsonschema",
    # the remotes' readers: build_app makes them (from a checked profile file), the app starts them
    "serial",
    # the configuration, words, profiles and policy parsed at the last start are read back (fileio.positions)
    "yaml",
    "fileio.yamlfile",
    "plotext",
    "textual_plotext",
    "matplotlib",
    "numpy",
    "station",
    "starlette",
    "sqlalchemy",
)
#: the speech stack loads on the channels' own threads once the app runs, never while it is built
NOT_WHILE_BUILDING = (
    "numpy",
    "sounddevice",
    "vosk",
    "pocketsphinx",
    "kiosk.speech.asr",
    "kiosk.speech.audio",
    "serial",  # pyserial: on the serial remote's reader thread
    "hid",  # hidapi
)


def _run(tmp_path, body: str, more: str = "") -> dict[str, Any]:
    config = tmp_path / "config.yaml"
    config.write_text(f"data_dir: {tmp_path / 'data'}\n{more}")
    code = textwrap.dedent(
        f"""
        import asyncio, json, sys
        from pathlib import Path
        import kiosk.cli, qos.cli  # what `kiosk` imports before it dispatches to `run`
        from kiosk.commands.run import build_app
        from kiosk.ui.app import KIOSK_SIZE
        config = Path({str(config)!r})
        """
    ) + textwrap.dedent(body)
    env = dict(os.environ, XDG_CACHE_HOME=str(tmp_path / "cache"))
    for _start in ("first", "second"):
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, env=env)
        assert out.returncode == 0, out.stderr
    return json.loads(out.stdout.splitlines()[-1])


def test_the_welcome_is_drawn_before_exports_plots_and_the_station_are_imported(tmp_path):
    found = _run(
        tmp_path,
        """
        app, close = build_app(config_path=config, voice=False, remote=False)

        async def welcome():
            async with app.run_test(size=KIOSK_SIZE) as pilot:
                while not (type(app.screen).__name__ == "WelcomeScreen" and app.screen.query("Button")):
                    await pilot.pause()
                drawn = " ".join(str(b.label) for b in app.screen.query("Button"))
                return drawn, sorted(sys.modules)

        try:
            drawn, modules = asyncio.run(welcome())
        finally:
            close()
        print(json.dumps({"drawn": drawn, "modules": modules}))
        """,
    )
    assert "English" in str(found["drawn"])
    modules = set(found["modules"])
    early = sorted(
        m for m in modules if m.split(".")[0] in NOT_BEFORE_THE_WELCOME or m.startswith(NOT_BEFORE_THE_WELCOME)
    )
    assert early == []


#: a ward kiosk's client of the station is built after the welcome is drawn (issue 32, part 7)
NOT_BEFORE_A_WARD_WELCOME = ("kiosk.sync.client", "kiosk.sync.http", "kiosk.sync.orders", "kiosk.sync.outbox", "http")


def test_a_ward_kiosk_draws_its_welcome_before_it_imports_the_station_client(tmp_path):
    import socket

    with socket.socket() as sock:  # a port nothing listens on
        sock.bind(("127.0.0.1", 0))
        port = sock.getsockname()[1]
    station = f'station: {{url: "http://127.0.0.1:{port}", token: "t0123456789abcdef", kiosk_id: bed1}}\n'
    found = _run(
        tmp_path,
        """
        app, close = build_app(config_path=config, voice=False, remote=False)

        async def welcome():
            async with app.run_test(size=KIOSK_SIZE) as pilot:
                while not (type(app.screen).__name__ == "WelcomeScreen" and app.screen.query("Button")):
                    await pilot.pause()
                early = sorted(sys.modules)
                while "kiosk.sync.client" not in sys.modules:  # started once the welcome is drawn
                    await pilot.pause()
                return early, type(app.controller.sync.station).__name__

        try:
            early, station = asyncio.run(welcome())
        finally:
            close()
        print(json.dumps({"early": early, "station": station}))
        """,
        more=station,
    )
    assert found["station"] == "Station"
    assert sorted(m for m in found["early"] if m.split(".")[0] == "http" or m in NOT_BEFORE_A_WARD_WELCOME) == []


def test_building_the_kiosk_with_voice_and_remotes_loads_no_speech_stack(tmp_path):
    found = _run(
        tmp_path,
        """
        app, close = build_app(config_path=config)
        try:
            loaded = sorted(sys.modules)
            voice = type(app.channels.voice).__name__
        finally:
            close()
        print(json.dumps({"voice": voice, "modules": loaded}))
        """,
    )
    assert found["voice"] == "VoiceChannel"  # the channel is there: it loads its stack when started
    modules = set(found["modules"])
    assert sorted(m for m in modules if m.split(".")[0] in NOT_WHILE_BUILDING or m in NOT_WHILE_BUILDING) == []
