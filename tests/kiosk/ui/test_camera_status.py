"""The camera on the clinician screen: started by the app after its first frame like the other
channels, it says there whether it sees, or why not; a kiosk without a camera runs as before."""

from __future__ import annotations

import numpy as np
from textual.widgets import Static

from kiosk.camera import CameraChannel, CameraUnavailable, Frame
from kiosk.ui.app import CLINICIAN_CHORD, KIOSK_SIZE

from .conftest import UI_PIN
from .helpers import screen_name, settle, start_in_english


class EndlessBlank:
    name = "blank"

    def read(self):
        return Frame(t=0.0, image=np.zeros((4, 4, 3), np.uint8))

    def close(self):
        pass


class NobodyThere:
    name = "nobody"

    def estimate(self, frame):
        return None

    def close(self):
        pass


def no_camera():
    raise CameraUnavailable("no camera found; the kiosk runs without one")


async def channels_line(kiosk, pilot, wanted: str) -> str:
    await pilot.press(CLINICIAN_CHORD, *UI_PIN, "enter")
    await settle(pilot, lambda: screen_name(kiosk) == "ClinicianHomeScreen")
    line = kiosk.app.screen.query_one("#channel-reasons", Static)
    await settle(pilot, lambda: wanted in str(line.render()))
    return str(line.render())


async def test_without_a_camera_the_clinician_reads_why_and_the_test_goes_on(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False, sources=[CameraChannel(no_camera, NobodyThere)])
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await start_in_english(kiosk, pilot)
        text = await channels_line(kiosk, pilot, "camera off")
        assert "camera off (no camera found; the kiosk runs without one)" in text


async def test_a_working_camera_shows_on(ui_kiosk):
    channel = CameraChannel(EndlessBlank, NobodyThere)
    kiosk = ui_kiosk(familiarisation=False, sources=[channel])
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await start_in_english(kiosk, pilot)
        assert "camera on" in await channels_line(kiosk, pilot, "camera on")
    channel.stop()
