"""The camera channel's readings reach a Timed Up and Go step through a feed: the channel runs on
its own thread, the step is fed on the test's, and the generated patient is timed."""

from __future__ import annotations

import pytest

from kiosk.camera import CameraChannel
from kiosk.camera.feed import PoseFeed
from kiosk.core.clock import SimClock
from kiosk.core.tug.families import generate
from kiosk.core.tug.step import TugStep
from tests.kiosk.camera.test_channel import WAIT_S, Replayed, Stills


def test_a_patient_seen_by_the_channel_is_timed_by_the_step():
    sequence, truth = generate("normal", 21)
    assert truth.onset_t is not None and truth.seated_t is not None
    go_t = truth.onset_t - 0.5
    feed = PoseFeed()
    channel = CameraChannel(
        lambda: Stills([f.t for f in sequence.frames]), lambda: Replayed(sequence.frames), on_pose=feed
    )
    channel.start(lambda status: None)
    channel.join(WAIT_S)
    clock, published = SimClock(), []
    step = TugStep(clock, lambda t, values: published.append(dict(values)), walk_up=False)
    step.confirm_staff("nurse-7")
    assert feed.into(step, before=go_t) > 0 and step.framing == ""
    clock.set(go_t)
    step.go()
    assert feed.into(step) > 0 and feed.into(step) == 0
    analysis = step.finish()
    assert analysis.valid and analysis.total_s == pytest.approx(truth.seated_t - go_t, abs=0.3)
    assert {"PersonGetsUp": True, "PersonIsSeated": False} in published


def test_a_feed_not_drained_keeps_the_latest_readings():
    from kiosk.camera import PoseReading

    feed = PoseFeed(max_readings=3)
    for t in range(5):
        feed(PoseReading(t=float(t), width=64, height=48, landmarks=None))
    step = TugStep(SimClock(), lambda t, values: None, walk_up=False)
    assert feed.into(step) == 3
    assert step.framing == "nobody in the picture"
