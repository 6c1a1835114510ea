"""The camera channel: a camera's frames in, MediaPipe Pose's 33 landmarks and the patient's
presence out, off the UI thread. Beside :mod:`kiosk.speech` and :mod:`kiosk.remote`.

The public interface (others build on it): :class:`FrameSource` (pictures in), :class:`PoseEstimator`
(33 landmarks ``[x, y, z, visibility]`` or None), :class:`Presence` (person seen / not seen,
debounced) and :class:`CameraChannel` (an input source wiring them on a worker thread, calling
``on_pose`` with a :class:`PoseReading` per frame and ``on_presence`` on each change).
:func:`camera_status` says, without opening anything, whether this kiosk can see.
"""

from __future__ import annotations

from collections.abc import Callable

from kiosk.camera.channel import CameraChannel, PoseReading, PoseRecorder
from kiosk.camera.frames import CameraInfo, CameraUnavailable, Frame, FrameSource, OpenCvCamera, list_cameras
from kiosk.camera.pose import MediapipePose, ModelUnavailable, PoseEstimator, model_problem
from kiosk.camera.presence import Presence
from kiosk.core.channels import Channel, ChannelState, ChannelStatus, PresenceSource, Sink
from kiosk.core.channels import Presence as PresenceReport

__all__ = [
    "CameraChannel",
    "CameraInfo",
    "CameraUnavailable",
    "Frame",
    "FrameSource",
    "MediapipePose",
    "ModelUnavailable",
    "OpenCvCamera",
    "PoseEstimator",
    "PoseReading",
    "PoseRecorder",
    "Presence",
    "camera_channel",
    "camera_status",
    "list_cameras",
    "presence_reports",
]


def camera_status() -> ChannelStatus:
    """The camera channel as this machine allows it, before anything is opened: off with the
    reason (no camera, no pose model), or connecting (the channel will open the first camera)."""
    cameras = list_cameras()
    if not cameras:
        return ChannelStatus(Channel.CAMERA, ChannelState.OFF, "camera", "no camera found; the kiosk runs without one")
    problem = model_problem()
    if problem:
        return ChannelStatus(Channel.CAMERA, ChannelState.OFF, "camera", problem)
    return ChannelStatus(Channel.CAMERA, ChannelState.CONNECTING, "camera", f"will use {cameras[0].device}")


def camera_channel(
    on_pose: Callable[[PoseReading], None] | None = None, on_presence: Callable[[bool], None] | None = None
) -> CameraChannel | None:
    """The channel on this machine's first camera with MediaPipe Pose, or None when
    :func:`camera_status` says the camera is off."""
    if camera_status().state is ChannelState.OFF:
        return None
    device = list_cameras()[0].device
    return CameraChannel(lambda: OpenCvCamera(device), MediapipePose, on_pose=on_pose, on_presence=on_presence)


def presence_reports(sink: Sink) -> Callable[[bool], None]:
    """An ``on_presence`` listener that hands each debounced change to the session's sink as the
    core's presence report (called on the camera's thread; the sink posts to the UI thread)."""

    def report(seen: bool) -> None:
        detail = "in front of the camera" if seen else "nobody in front of the camera"
        sink(PresenceReport(seen, PresenceSource.CAMERA, detail))

    return report
