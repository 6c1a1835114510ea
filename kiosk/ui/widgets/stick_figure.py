"""The live preview of a Timed Up and Go's set-up: the pose landmarks drawn as a stick figure in
text, never a picture (nothing of it is stored; issue 34)."""

from __future__ import annotations

from collections.abc import Sequence

from kiosk.core.tug.landmarks import INDEX, Landmark
from kiosk.core.tug.signals import SEEN

#: the bones drawn, as pairs of landmark names
BONES = tuple(
    (f"{side}_{a}", f"{side}_{b}")
    for side in ("left", "right")
    for a, b in (
        ("shoulder", "elbow"),
        ("elbow", "wrist"),
        ("shoulder", "hip"),
        ("hip", "knee"),
        ("knee", "ankle"),
        ("ankle", "heel"),
    )
) + (("left_shoulder", "right_shoulder"), ("left_hip", "right_hip"))


def stick_figure(landmarks: Sequence[Landmark] | None, columns: int = 24, rows: int = 12) -> str:
    """The picture's frame ``columns`` x ``rows`` with the seen bones drawn (``*``), the head
    (``O``) and a border; "nobody in the picture" in the middle when there is no person."""
    grid = [[" "] * columns for _ in range(rows)]

    def cell(point: Landmark) -> tuple[int, int] | None:
        x, y, _, visibility = point
        if visibility < SEEN or not (0 <= x <= 1 and 0 <= y <= 1):
            return None
        return min(columns - 1, int(x * columns)), min(rows - 1, int(y * rows))

    if landmarks is None:
        text = "nobody in the picture"[:columns]
        start = max(0, (columns - len(text)) // 2)
        grid[rows // 2][start : start + len(text)] = list(text)
    else:
        for a, b in BONES:
            ends = cell(landmarks[INDEX[a]]), cell(landmarks[INDEX[b]])
            if ends[0] is not None and ends[1] is not None:
                for x, y in _line(ends[0], ends[1]):
                    grid[y][x] = "*"
        if (head := cell(landmarks[INDEX["nose"]])) is not None:
            grid[head[1]][head[0]] = "O"
    border = "+" + "-" * columns + "+"
    return "\n".join([border, *("|" + "".join(row) + "|" for row in grid), border])


def _line(a: tuple[int, int], b: tuple[int, int]) -> list[tuple[int, int]]:
    """The cells from ``a`` to ``b`` (both included), in as many steps as the longer side."""
    steps = max(abs(b[0] - a[0]), abs(b[1] - a[1]), 1)
    dx, dy = (b[0] - a[0]) / steps, (b[1] - a[1]) / steps
    return [(round(a[0] + dx * i), round(a[1] + dy * i)) for i in range(steps + 1)]
