"""A visit's Timed Up and Go through the real app (Pilot), issue 34 part 3.

The camera itself cannot run here: the frames come from a generated landmark file
(:mod:`kiosk.core.tug.families`) through the interfaces the camera uses, a
:class:`~kiosk.camera.CameraChannel` on its own thread with a frame source and a pose estimator,
into the :class:`~kiosk.camera.feed.PoseFeed` the kiosk drains. Time is the simulated clock; tests
wait on what is drawn or stored."""

from __future__ import annotations

import shutil
import threading

import numpy as np
import pytest

from kiosk.camera import CameraChannel, Frame
from kiosk.camera.feed import PoseFeed
from kiosk.config import InstrumentChoice
from kiosk.core.channels import ChannelState
from kiosk.core.session import Phase
from kiosk.core.tug.families import generate
from kiosk.core.tug.step import TugStage
from kiosk.ui.app import CLINICIAN_CHORD, KIOSK_SIZE
from kiosk.ui.widgets.channel_board import VOICE_OUT
from kiosk.ui.widgets.literal import Label, Static
from tests.kiosk.battery_instruments import write_mini

from .conftest import UI_PIN
from .helpers import drawn_text, screen_name, settle, text_of, until_thread
from .test_speaker_wiring import RecordingPlayer, SaidSpeaker

WAIT_S = 60  # a guard against a hang, not a timing assertion


class GatedFrames:
    """A frame source of blank pictures at a generated sequence's times, held until the test opens
    the gate with the clock's offset (the camera's clock is the kiosk's), then none."""

    name = "generated"

    def __init__(self, times):
        self.times, self.offset, self.gate = list(times), 0.0, threading.Event()

    def read(self):
        self.gate.wait(WAIT_S)
        return Frame(t=self.times.pop(0) + self.offset, image=np.zeros((48, 64, 3), np.uint8)) if self.times else None

    def close(self):
        pass


class Estimated:
    """A pose estimator giving the generated sequence's landmarks, frame by frame."""

    name = "generated"

    def __init__(self, frames):
        self.frames = list(frames)

    def estimate(self, frame):
        return self.frames.pop(0).landmarks

    def close(self):
        pass


async def open_staff(kiosk, pilot) -> None:
    await pilot.press(CLINICIAN_CHORD, *UI_PIN, "enter")
    await settle(pilot, lambda: screen_name(kiosk) == "TugStaffScreen")


async def touch(pilot, selector: str) -> None:
    """Touch a widget of the screen on top, scrolled into view first (as staff would page to it)."""
    await settle(pilot, lambda: bool(pilot.app.screen.query(selector)))
    pilot.app.screen.query_one(selector).scroll_visible(animate=False, immediate=True)
    await pilot.pause()
    await pilot.click(selector)


async def type_into(pilot, selector: str, text: str) -> None:
    await touch(pilot, selector)
    await pilot.press(*text)


async def answer_mini(kiosk, pilot) -> None:
    """Answer the running two-question instrument with 1s until it finishes."""
    session = kiosk.app.session
    await settle(pilot, lambda: session.phase in (Phase.EXPLANATION, Phase.QUESTIONS))
    if session.phase is Phase.EXPLANATION:
        await pilot.press("1")
    for _ in range(2):
        kiosk.to_next_deadline_of(session)
        await settle(pilot, lambda: session.current_attempt == 1)
        item = session.current_item
        await pilot.press("1")
        await settle(pilot, lambda: item.id in session.answers)
    kiosk.to_next_deadline_of(session)
    await settle(pilot, lambda: session.finished)


