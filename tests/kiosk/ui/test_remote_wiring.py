"""The app wired to a real serial remote: pyserial reads a pty that a simulated button box writes
to; the reader thread's statuses and presses reach the screen and the session through the app's
sink. Unplugging shows the remote as lost while touch keeps working."""

from __future__ import annotations

from dataclasses import replace

from textual.widgets import Label

from kiosk.core.channels import Channel, ChannelState
from kiosk.remote.profiles import load_profiles
from kiosk.remote.reconnect import Backoff
from kiosk.remote.serial import SerialRemote
from kiosk.ui.app import KIOSK_SIZE
from kiosk.ui.widgets.channel_board import REMOTE
from tests.kiosk.remote.boxes import PATIENCE, ButtonBox

from .helpers import settle, start_in_english, until_thread


async def test_a_serial_remote_answers_and_its_unplugging_shows(ui_kiosk, tmp_path):
    profile = replace(load_profiles().serial[0], port=str(tmp_path / "ttyUSB-ui*"))
    box = ButtonBox(tmp_path / "ttyUSB-ui0")
    kiosk = ui_kiosk(familiarisation=False, sources=[SerialRemote(profile, backoff=Backoff(0.01, 2, 0.05))])
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await until_thread(
            lambda: kiosk.app.board.state(REMOTE)[0] is ChannelState.ON, "the remote's reader thread", PATIENCE
        )
        await start_in_english(kiosk, pilot)
        kiosk.to_next_deadline()
        await settle(pilot, lambda: kiosk.session.current_attempt == 1)
        assert "remote" in str(kiosk.app.screen.query_one("#ways", Label).render())
        box.write(b"BTN 2\n")
        await until_thread(lambda: "feeding" in kiosk.session.answers, "the remote's reader thread", PATIENCE)
        answer = kiosk.session.answers["feeding"]
        assert (answer.option, answer.channel) == (2, Channel.REMOTE)

        box.unplug()
        await until_thread(
            lambda: kiosk.app.board.state(REMOTE)[0] is not ChannelState.ON, "the remote's reader thread", PATIENCE
        )
        await settle(pilot)
        # the patient's row of ways to answer no longer offers it; no device words on their screen
        assert "remote" not in str(kiosk.app.screen.query_one("#ways", Label).render())
        kiosk.to_next_deadline()
        await settle(pilot, lambda: kiosk.session.current_attempt == 1)
        await pilot.click("#answer-1")
        await settle(pilot, lambda: "bathing" in kiosk.session.answers)
