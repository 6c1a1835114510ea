"""`kiosk run` as a fresh machine gets it: the real speaker, voice channel and remote sources, with
no audio device, microphone or remote attached here -- the kiosk starts a session anyway and says
which channels are off and why. Plus the command lines' answers to a user's mistakes."""

from __future__ import annotations

import asyncio
import threading
import time

from kiosk import cli
from kiosk.commands import run as kiosk_run
from kiosk.commands.run import build_app
from kiosk.core.channels import ChannelState
from kiosk.core.session import Phase
from kiosk.ui.app import KIOSK_SIZE
from kiosk.ui.serve import server as serve
from kiosk.ui.widgets.channel_board import CAMERA, REMOTE, VOICE_IN, VOICE_OUT

#: real threads probe real devices and load a speech model: allow them this long
PATIENCE_S = 30.0


async def test_a_fresh_kiosk_starts_a_session_with_whatever_channels_it_has(tmp_path):
    config = tmp_path / "config.yaml"
    config.write_text("data_dir: data\n")
    app, close = build_app(config_path=config)
    try:
        async with app.run_test(size=KIOSK_SIZE) as pilot:
            deadline = time.monotonic() + PATIENCE_S
            # every channel has said what it is (on, or off with a reason) -- whatever this machine has
            while time.monotonic() < deadline and not all(
                app.board.state(name)[0] is ChannelState.ON or app.board.state(name)[1]
                for name in (VOICE_OUT, VOICE_IN, REMOTE, CAMERA)
            ):
                await asyncio.sleep(0.05)  # waiting on real device threads, bounded by PATIENCE_S
            for name in (VOICE_OUT, VOICE_IN, REMOTE, CAMERA):
                state, reason = app.board.state(name)
                assert state is ChannelState.ON or reason, f"{name} is {state.value} without a reason"
            await pilot.press("1")
            await pilot.pause()
            assert app.session.phase is Phase.FAMILIARISATION
            assert type(app.screen).__name__ == "FamiliarisationScreen"
            assert app.controller.store.session(app.session.id).status == "running"
    finally:
        close()
    assert (tmp_path / "data" / "kiosk.sqlite3").stat().st_mode & 0o077 == 0


def test_kiosk_run_with_a_bad_configuration_says_where_and_exits_2(tmp_path, capsys):
    config = tmp_path / "config.yaml"
    config.write_text("data_dir: data\nclinician_pin: 12\n")
    assert kiosk_run.main(["--config", str(config)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"kiosk run: {config}:2:1: ") and "PIN" in err[0]


def test_kiosk_run_rejects_a_patient_id_that_looks_like_a_name(tmp_path, capsys):
    config = tmp_path / "config.yaml"
    config.write_text("data_dir: data\n")
    assert kiosk_run.main(["--config", str(config), "--patient", "Ann Smith"]) == 2
    assert capsys.readouterr().err.startswith("kiosk run: --patient 'Ann Smith' is not a pseudonymous id")
    assert not (tmp_path / "data").exists()  # refused before anything was opened


def test_kiosk_serve_listens_on_localhost_by_default_and_refuses_a_bad_port(capsys):
    args, rest = serve._parser().parse_known_args(["--data-dir", "/somewhere"])
    assert (args.host, args.port) == ("127.0.0.1", 8000)
    assert serve.build_command(rest).endswith("-m kiosk run --data-dir /somewhere")
    assert serve.main(["--port", "70000"]) == 2
    assert "between 1 and 65535" in capsys.readouterr().err


def test_kiosk_serve_refuses_a_mistyped_run_option_before_starting_a_server(capsys):
    results: list[int] = []
    # a server would block this thread serving; a refusal returns at once
    thread = threading.Thread(target=lambda: results.append(cli.main(["serve", "--prot", "8001"])), daemon=True)
    thread.start()
    thread.join(timeout=PATIENCE_S)
    assert not thread.is_alive(), "kiosk serve started a server"
    assert results == [2]
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [
        "kiosk serve: unrecognised arguments: --prot 8001 (neither `kiosk serve` nor `kiosk run` takes them)"
    ]


def test_kiosk_serve_refuses_a_run_option_without_its_value(capsys):
    assert serve.main(["--data-dir"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["kiosk serve: argument --data-dir: expected one argument"]


async def test_what_waits_for_the_first_frame_runs_once_the_welcome_is_drawn(tmp_path):
    config = tmp_path / "config.yaml"
    config.write_text("data_dir: data\n")
    app, close = build_app(config_path=config, voice=False, remote=False)
    seen: list[tuple[str, list[str]]] = []
    app.after_first_frame.append(
        lambda: seen.append((type(app.screen).__name__, [str(b.label) for b in app.screen.query("Button")]))
    )
    try:
        async with app.run_test(size=KIOSK_SIZE) as pilot:
            while not seen:
                await pilot.pause()
            await pilot.press("1")
            await pilot.pause()
    finally:
        close()
    assert len(seen) == 1  # once, not again for the next screens
    screen, buttons = seen[0]
    assert screen == "WelcomeScreen" and any("English" in label for label in buttons)


def test_kiosk_run_collects_garbage_again_once_the_welcome_is_drawn():
    kiosk_run.gc.disable()  # as kiosk run's main does before it builds the kiosk
    try:
        kiosk_run._collect_from_now_on()
        assert kiosk_run.gc.isenabled()
        assert kiosk_run.gc.get_freeze_count() > 0
    finally:
        kiosk_run.gc.unfreeze()
        kiosk_run.gc.enable()
