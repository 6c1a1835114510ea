"""What voice in listens for on a prompt and what an utterance means there, without audio:
the rules the voice channel applies to every recognition (tests/kiosk/speech/test_voice.py hears
them end to end with real speech)."""

from __future__ import annotations

from kiosk.core.channels import Channel, Command
from kiosk.speech.asr import Recognition
from kiosk.speech.audio import Utterance
from kiosk.speech.listening import Listening
from kiosk.speech.matching import OptionWords
from kiosk.speech.voice import CONFIRM_BELOW, REPLY_MIN_ABOVE_ROOM_DB

OPTIONS = [OptionWords("independent", ()), OptionWords("needs help", ()), OptionWords("unable", ())]
YES_NO = [OptionWords("yes", ()), OptionWords("no", ())]


def _listening(confirm_below: float = CONFIRM_BELOW) -> Listening:
    return Listening(min_confidence=0.6, confirm_below=confirm_below, reply_min_above_room_db=REPLY_MIN_ABOVE_ROOM_DB)


def _said(text: str, confidence: float = 0.95, *, above_room_db: float | None = None) -> Utterance:
    """An utterance heard as ``text``; ``above_room_db`` sets how far the voice stood above the room."""
    levels = {} if above_room_db is None else {"speech_db": -40.0, "room_db": -40.0 - above_room_db}
    return Utterance(Recognition(text, confidence), 0.0, 0.5, 0.8, 0.01, **levels)


def test_nothing_is_listened_for_before_the_first_prompt_with_options():
    listening = _listening()
    assert listening.grammar("en") is None and listening.matcher is None


def test_every_answer_to_a_scored_question_is_asked_back_and_commands_are_not():
    listening = _listening()
    listening.set_question(OPTIONS, scored=True, welcome=False, key="feeding", confirming=False)
    assert "needs help" in listening.grammar("en") and not listening.taken_as_heard
    answer = listening.hear(_said("needs help", 0.99))
    assert (answer.channel, answer.option, answer.needs_confirmation) == (Channel.VOICE, 2, True)
    pause = listening.hear(_said("pause", 0.99))
    assert (pause.command, pause.needs_confirmation) == (Command.PAUSE, False)


def test_an_option_declined_is_left_out_on_that_question_and_heard_again_on_the_next():
    listening = _listening()
    listening.set_question(OPTIONS, scored=True, welcome=False, key="feeding", confirming=False)
    listening.declined("feeding", 1)
    listening.set_question(OPTIONS, scored=True, welcome=False, key="feeding", confirming=False)
    assert "independent" not in listening.grammar("en")
    listening.set_question(OPTIONS, scored=True, welcome=False, key="bathing", confirming=False)
    assert "independent" in listening.grammar("en")


def test_an_unsure_answer_heard_alike_twice_is_asked_back_and_once_is_not_taken():
    listening = _listening()
    listening.set_question(OPTIONS, scored=True, welcome=False, key="feeding", confirming=False)
    listening.grammar("en")
    first = listening.hear(_said("unable", 0.3))
    assert isinstance(first, str) and "unsure" in first
    second = listening.hear(_said("unable", 0.3))
    assert (second.option, second.needs_confirmation) == (3, True)


def test_a_yes_spoken_barely_above_the_room_is_sent_as_unsure():
    listening = _listening()
    listening.set_question(YES_NO, scored=False, welcome=False, key=None, confirming=True)
    listening.grammar("en")
    loud_room = listening.hear(_said("yes", 0.99, above_room_db=REPLY_MIN_ABOVE_ROOM_DB - 3))
    quiet_room = listening.hear(_said("yes", 0.99, above_room_db=REPLY_MIN_ABOVE_ROOM_DB + 20))
    assert (loud_room.option, loud_room.needs_confirmation) == (1, True)
    assert (quiet_room.option, quiet_room.needs_confirmation) == (1, False)


def test_after_an_answer_only_taking_it_back_is_heard_and_while_paused_only_commands():
    listening = _listening()
    listening.set_question(OPTIONS, scored=True, welcome=False, key="feeding", confirming=False)
    listening.expect_undo()
    listening.grammar("en")
    assert isinstance(listening.hear(_said("needs help", 0.99)), str)
    assert listening.hear(_said("no that's wrong", 0.99)).command is Command.UNDO
    assert listening.set_paused(True) and not listening.set_paused(True)
    listening.grammar("en")
    assert listening.hear(_said("continue", 0.99)).command is Command.RESUME
