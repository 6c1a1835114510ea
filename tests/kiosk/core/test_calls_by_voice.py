"""Never a false call (issue 33, part 3): a call for the doctor heard by voice is asked back
("Shall I call the nurse?") and made on Yes, on a second hearing or on the doctor's key; a pressed
call is made at once; every outcome is in the session log for staff."""

from __future__ import annotations

import pytest

from kiosk.core.channels import Channel, ChannelInput, Command
from kiosk.core.session import (
    ConfirmationAsked,
    DoctorCallAsked,
    DoctorCalled,
    DoctorCallNotConfirmed,
    IgnoreReason,
    InputIgnored,
    Prompt,
)
from kiosk.core.session.words import CALL_CONFIRM, CONFIRM_WORDS
from kiosk.store.database import Store

from .helpers import make_rig, started


def _heard(rig, detail: str = "call the nurse", confidence: float = 0.93) -> None:
    rig.session.handle(ChannelInput(Channel.VOICE, command=Command.CALL_DOCTOR, detail=detail, confidence=confidence))


def _asked(tmp_path=None, **kwargs):
    """A session with feeding open since 25, a call heard by voice at 30."""
    rig = started(store=Store.open(tmp_path / "data") if tmp_path else None, **kwargs)
    rig.run_until(25)
    rig.at(30)
    _heard(rig)
    return rig


def _log(rig) -> list[tuple[str, str]]:
    return [(e.kind, e.detail) for e in rig.session.store.session(rig.session.id).log]


def test_a_call_heard_by_voice_is_asked_back_and_made_on_yes(tmp_path):
    rig = _asked(tmp_path)
    assert not rig.session.halted and rig.of(DoctorCalled) == []
    (asked,) = rig.of(DoctorCallAsked)
    assert (asked.detail, asked.deadline) == ("call the nurse", 40)  # confirm_window_s: 10
    prompt = rig.of(Prompt)[-1]
    assert (prompt.kind, prompt.text, [o.label for o in prompt.options]) == (
        "call",
        "Shall I call the nurse?",
        ["Yes", "No"],
    )
    assert rig.session.snapshot().calling == "Shall I call the nurse?" and rig.session.listening
    assert rig.session.snapshot().prompt.key == "feeding"  # the screen under it keeps its question
    rig.at(33)
    rig.session.handle(ChannelInput(Channel.VOICE, option=1, detail="yes", confidence=0.9))
    assert rig.session.halted and rig.of(DoctorCalled)[-1].channel is Channel.VOICE
    assert rig.session.snapshot().calling is None
    assert [e for e in rig.session.trace if e["t"] >= 30] == [{"t": 33, "emit": ["CallingDoctor"]}]
    log = _log(rig)
    assert ("doctor_call_heard", "voice 'call the nurse' (confidence 0.93): asked before calling") in log
    assert ("doctor_call_confirmed", "voice 'call the nurse': yes by voice") in log
    assert ("call_doctor", "voice") in log  # the station's alert


def test_no_makes_no_call_and_the_question_goes_on_with_the_time_it_had(tmp_path):
    rig = _asked(tmp_path)
    rig.at(36)
    rig.session.handle(ChannelInput(Channel.TOUCH, option=2, detail="screen"))
    assert not rig.session.halted and rig.of(DoctorCalled) == []
    assert [(e.why, e.channel) for e in rig.of(DoctorCallNotConfirmed)] == [("declined", Channel.TOUCH)]
    prompt = rig.of(Prompt)[-1]
    assert (prompt.kind, prompt.key, prompt.repeat) == ("question", "feeding", True)
    assert rig.session.current_attempt == 1 and rig.session.remaining() == 25  # 55 - 30: the clock stood still
    assert not any("CallingDoctor" in e.get("emit", ()) for e in rig.session.trace)
    assert ("doctor_call_declined", "voice 'call the nurse': not called by touch") in _log(rig)
    rig.answer(3)
    assert rig.session.answers["feeding"].option == 3


def test_no_reply_makes_no_call_and_is_recorded_for_staff(tmp_path):
    rig = _asked(tmp_path)
    rig.run_until(40)
    assert not rig.session.halted and [e.why for e in rig.of(DoctorCallNotConfirmed)] == ["unanswered"]
    assert rig.session.current_attempt == 1 and rig.session.remaining() == 25
    assert ("doctor_call_unanswered", "voice 'call the nurse': not called") in _log(rig)