async def test_a_battery_with_a_tug_timed_by_the_camera(ui_kiosk, tmp_path):
    sequence, truth = generate("normal", 7)
    feed = PoseFeed()
    frames = GatedFrames([f.t for f in sequence.frames])
    camera = CameraChannel(lambda: frames, lambda: Estimated(sequence.frames), on_pose=feed)
    mini = write_mini(tmp_path)
    kiosk = ui_kiosk(
        instruments=(InstrumentChoice(str(mini), mini), InstrumentChoice("tug")),
        sources=[camera],
        poses=feed,
        patient="P-4711",
        familiarisation=False,
    )
    app = kiosk.app
    async with app.run_test(size=KIOSK_SIZE) as pilot:
        await settle(pilot, lambda: app.channels.camera_off() is None)  # the channel reported on
        app.controller.start_in("en")
        first = app.session
        await answer_mini(kiosk, pilot)
        await settle(pilot, lambda: screen_name(kiosk) == "TugScreen")
        await settle(pilot, lambda: "Part 2 of 2" in drawn_text(app) and "A short walking test" in drawn_text(app))
        run = app.controller.tugs.run
        assert run.timed_by_camera and first.battery.instruments == ("mini", "tug")
        # the camera's frames start now on the kiosk's clock
        frames.offset = kiosk.clock.now() - sequence.frames[0].t + 1.0
        frames.gate.set()
        camera.join(WAIT_S)
        await open_staff(kiosk, pilot)
        kiosk.advance(1.2)  # the first frames reach the set-up
        preview = app.screen.query_one("#tug-preview", Static)
        await settle(pilot, lambda: "O" in text_of(preview) and "*" in text_of(preview))
        assert "the whole body is in the picture" in text_of(app.screen.query_one("#tug-framing", Label))
        # no confirmation before both checks
        await type_into(pilot, "#tug-staff", "nurse-7")
        await touch(pilot, "#tug-confirm")
        await settle(pilot, lambda: "chair and at the 3 m line first" in text_of(app.screen.query_one("#tug-message")))
        await touch(pilot, "#tug-check-chair")
        await touch(pilot, "#tug-check-line")
        await settle(pilot, lambda: "at the 3 m line: whole body seen" in text_of(app.screen.query_one("#tug-checks")))
        await touch(pilot, "#tug-confirm")
        await settle(pilot, lambda: screen_name(kiosk) == "TugScreen" and run.stage is TugStage.READY)
        await settle(pilot, lambda: "When I say Go, stand up" in drawn_text(app))
        go_t = truth.onset_t - 0.5 + frames.offset
        kiosk.clock.set(go_t)
        await touch(pilot, "#tug-go")
        await settle(pilot, lambda: run.step.go_t == go_t)
        seen = set()
        last = sequence.frames[-1].t + frames.offset
        while run.stage is TugStage.RUNNING and kiosk.clock.now() < last + 5:
            kiosk.advance(0.25)
            await settle(pilot)
            seen.add(text_of(app.screen.query_one("#tug-phase", Static)))
        assert run.stage is TugStage.ANALYSED
        assert {"Walk to the line, turn, and come back.", "Sit down. Well done."} <= seen
        await settle(pilot, lambda: "will check the result" in drawn_text(app))
        await open_staff(kiosk, pilot)
        result = app.screen.query_one("#tug-result", Static)
        await settle(pilot, lambda: "the site's threshold (13.5 s)" in text_of(result))
        await touch(pilot, "#tug-rating-2")
        await touch(pilot, "#tug-aid-stick")
        await type_into(pilot, "#tug-decided-by", "dr-3")
        await touch(pilot, "#tug-accept")
        # the TUG was the visit's last step: the welcome for the next patient
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")

    (stored,) = kiosk.store.tug.all("P-4711")
    r = stored.result
    assert (r.decision, r.method, r.confirmed_by, r.decided_by) == ("accepted", "camera", "nurse-7", "dr-3")
    assert (r.get_up_go, r.walking_aid, r.threshold_s) == (2, "stick", 13.5)
    assert r.total_s == pytest.approx(truth.seated_t - (truth.onset_t - 0.5), abs=0.3)
    assert r.landmarks is None and stored.visit_id == first.battery.visit_id
    assert {p.name for p in r.phases} >= {"sit_to_stand", "walk_out", "turn", "walk_back", "turn_and_sit"}
    assert any(e["set"].get("PersonGetsUp") is True for e in first.out.trace)  # the contexts, in the visit's trace


