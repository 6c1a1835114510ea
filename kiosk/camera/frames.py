"""Pictures in: the frame source interface, the cameras of this machine, and OpenCV's reader.

A :class:`FrameSource` hands out :class:`Frame` s (an RGB picture and its time in seconds on the
source's clock) until it has no more. :func:`list_cameras` only looks (Video4Linux device nodes and
their names): nothing is opened, so `kiosk devices` can run beside a running kiosk.
"""

from __future__ import annotations

import glob
import os
import re
import time
from dataclasses import field
from typing import TYPE_CHECKING, Any, Protocol

from basis import record
from basis.errors import KioskError

if TYPE_CHECKING:  # numpy loads with the model, on the camera's thread, not with the package
    import numpy as np

#: where Linux lists its video devices and their names
VIDEO_NODES = "/dev/video*"
VIDEO_NAMES = "/sys/class/video4linux"


@record
class Frame:
    """One picture: ``image`` height x width x 3, RGB, uint8; ``t`` seconds on the source's clock."""

    t: float
    image: np.ndarray = field(repr=False, compare=False)

    @property
    def size(self) -> tuple[int, int]:
        """(width, height) in pixels."""
        return int(self.image.shape[1]), int(self.image.shape[0])


class FrameSource(Protocol):
    """Where pictures come from: a camera, a recording, a still picture in a test."""

    name: str

    def read(self) -> Frame | None:
        """The next picture (blocking until it comes), or None when there are no more."""

    def close(self) -> None:
        """Release the device; safe to call twice."""


class CameraUnavailable(KioskError):
    """The camera cannot be opened or read; the message says why, for the clinician screen."""


@record
class CameraInfo:
    """One video device: its node (/dev/video0) and the name its driver gives."""

    device: str
    name: str


def list_cameras(nodes: str = VIDEO_NODES, names: str = VIDEO_NAMES) -> list[CameraInfo]:
    """The Video4Linux capture nodes of this machine, in number order (none on a machine without a camera)."""
    found = []
    for node in sorted(glob.glob(nodes), key=lambda path: int(re.sub(r"\D", "", path) or 0)):
        base = os.path.basename(node)
        try:
            with open(os.path.join(names, base, "name"), encoding="utf-8") as handle:
                name = handle.read().strip()
        except OSError:
            name = "unnamed"
        found.append(CameraInfo(device=node, name=name))
    return found


class OpenCvCamera:
    """A camera read through OpenCV (V4L2 on Linux), at ``width`` x ``height`` if it can; frames are
    timed by the monotonic clock. Opening is :meth:`open`, on the caller's (worker) thread."""

    def __init__(self, device: str | int = 0, *, width: int = 640, height: int = 480) -> None:
        self.name = f"camera {device}"
        self.device, self.width, self.height = device, width, height
        self._capture: Any = None

    def open(self) -> None:
        """Open the device; :class:`CameraUnavailable` when it cannot be."""
        try:
            import cv2
        except ImportError as error:
            raise CameraUnavailable(f"OpenCV is not installed ({error})") from None
        index = int(re.sub(r"\D", "", self.device)) if isinstance(self.device, str) else self.device
        capture = cv2.VideoCapture(index, cv2.CAP_V4L2)
        if not capture.isOpened():
            raise CameraUnavailable(f"cannot open {self.device}")
        capture.set(cv2.CAP_PROP_FRAME_WIDTH, self.width)
        capture.set(cv2.CAP_PROP_FRAME_HEIGHT, self.height)
        self._capture = capture

    def read(self) -> Frame | None:
        if self._capture is None:
            self.open()
        import cv2

        ok, picture = self._capture.read()
        if not ok:
            return None
        return Frame(t=time.monotonic(), image=cv2.cvtColor(picture, cv2.COLOR_BGR2RGB))

    def close(self) -> None:
        if self._capture is not None:
            self._capture.release()
            self._capture = None
