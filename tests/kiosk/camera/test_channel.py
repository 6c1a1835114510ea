"""The camera channel around its two interfaces: it reports off with the reason when the camera or
the model is missing, hands each frame's landmarks and each presence change to its listeners, and
records landmarks (never pictures) as a pose-landmarks sequence the analysis reads."""

from __future__ import annotations

import queue

import numpy as np

from kiosk.camera import (
    CameraChannel,
    CameraUnavailable,
    Frame,
    ModelUnavailable,
    PoseRecorder,
    Presence,
    presence_reports,
)
from kiosk.core.channels import Channel, ChannelState, ChannelStatus, PresenceSource
from kiosk.core.channels import Presence as PresenceReport
from kiosk.core.tug.families import generate
from kiosk.core.tug.landmarks import PoseFrame

WAIT_S = 60  # a guard against a hang, not a timing assertion


class Stills:
    """A frame source of blank pictures at the given times, then none."""

    name = "stills"

    def __init__(self, times):
        self.times, self.closed = list(times), False

    def read(self):
        return Frame(t=self.times.pop(0), image=np.zeros((48, 64, 3), np.uint8)) if self.times else None

    def close(self):
        self.closed = True


class Replayed:
    """A pose estimator that returns the landmarks of a generated sequence, frame by frame."""

    name = "replayed"

    def __init__(self, frames):
        self.frames = list(frames)

    def estimate(self, frame):
        return self.frames.pop(0).landmarks

    def close(self):
        pass


def run(channel):
    got: queue.Queue = queue.Queue()
    channel.start(got.put)
    channel.join(WAIT_S)
    items = []
    while not got.empty():
        items.append(got.get())
    return items


def test_no_camera_is_one_status_off_with_the_reason():
    def no_camera():
        raise CameraUnavailable("cannot open /dev/video0")

    statuses = run(CameraChannel(no_camera, lambda: Replayed([])))
    assert statuses[-1] == ChannelStatus(Channel.CAMERA, ChannelState.OFF, "camera", "cannot open /dev/video0")


def test_no_model_is_off_and_the_camera_is_released():
    source = Stills([0.0])

    def no_model():
        raise ModelUnavailable("the pose model is not installed")

    statuses = run(CameraChannel(lambda: source, no_model))
    assert statuses[-1].state is ChannelState.OFF and "not installed" in statuses[-1].reason
    assert source.closed


def test_each_frame_goes_to_the_listeners_and_a_generated_walk_is_recorded_whole():
    sequence, truth = generate("normal", 21)
    recorder = PoseRecorder(fps=sequence.fps)
    changes: list[bool] = []
    channel = CameraChannel(
        lambda: Stills([f.t for f in sequence.frames]),
        lambda: Replayed(sequence.frames),
        on_pose=recorder,
        on_presence=changes.append,
        presence=Presence(away_s=1.0, back_s=0.5),
    )
    statuses = run(channel)
    assert [s.state for s in statuses] == [ChannelState.CONNECTING, ChannelState.ON, ChannelState.LOST]
    assert statuses[-1].reason == "the camera stopped sending pictures"
    assert changes == [True]
    recorded = recorder.sequence(go_t=truth.go_t)
    assert (recorded.width, recorded.height) == (64, 48)
    assert [f.landmarks for f in recorded.frames] == [f.landmarks for f in sequence.frames]


def test_stop_ends_the_thread_between_frames():
    nobody = [PoseFrame(t=0.0, landmarks=None)] * 10**6
    channel = CameraChannel(lambda: Stills([i / 30 for i in range(10**6)]), lambda: Replayed(nobody))
    got: queue.Queue = queue.Queue()
    channel.start(got.put)
    assert got.get(timeout=WAIT_S).state is ChannelState.CONNECTING
    assert got.get(timeout=WAIT_S).state is ChannelState.ON
    channel.stop()
    channel.join(WAIT_S)
    assert not channel._thread.is_alive()


def test_a_patient_who_leaves_the_frame_reaches_the_session_as_away_then_back():
    """What the kiosk's session receives from the camera: a core presence report per debounced
    change, from the camera's thread, in the order the frames showed it."""
    sequence, _ = generate("normal", 3)
    person = sequence.frames[0].landmarks
    frames = [PoseFrame(t=i / 10, landmarks=None if 20 <= i < 60 else person) for i in range(90)]
    got: queue.Queue = queue.Queue()
    sink = got.put
    channel = CameraChannel(
        lambda: Stills([f.t for f in frames]),
        lambda: Replayed(frames),
        on_presence=presence_reports(sink),
        presence=Presence(away_s=1.0, back_s=0.5),
    )
    channel.start(sink)
    channel.join(WAIT_S)
    reports = []
    while not got.empty():
        item = got.get()
        if isinstance(item, PresenceReport):
            reports.append(item)
    assert [(r.seen, r.source) for r in reports] == [
        (True, PresenceSource.CAMERA),
        (False, PresenceSource.CAMERA),
        (True, PresenceSource.CAMERA),
    ]
    assert reports[1].detail == "nobody in front of the camera"
