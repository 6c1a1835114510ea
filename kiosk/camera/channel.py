"""The camera channel: frames in, landmarks and presence out, on a worker thread of its own.

:class:`CameraChannel` is an :class:`~kiosk.core.channels.InputSource` like the remotes: the app
starts it after its first frame is drawn, it opens the camera and loads the pose model on its own
thread (MediaPipe's import and model load take about a second), and reports what it can do as
:class:`~kiosk.core.channels.ChannelStatus` (camera off: no camera, no model). Each frame's
landmarks go to ``on_pose`` and presence changes to ``on_presence``, both called on the camera's
thread: a listener in the UI hands them over with ``call_from_thread``. Pictures are never kept.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import field

from basis import record
from kiosk.camera.frames import CameraUnavailable, FrameSource
from kiosk.camera.pose import ModelUnavailable, PoseEstimator
from kiosk.camera.presence import Presence
from kiosk.core.channels import Channel, ChannelState, ChannelStatus, Sink
from kiosk.core.tug.landmarks import Landmark, PoseFrame, PoseSequence


@record
class PoseReading:
    """One frame's result: its time, the picture's size, the landmarks or None (nobody found)."""

    t: float
    width: int
    height: int
    landmarks: tuple[Landmark, ...] | None = field(repr=False)


class CameraChannel:
    """``open_source`` and ``open_estimator`` are called on the channel's thread (they may raise
    :class:`CameraUnavailable` / :class:`ModelUnavailable`: the channel is then off, with why)."""

    def __init__(
        self,
        open_source: Callable[[], FrameSource],
        open_estimator: Callable[[], PoseEstimator],
        *,
        name: str = "camera",
        on_pose: Callable[[PoseReading], None] | None = None,
        on_presence: Callable[[bool], None] | None = None,
        presence: Presence | None = None,
    ) -> None:
        self.name = name
        self._open_source, self._open_estimator = open_source, open_estimator
        self.on_pose, self.on_presence = on_pose, on_presence
        self.presence = presence or Presence()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def start(self, sink: Sink) -> None:
        """Open the camera and the model and follow the frames, on a new thread."""
        if self._thread is not None:
            return
        self._thread = threading.Thread(target=self._run, args=(sink,), name=self.name, daemon=True)
        self._thread.start()

    def stop(self) -> None:
        """Stop following frames (the thread ends after the frame under way); safe to call twice."""
        self._stop.set()

    def join(self, timeout: float | None = None) -> None:
        """Wait for the channel's thread to end (tests and shutdown)."""
        if self._thread is not None:
            self._thread.join(timeout)

    def _status(self, sink: Sink, state: ChannelState, reason: str = "") -> None:
        sink(ChannelStatus(Channel.CAMERA, state, self.name, reason))

    def _run(self, sink: Sink) -> None:
        self._status(sink, ChannelState.CONNECTING, "opening the camera and the pose model")
        source: FrameSource | None = None
        estimator: PoseEstimator | None = None
        try:
            source = self._open_source()
            estimator = self._open_estimator()
        except (CameraUnavailable, ModelUnavailable) as error:
            self._status(sink, ChannelState.OFF, str(error))
            for opened in (source, estimator):
                if opened is not None:
                    opened.close()
            return
        self._status(sink, ChannelState.ON)
        try:
            self._follow(sink, source, estimator)
        finally:
            source.close()
            estimator.close()

    def _follow(self, sink: Sink, source: FrameSource, estimator: PoseEstimator) -> None:
        while not self._stop.is_set():
            try:
                frame = source.read()
            except CameraUnavailable as error:
                self._status(sink, ChannelState.LOST, str(error))
                return
            if frame is None:
                self._status(sink, ChannelState.LOST, "the camera stopped sending pictures")
                return
            landmarks = estimator.estimate(frame)
            width, height = frame.size
            if self.on_pose is not None:
                self.on_pose(PoseReading(t=frame.t, width=width, height=height, landmarks=landmarks))
            change = self.presence.feed(frame.t, landmarks is not None)
            if change is not None and self.on_presence is not None:
                self.on_presence(change)


class PoseRecorder:
    """An ``on_pose`` listener that keeps the landmarks (never the pictures) of a test, so that it
    can be analysed and, where a site turns it on, stored as a pose-landmarks/1 file."""

    def __init__(self, fps: float) -> None:
        self.fps = fps
        self._frames: list[PoseFrame] = []
        self._size = (0, 0)
        self._lock = threading.Lock()

    def __call__(self, reading: PoseReading) -> None:
        with self._lock:
            if self._frames and reading.t <= self._frames[-1].t:
                return
            self._size = (reading.width, reading.height)
            self._frames.append(PoseFrame(t=reading.t, landmarks=reading.landmarks))

    def sequence(self, go_t: float | None = None) -> PoseSequence:
        """What was recorded so far, with the moment the kiosk said "Go" (same clock as the frames)."""
        with self._lock:
            width, height = self._size
            return PoseSequence(fps=self.fps, width=width, height=height, go_t=go_t, frames=tuple(self._frames))
