"""Is the whole body in the picture? The set-up check before a Timed Up and Go (at the chair and at
the 3 m line), and what a camera picture of a person must show for the analysis to use it.

MediaPipe places the hips with 0.98 visibility even when the legs are out of the picture (measured;
docs/tug.md), so the check asks for the knees, ankles and heels too, seen and inside the picture.
"""

from __future__ import annotations

from collections.abc import Sequence

from kiosk.core.tug.landmarks import INDEX, Landmark
from kiosk.core.tug.signals import MARGIN, SEEN

#: the parts a whole body shows, each by its two sides (one side seen is enough: a side view hides one)
PARTS = ("shoulder", "hip", "knee", "ankle", "heel")


def missing_parts(landmarks: Sequence[Landmark] | None) -> list[str]:
    """The parts of the body not seen inside the picture (empty when the whole body is), or
    ``["person"]`` when nobody was found."""
    if landmarks is None:
        return ["person"]
    missing = []
    for part in PARTS:
        sides = (landmarks[INDEX[f"left_{part}"]], landmarks[INDEX[f"right_{part}"]])
        if not any(_inside(point) for point in sides):
            missing.append(part + "s")
    return missing


def _inside(point: Landmark) -> bool:
    x, y, _, visibility = point
    return visibility >= SEEN and -MARGIN <= x <= 1 + MARGIN and -MARGIN <= y <= 1 + MARGIN


def framing_problem(landmarks: Sequence[Landmark] | None) -> str:
    """One sentence for staff setting the camera up, or "" when the whole body is in the picture."""
    missing = missing_parts(landmarks)
    if not missing:
        return ""
    if missing == ["person"]:
        return "nobody in the picture"
    return f"not the whole body: no {', '.join(missing)} in the picture; move the camera back or tilt it"