async def test_without_a_camera_staff_time_it_by_stopwatch_before_the_first_instrument(ui_kiosk, tmp_path):
    mini = write_mini(tmp_path)
    kiosk = ui_kiosk(instruments=(InstrumentChoice("tug"), InstrumentChoice(str(mini), mini)), visits=True)
    app = kiosk.app
    async with app.run_test(size=KIOSK_SIZE) as pilot:
        await settle(pilot)
        assert app.controller.start_staff_visit("P-0815", "en", False) is None
        await settle(pilot, lambda: screen_name(kiosk) == "TugScreen")
        await settle(pilot, lambda: "Part 1 of 2" in drawn_text(app))
        await open_staff(kiosk, pilot)
        camera = text_of(app.screen.query_one("#tug-camera", Label))
        assert camera.startswith("Camera off (") and "stopwatch" in camera
        home = app.screen_stack[-2]  # the clinician home under it says so too
        assert "Timed Up and Go: no camera, so a stopwatch time or a skip" in text_of(
            home.query_one("#channel-reasons")
        )
        assert not app.screen.query_one("#tug-check-chair").display
        await type_into(pilot, "#tug-staff", "nurse-7")
        await touch(pilot, "#tug-confirm")
        await settle(pilot, lambda: screen_name(kiosk) == "TugScreen")
        await touch(pilot, "#tug-go")
        run = app.controller.tugs.run
        await settle(pilot, lambda: run.stage is TugStage.RUNNING)
        kiosk.advance(12.3)
        await settle(pilot, lambda: "12.3 s" in drawn_text(app))
        await touch(pilot, "#tug-stop")
        await settle(pilot, lambda: run.stage is TugStage.ANALYSED)
        await open_staff(kiosk, pilot)
        assert not app.screen.query_one("#tug-accept").display  # no camera time to accept
        await type_into(pilot, "#tug-decided-by", "nurse-7")
        await touch(pilot, "#tug-use-stopwatch")  # no time typed: said, nothing stored
        await settle(pilot, lambda: "a number of seconds" in text_of(app.screen.query_one("#tug-message")))
        assert kiosk.store.tug.all() == []
        await type_into(pilot, "#tug-stopwatch", "12,4")
        await touch(pilot, "#tug-use-stopwatch")
        # then the visit's questionnaire starts
        await settle(pilot, lambda: app.session.phase is not Phase.WELCOME and not app.controller.tug_busy)
        assert app.session.questionnaire.id == "mini" and app.session.battery.index == 1

    (stored,) = kiosk.store.tug.all("P-0815")
    r = stored.result
    assert (r.decision, r.method, r.total_s, r.camera_total_s) == ("stopwatch", "stopwatch", 12.4, None)
    assert "no frames: the camera saw nothing of the test" in r.reasons


