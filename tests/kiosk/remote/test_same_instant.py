"""A press on the remote and a touch in the same instant: exactly one answer is recorded.

The remote is real (pyserial reading a pty the simulated button box writes to) and so is the
session. As in the app, the remote's reader thread never calls the session: its sink hands each
input to the session's thread (here a queue the test drains, as Textual's call_from_thread would),
where the touch arrives too. The simulated clock does not move between the two.
"""

from __future__ import annotations

import queue
from dataclasses import replace

import pytest

from kiosk.core.channels import Channel, ChannelInput, ChannelState, ChannelStatus
from kiosk.core.clock import SimClock
from kiosk.core.questionnaire import load_questionnaire
from kiosk.core.session import AnswerRecorded, AttemptOpened, IgnoreReason, InputIgnored, Session
from kiosk.remote.profiles import load_profiles
from kiosk.remote.reconnect import Backoff
from kiosk.remote.serial import SerialRemote

from .boxes import PATIENCE, ButtonBox


@pytest.fixture
def open_attempt():
    """A session on a simulated clock with the first question's first attempt open."""
    clock = SimClock()
    session = Session(load_questionnaire(), clock=clock, engine=None, patient_id="P-TEST", familiarisation=False)
    events = []
    session.subscribe(events.append)
    session.start()
    session.acknowledge()
    while not any(isinstance(e, AttemptOpened) for e in events):
        clock.advance(session.next_deadline() - clock.now())
        session.poll()
    return session, events


@pytest.mark.parametrize("first", ["remote", "touch"])
def test_remote_press_and_touch_at_the_same_instant_record_one_answer(tmp_path, open_attempt, first):
    session, events = open_attempt
    item = session.current_item
    at = session.now()
    ui_thread: queue.Queue = queue.Queue()  # what the app's sink posts to

    profile = replace(load_profiles().serial[0], port=str(tmp_path / "ttyUSB-test*"))
    box = ButtonBox(tmp_path / "ttyUSB-test0")
    remote = SerialRemote(profile, backoff=Backoff(0.01, 2, 0.05))
    remote.start(ui_thread.put)
    try:
        status = ui_thread.get(timeout=PATIENCE)
        assert isinstance(status, ChannelStatus) and status.state is ChannelState.ON
        touch = ChannelInput(Channel.TOUCH, option=3, detail="button 3")
        if first == "touch":
            ui_thread.put(touch)
        box.write(b"BTN 2\n")
        inputs = []
        while len(inputs) < 2:
            if first == "remote" and len(inputs) == 1:
                ui_thread.put(touch)
            inputs.append(ui_thread.get(timeout=PATIENCE))
        for received in inputs:  # the UI thread handles both, the clock still at the same instant
            session.handle(received)
    finally:
        remote.stop()
        box.unplug()

    assert session.now() == at
    assert [i.channel for i in inputs] == (
        [Channel.REMOTE, Channel.TOUCH] if first == "remote" else [Channel.TOUCH, Channel.REMOTE]
    )
    recorded = [e for e in events if isinstance(e, AnswerRecorded)]
    ignored = [e for e in events if isinstance(e, InputIgnored)]
    assert len(recorded) == 1 and len(ignored) == 1
    winner, loser = inputs
    assert (recorded[0].item_id, recorded[0].channel, recorded[0].option) == (item.id, winner.channel, winner.option)
    assert ignored[0].input == loser and ignored[0].reason is IgnoreReason.ALREADY_ANSWERED
    assert list(session.answers) == [item.id]
    assert session.answers[item.id].option == winner.option