def test_a_call_said_twice_is_made():
    rig = _asked()
    rig.at(32)
    _heard(rig, "get the nurse", 0.81)
    assert rig.session.halted and rig.of(DoctorCalled)[-1].channel is Channel.VOICE


@pytest.mark.parametrize("channel", [Channel.KEYBOARD, Channel.REMOTE, Channel.TOUCH])
def test_a_pressed_call_is_made_at_once_and_also_answers_the_question(channel):
    rig = started()
    rig.run_until(25)
    rig.command(Command.CALL_DOCTOR, channel)
    assert rig.session.halted and rig.of(DoctorCallAsked) == []
    rig = _asked()
    rig.command(Command.CALL_DOCTOR, channel)
    assert rig.session.halted and rig.of(DoctorCalled)[-1].channel is Channel.VOICE


def test_an_unsure_spoken_yes_asks_for_a_press_and_the_press_calls():
    rig = _asked()
    rig.session.handle(ChannelInput(Channel.VOICE, option=1, detail="yes", confidence=0.65, needs_confirmation=True))
    assert not rig.session.halted and rig.of(InputIgnored)[-1].reason is IgnoreReason.UNSURE_REPLY
    assert rig.session.snapshot().calling == CALL_CONFIRM["en"][1]
    rig.session.handle(ChannelInput(Channel.KEYBOARD, option=1, detail="key 1"))
    assert rig.session.halted


def test_where_voice_is_failing_the_question_asks_for_a_press():
    rig = started()
    rig.run_until(25)
    rig.session.set_voice_available(False)
    _heard(rig)
    assert rig.session.snapshot().calling == CALL_CONFIRM["en"][1]
    rig.session.handle(ChannelInput(Channel.TOUCH, option=1, detail="screen"))
    assert rig.session.halted


def test_other_inputs_wait_until_the_question_is_answered():
    rig = _asked()
    rig.command(Command.PAUSE, Channel.VOICE)
    rig.command(Command.UNDO, Channel.VOICE)
    assert [e.reason for e in rig.of(InputIgnored)] == [IgnoreReason.CALL_ASKED] * 2
    assert not rig.session.paused
    rig.session.handle(ChannelInput(Channel.TOUCH, option=3, detail="screen"))  # not Yes or No
    assert rig.of(InputIgnored)[-1].reason is IgnoreReason.NO_SUCH_OPTION and "feeding" not in rig.session.answers
    rig.command(Command.REPEAT, Channel.VOICE)
    assert (rig.of(Prompt)[-1].kind, rig.of(Prompt)[-1].repeat) == ("call", True)


def test_a_call_heard_while_is_that_right_waits_leaves_the_answer_waiting():
    rig = started()
    rig.run_until(25)
    rig.session.handle(ChannelInput(Channel.VOICE, option=3, detail="independent", needs_confirmation=True))
    assert rig.of(ConfirmationAsked)
    _heard(rig)
    rig.session.handle(ChannelInput(Channel.VOICE, option=2, detail="no", confidence=0.9))
    assert rig.of(Prompt)[-1].kind == "confirm" and rig.session.snapshot().confirming == 3
    rig.session.handle(ChannelInput(Channel.TOUCH, option=1, detail="screen"))
    assert rig.session.answers["feeding"].option == 3


def test_after_a_pause_the_call_question_is_asked_again_not_the_item():
    rig = _asked()
    rig.session.pause()  # the clinician opened the staff screens
    rig.session.resume()
    prompt = rig.of(Prompt)[-1]
    assert (prompt.kind, prompt.repeat) == ("call", True) and rig.session.snapshot().calling
    rig.session.handle(ChannelInput(Channel.TOUCH, option=1, detail="screen"))
    assert rig.session.halted


def test_a_call_before_the_test_is_not_asked_back_nor_made():
    rig = make_rig()
    rig.session.welcome()
    _heard(rig)
    assert rig.of(DoctorCallAsked) == [] and rig.of(InputIgnored)[-1].reason is IgnoreReason.NOT_STARTED


@pytest.mark.parametrize("language", ["en", "es", "fr", "de"])
def test_the_question_is_asked_in_every_shipped_language(language):
    rig = started(language=language)
    rig.run_until(25)
    _heard(rig)
    prompt = rig.of(Prompt)[-1]
    assert prompt.text == CALL_CONFIRM[language][0] and prompt.language == language
    assert [o.label for o in prompt.options] == [label for label, _ in CONFIRM_WORDS[language].values()]