async def test_staff_reject_a_run_or_skip_the_test_saying_why(ui_kiosk, tmp_path):
    mini = write_mini(tmp_path)
    kiosk = ui_kiosk(instruments=(InstrumentChoice("tug"), InstrumentChoice(str(mini), mini)), visits=True)
    app = kiosk.app
    async with app.run_test(size=KIOSK_SIZE) as pilot:
        await settle(pilot)
        app.controller.start_staff_visit("P-0816", "en", False)
        await settle(pilot, lambda: screen_name(kiosk) == "TugScreen")
        await open_staff(kiosk, pilot)
        await type_into(pilot, "#tug-staff", "nurse-7")
        await touch(pilot, "#tug-confirm")
        await settle(pilot, lambda: screen_name(kiosk) == "TugScreen")
        await touch(pilot, "#tug-go")
        kiosk.advance(4.0)
        await touch(pilot, "#tug-stop")
        await settle(pilot, lambda: app.controller.tugs.run.stage is TugStage.ANALYSED)
        await open_staff(kiosk, pilot)
        await type_into(pilot, "#tug-decided-by", "dr-3")
        await touch(pilot, "#tug-reject")
        await settle(pilot, lambda: not app.controller.tug_busy and app.session.phase is not Phase.WELCOME)
        app.controller.start_new_session()  # the next patient: a visit whose TUG staff skip
        await settle(pilot)
        app.controller.start_staff_visit("P-0817", "en", False)
        await settle(pilot, lambda: screen_name(kiosk) == "TugScreen")
        await open_staff(kiosk, pilot)
        await type_into(pilot, "#tug-staff", "nurse-7")
        await touch(pilot, "#tug-skip")  # no reason: refused
        await settle(pilot, lambda: "who skips it and why" in text_of(app.screen.query_one("#tug-message")))
        await type_into(pilot, "#tug-skip-reason", "cannot stand unaided today")
        await touch(pilot, "#tug-skip")
        await settle(pilot, lambda: not app.controller.tug_busy and app.session.phase is not Phase.WELCOME)

    rejected, skipped = (kiosk.store.tug.all(p)[0].result for p in ("P-0816", "P-0817"))
    assert (rejected.decision, rejected.total_s, rejected.decided_by, rejected.confirmed_by) == (
        "rejected",
        None,
        "dr-3",
        "nurse-7",
    )
    assert (skipped.decision, skipped.reasons, skipped.decided_by) == (
        "rejected",
        ("skipped: cannot stand unaided today",),
        "nurse-7",
    )


async def test_a_walk_up_visit_never_gives_the_tug(ui_kiosk, tmp_path):
    mini = write_mini(tmp_path)
    kiosk = ui_kiosk(instruments=(InstrumentChoice(str(mini), mini), InstrumentChoice("tug")), familiarisation=False)
    app = kiosk.app
    async with app.run_test(size=KIOSK_SIZE) as pilot:
        await settle(pilot)
        app.controller.start_in("en")
        assert app.session.visit == "walk-up" and app.session.battery is None  # a battery of one
        await answer_mini(kiosk, pilot)
        await settle(pilot, lambda: screen_name(kiosk) == "SummaryScreen")
        assert not app.controller.tug_busy
    assert kiosk.store.tug.all() == []


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("espeak-ng") is None, reason="espeak-ng is not installed")
async def test_the_instructions_and_go_are_said_in_the_patients_language(ui_kiosk, tmp_path):
    """The real espeak-ng speaker (the sound card stands in): Spanish words, said once each."""
    player = RecordingPlayer()
    speaker = SaidSpeaker(player_factory=lambda: player)
    mini = write_mini(tmp_path)
    kiosk = ui_kiosk(
        instruments=(InstrumentChoice("tug"), InstrumentChoice(str(mini), mini)), visits=True, speaker=speaker
    )
    app = kiosk.app
    async with app.run_test(size=KIOSK_SIZE) as pilot:
        await until_thread(lambda: app.board.state(VOICE_OUT)[0] is ChannelState.ON, "the speaker's worker")
        app.controller.start_staff_visit("P-0818", "es", False)
        await settle(
            pilot, lambda: "Una breve prueba de marcha" in drawn_text(app) and "Parte 1 de 2" in drawn_text(app)
        )
        played = player.played
        await open_staff(kiosk, pilot)
        await type_into(pilot, "#tug-staff", "nurse-7")
        await touch(pilot, "#tug-confirm")
        await settle(pilot, lambda: "Cuando diga Ya, levántese" in drawn_text(app))
        await touch(pilot, "#tug-go")
        await settle(pilot, lambda: "¡Ya!" in drawn_text(app))
        said = [text for text in speaker.said if text.startswith(("Cuando diga Ya", "¡Ya!"))]
        assert said == [
            "Cuando diga Ya, levántese, camine hasta la línea del suelo a su paso habitual, dé la vuelta, "
            "vuelva y siéntese otra vez. Use su ayuda para caminar si la usa normalmente.",
            "¡Ya!",
        ]
        await until_thread(lambda: player.played >= played + 2, "the speaker's worker")
