"""The patient is never locked out: "I'm fine, carry on" after call-doctor, the welcome listens for
"start", and after the end screen the kiosk goes back to the welcome for the next patient."""

from __future__ import annotations

from kiosk.core.channels import Channel, ChannelInput, Command
from kiosk.core.session import (
    DoctorCallCancelled,
    IgnoreReason,
    InputIgnored,
    ListeningChanged,
    NextPatient,
    Phase,
    Prompt,
)
from kiosk.store.database import Store

from .helpers import QUESTIONNAIRE, TIMING, make_rig, started


def test_im_fine_carry_on_ends_a_doctor_call_and_is_recorded(tmp_path):
    store = Store.open(tmp_path / "data")
    rig = started(store=store)
    rig.run_until(25)
    rig.at(30)
    rig.command(Command.CALL_DOCTOR, Channel.KEYBOARD)  # an accidental D
    assert rig.session.halted
    rig.session.handle(ChannelInput(Channel.VOICE, option=1, detail="i'm fine"))
    assert rig.of(InputIgnored)[-1].reason is IgnoreReason.DOCTOR_CALLED  # a misheard phrase never calls help off
    rig.session.handle(ChannelInput(Channel.KEYBOARD, option=2, detail="key 2"))
    assert rig.session.halted
    rig.at(34)
    rig.session.handle(ChannelInput(Channel.REMOTE, option=1, detail="BTN 1"))
    assert not rig.session.halted and rig.session.current_attempt == 1
    cancelled = rig.of(DoctorCallCancelled)[-1]
    assert cancelled.channel is Channel.REMOTE and cancelled.deadline == 34 + (55 - 30)  # the 25 s it had left
    assert (rig.of(Prompt)[-1].key, rig.of(Prompt)[-1].repeat) == ("feeding", True)
    assert rig.session.listening
    log = [(e.kind, e.detail) for e in store.session(rig.session.id).log]
    assert ("call_doctor", "keyboard") in log and ("doctor_call_cancelled", "remote") in log
    assert [e for e in rig.session.trace if e["t"] >= 30] == [
        {"t": 30, "emit": ["CallingDoctor"]},
        {"t": 34, "set": {"TestState": "RESTARTED"}},
    ]
    rig.session.cancel_doctor_call(Channel.TOUCH)
    assert rig.of(InputIgnored)[-1].reason is IgnoreReason.NOT_HALTED


def test_a_doctor_call_from_the_paused_screen_cancelled_goes_back_to_the_pause():
    rig = started()
    rig.run_until(25)
    rig.session.pause()
    rig.command(Command.CALL_DOCTOR)
    rig.session.cancel_doctor_call(Channel.TOUCH)
    assert rig.session.paused and not rig.session.halted
    assert rig.of(Prompt)[-1].key == "paused"
    rig.session.resume()
    assert rig.session.current_attempt == 1 and rig.session.listening


def test_the_welcome_listens_for_start_and_for_a_language_name():
    rig = make_rig()
    rig.at(1)
    rig.session.welcome()
    prompt = rig.of(Prompt)[-1]
    assert (prompt.kind, prompt.key, prompt.text) == ("welcome", "welcome", QUESTIONNAIRE.message("welcome", "en"))
    assert [o.label for o in prompt.options] == ["English", "Español", "Français", "Deutsch"]
    assert "start" in prompt.options[0].synonyms and "Spanish" in prompt.options[1].synonyms
    assert rig.session.listening and rig.of(ListeningChanged)[-1].listening
    rig.session.choose_language("fr")  # the welcome is said again, with French words
    again = rig.of(Prompt)[-1]
    assert again.kind == "welcome" and "commencer" in again.options[2].synonyms
    assert "anglais" in again.options[0].synonyms
    rig.at(3)
    rig.session.handle(ChannelInput(Channel.VOICE, option=2, detail="espagnol"))
    assert rig.session.phase is Phase.EXPLANATION and rig.session.language == "es"
    # the explanation listens for its Start ("estoy listo"), as its text promises by voice
    explanation = rig.of(Prompt)[-1]
    assert (explanation.key, [o.number for o in explanation.options]) == ("explanation", [1])
    assert "estoy listo" in explanation.options[0].synonyms and rig.session.listening
    rig.at(5)
    rig.session.handle(ChannelInput(Channel.VOICE, option=1, detail="estoy listo"))
    assert rig.session.phase is Phase.QUESTIONS
    assert not rig.session.listening  # nothing to hear before the first question opens


def test_after_the_end_screen_the_kiosk_is_ready_for_the_next_patient(tmp_path):
    store = Store.open(tmp_path / "data")
    rig = started(store=store, next_patient_after_s=90)
    for _ in QUESTIONNAIRE.items:
        rig.run_until(rig.session.next_deadline() - rig.session._origin)  # open the next item
        rig.answer(2)
    rig.run_until(rig.session.now() + TIMING["closing_s"])
    assert rig.session.finished and not rig.of(NextPatient)
    assert rig.of(Prompt)[-1].text == "Thank you, you are done. Please call the nurse."
    finished_at = rig.session.now()
    rig.command(Command.UNDO)  # too late to change anything
    assert rig.of(InputIgnored)[-1].reason is IgnoreReason.NOTHING_TO_UNDO
    rig.run_until(finished_at + 90)
    assert [e.t for e in rig.of(NextPatient)] == [finished_at + 90]
    assert rig.session.next_deadline() is None
    stored = store.session(rig.session.id)  # the result stays for staff
    assert stored.status == "finished" and len(stored.answers) == len(QUESTIONNAIRE.items)


def test_without_a_next_patient_delay_the_end_screen_stays():
    rig = started()
    for _ in QUESTIONNAIRE.items:
        rig.run_until(rig.session.next_deadline() - rig.session._origin)  # open the next item
        rig.answer(1)
    rig.run_until(rig.session.now() + TIMING["closing_s"])
    assert rig.session.finished and rig.session.next_deadline() is None
