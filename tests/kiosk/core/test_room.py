"""The room (issue 33, part 5): voice failing in the room the kiosk stands in switches voice_room
on through the live adaptation's hysteresis, on the simulated clock with the real engine; the
measure is the kiosk's, so the next patient is steered to touch after fewer failures."""

from __future__ import annotations

from kiosk.core.adaptation import Adaptation, load_policy
from kiosk.core.channels import Channel, ChannelInput, Command
from kiosk.core.room import METRIC, START, RoomHearing
from kiosk.core.session import AdaptationChanged, IgnoreReason, InputIgnored, Prompt
from kiosk.store.database import Store

from .helpers import started


def _rig(room: RoomHearing, **kwargs):
    rig = started(adaptation=Adaptation(load_policy()), room=room, **kwargs)
    rig.run_until(25)  # feeding open
    return rig


def _misheard(rig) -> None:
    """A voice answer asked back and turned down ("I heard: Independent." - "No")."""
    rig.session.handle(ChannelInput(Channel.VOICE, option=3, detail="independent", needs_confirmation=True))
    rig.session.handle(ChannelInput(Channel.VOICE, option=2, detail="no", confidence=0.9))


def _switched(rig) -> list[tuple[str, bool]]:
    return [(e.name, e.active) for e in rig.of(AdaptationChanged)]


def test_the_measure_falls_with_failed_hearings_and_rises_with_good_ones():
    room = RoomHearing()
    assert room.value == START
    low = [room.add(False) for _ in range(3)]
    assert low == sorted(low, reverse=True) and low[-1] < 0.3
    assert room.add(True) > low[-1] and room.hearings == 4


def test_the_bundled_policy_watches_the_rooms_own_measure():
    rule = {r.name: r for r in load_policy().rules}["voice_room"]
    assert (rule.metric, rule.below, rule.count, rule.recover_above) == (METRIC, 0.4, 2, 0.6)


def test_two_failures_below_the_threshold_steer_the_patient_to_touch(tmp_path):
    store = Store.open(tmp_path / "data")
    rig = _rig(RoomHearing(), store=store)
    _misheard(rig)
    rig.session.voice_unheard("'banana' is not an answer or a command here")  # 0.37: the first low reading
    assert _switched(rig) == [] and rig.session.listening
    rig.session.voice_unheard("unsure recognition of 'two' (confidence 0.41 < 0.60)")
    assert _switched(rig) == [("voice_room", True)]
    assert not rig.session.listening
    assert rig.of(Prompt)[-1].key == "voice_off"  # "I am having trouble hearing you. Please touch ..."
    rig.session.handle(ChannelInput(Channel.VOICE, option=3, detail="independent"))
    assert rig.of(InputIgnored)[-1].reason is IgnoreReason.VOICE_OFF
    rig.session.handle(ChannelInput(Channel.TOUCH, option=3, detail="screen"))
    assert rig.session.answers["feeding"].option == 3
    stored = store.session(rig.session.id)
    assert [(a.name, a.active) for a in stored.adaptations] == [("voice_room", True)]
    assert "VoiceHeard 0.26 < 0.4 for 2 updates in a row" == stored.adaptations[0].reason


def test_a_hearing_that_worked_between_two_failures_resets_the_count():
    rig = _rig(RoomHearing(0.45))
    rig.session.voice_unheard("noise")  # 0.315: low once
    rig.session.handle(ChannelInput(Channel.VOICE, option=3, detail="independent"))  # stored: 0.52
    rig.clock.advance(20)
    rig.session.poll()
    rig.session.voice_unheard("noise")  # 0.36: low once again, not twice
    assert _switched(rig) == []


def test_the_room_is_remembered_for_the_next_patient():
    room = RoomHearing()
    first = _rig(room)
    _misheard(first)
    first.session.voice_unheard("noise")
    first.session.voice_unheard("noise")
    assert ("voice_room", True) in _switched(first)
    second = _rig(room)  # the next patient, at the same kiosk
    second.session.voice_unheard("noise")
    assert _switched(second) == []  # each patient gets a chance, but fewer of them
    second.session.voice_unheard("noise")
    assert _switched(second) == [("voice_room", True)]


def test_the_patient_asking_for_voice_again_lifts_it_and_no_voice_in_holds_it():
    rig = _rig(RoomHearing(0.3))
    rig.session.voice_unheard("noise")
    rig.session.voice_unheard("noise")
    assert _switched(rig) == [("voice_room", True)]
    rig.session.request_voice()
    assert _switched(rig)[-1] == ("voice_room", False) and rig.session.listening
    rig.session.voice_unheard("noise")
    rig.session.voice_unheard("noise")
    assert _switched(rig)[-1] == ("voice_room", True)
    rig.session.set_voice_available(False)
    assert _switched(rig)[-1] == ("voice_room", False)
    rig.session.voice_unheard("noise")
    rig.session.voice_unheard("noise")
    assert _switched(rig)[-1] == ("voice_room", False)  # no evidence counts without voice in


def test_calls_not_wanted_and_unsure_yeses_count_against_the_room():
    room = RoomHearing()
    rig = _rig(room)
    rig.session.handle(ChannelInput(Channel.VOICE, option=3, detail="independent", needs_confirmation=True))
    rig.session.handle(ChannelInput(Channel.VOICE, option=1, detail="yes", needs_confirmation=True))
    assert room.hearings == 1
    rig.session.handle(ChannelInput(Channel.TOUCH, option=1, detail="screen"))
    assert room.hearings == 2 and room.value > 0.5  # the voice answer was stored: it worked
    rig.clock.advance(20)
    rig.session.poll()
    rig.session.handle(ChannelInput(Channel.VOICE, command=Command.CALL_DOCTOR, detail="i need a doctor"))
    rig.session.handle(ChannelInput(Channel.TOUCH, option=2, detail="screen"))
    assert room.hearings == 3
