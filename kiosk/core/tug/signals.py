"""Per-frame body signals of a pose sequence, in units that do not depend on the camera's place.

Every length is in torso lengths (shoulder midpoint to hip midpoint, in pixels): a torso's image is
vertical whatever way the patient faces, so the ratios below hold for a side, oblique or frontal
view and for either walking direction. Frames without a usable body hold NaN; :func:`fill_gaps` and
:func:`smooth` make the series the analysis reads. Pure numpy, deterministic.
"""

from __future__ import annotations

import numpy as np

from basis import record
from kiosk.core.tug.landmarks import INDEX, PoseSequence

#: a landmark counts as seen at this visibility or above (MediaPipe's own drawing threshold is 0.5)
SEEN = 0.5
#: how far outside the image (in image fractions) a landmark may lie and still count as in it
MARGIN = 0.01
#: the focal length assumed, in image widths: a 64-degree horizontal field, a webcam's usual one;
#: only distances walked (out and back) depend on it, and only as thresholds
FOCAL_WIDTHS = 0.8

_SHOULDERS = (INDEX["left_shoulder"], INDEX["right_shoulder"])
_HIPS = (INDEX["left_hip"], INDEX["right_hip"])
#: the lower body, by pairs: a frame sees the legs when one of each pair is seen inside the image
_LOWER_PAIRS = (
    (INDEX["left_knee"], INDEX["right_knee"]),
    (INDEX["left_ankle"], INDEX["right_ankle"]),
    (INDEX["left_heel"], INDEX["right_heel"]),
)


@record
class Signals:
    """Aligned arrays, one value per frame (NaN where the frame gives none)."""

    t: np.ndarray
    #: a person was found and shoulders and hips are usable
    person: np.ndarray
    #: knees, ankles and heels seen inside the image (one of each pair)
    legs: np.ndarray
    #: the torso's length in pixels
    torso: np.ndarray
    #: ankle height - hip height in the picture (pixels): divided by the torso measured at the chair,
    #: where the distance to the camera does not change, about 1.0 seated and 1.7 standing; not by
    #: each frame's torso, which a forward lean toward the camera shortens
    lift: np.ndarray
    #: shoulder midpoint (x, y) in pixels
    shoulder: np.ndarray
    #: the trunk's angle from upright (radians), from the picture and the model's depth: a frontal
    #: view sees a lean toward the camera only in depth (z), a side view in x
    lean: np.ndarray
    #: where the hips are, in torso lengths: across the image and away from the camera
    across: np.ndarray
    depth: np.ndarray
    #: left minus right shoulder: across the image (torso lengths) and in depth (model's z, same scale)
    shoulder_dx: np.ndarray
    shoulder_dz: np.ndarray


def body_signals(sequence: PoseSequence) -> Signals:
    """The :class:`Signals` of every frame of ``sequence``."""
    count = len(sequence.frames)
    width, height = float(sequence.width), float(sequence.height)
    points = np.full((count, 33, 4), np.nan)
    for number, frame in enumerate(sequence.frames):
        if frame.landmarks is not None:
            points[number] = frame.landmarks
    t = np.array([frame.t for frame in sequence.frames], dtype=float)
    x, y = points[:, :, 0] * width, points[:, :, 1] * height
    z, seen = points[:, :, 2] * width, points[:, :, 3] >= SEEN
    inside = (points[:, :, 0] >= -MARGIN) & (points[:, :, 0] <= 1 + MARGIN)
    inside &= (points[:, :, 1] >= -MARGIN) & (points[:, :, 1] <= 1 + MARGIN)
    usable = seen & inside

    def middle(pair: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
        # both sides wherever they lie in the picture: a side seen less surely is still placed
        # near its place, and dropping it would jump the midpoint by half a body's width
        weight = (inside[:, pair] & np.isfinite(points[:, pair, 3])).astype(float)
        total = weight.sum(axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            mx = np.nansum(x[:, pair] * weight, axis=1) / total
            my = np.nansum(y[:, pair] * weight, axis=1) / total
        return mx, my

    sx, sy = middle(_SHOULDERS)
    hx, hy = middle(_HIPS)
    torso = np.hypot(sx - hx, sy - hy)
    person = np.isfinite(torso) & (torso > 1.0)
    person &= usable[:, _SHOULDERS].any(axis=1) & usable[:, _HIPS].any(axis=1)
    legs = person.copy()
    for pair in _LOWER_PAIRS:
        legs &= usable[:, pair].any(axis=1)
    ax, ay = middle((INDEX["left_ankle"], INDEX["right_ankle"]))
    heel_x, heel_y = middle((INDEX["left_heel"], INDEX["right_heel"]))
    ay = np.where(np.isfinite(ay), ay, heel_y)
    ax = np.where(np.isfinite(ax), ax, heel_x)
    with np.errstate(invalid="ignore", divide="ignore"):
        lift = np.where(legs, ay - hy, np.nan)
        across = np.where(person, (hx - width / 2) / torso, np.nan)
        depth = np.where(person, FOCAL_WIDTHS * width / torso, np.nan)
        left, right = _SHOULDERS
        both = person & usable[:, left] & usable[:, right]
        shoulder_dx = np.where(both, (x[:, left] - x[:, right]) / torso, np.nan)
        shoulder_dz = np.where(both, (z[:, left] - z[:, right]) / torso, np.nan)
    shoulder = np.where(person[:, None], np.stack([sx, sy], axis=1), np.nan)
    zs = z[:, _SHOULDERS].mean(axis=1) - z[:, _HIPS].mean(axis=1)
    lean = np.where(person, np.arctan2(np.hypot(sx - hx, zs), hy - sy), np.nan)
    return Signals(
        t=t,
        person=person,
        legs=legs,
        torso=np.where(person, torso, np.nan),
        lift=lift,
        shoulder=shoulder,
        lean=lean,
        across=across,
        depth=depth,
        shoulder_dx=shoulder_dx,
        shoulder_dz=shoulder_dz,
    )


def fill_gaps(t: np.ndarray, values: np.ndarray) -> np.ndarray:
    """``values`` with NaN runs replaced by straight lines between their neighbours (held flat
    before the first and after the last finite value); all NaN stays all NaN."""
    known = np.isfinite(values)
    if not known.any():
        return values.copy()
    return np.interp(t, t[known], values[known])


def smooth(values: np.ndarray, frames: int) -> np.ndarray:
    """A running median over ``frames`` (odd, at least 1) then a running mean over the same window,
    edges padded with the end values: the median drops landmark jumps, the mean the jitter."""
    if frames <= 1 or len(values) < 3:
        return values.copy()
    frames = min(frames | 1, (len(values) - 1) | 1)
    half = frames // 2
    padded = np.concatenate([np.full(half, values[0]), values, np.full(half, values[-1])])
    windows = np.lib.stride_tricks.sliding_window_view(padded, frames)
    median = np.median(windows, axis=1)
    padded = np.concatenate([np.full(half, median[0]), median, np.full(half, median[-1])])
    return np.convolve(padded, np.ones(frames) / frames, mode="valid")


def gaps(t: np.ndarray, present: np.ndarray) -> list[tuple[float, float]]:
    """The (start, end) times of the runs of frames without ``present``, between present frames."""
    found: list[tuple[float, float]] = []
    indices = np.flatnonzero(present)
    for before, after in zip(indices[:-1], indices[1:]):
        if after - before > 1:
            found.append((float(t[before]), float(t[after])))
    return found


def crossing(t: np.ndarray, values: np.ndarray, level: float, start: int, step: int) -> float | None:
    """The first time, walking from index ``start`` by ``step`` (+1 or -1), where ``values`` passes
    ``level`` (from the side ``values[start]`` is on), interpolated between the two frames; None if never."""
    below = values[start] < level
    index = start
    while 0 <= index + step < len(values):
        nxt = index + step
        if (values[nxt] < level) != below:
            a, b = values[index], values[nxt]
            share = 0.0 if b == a else (level - a) / (b - a)
            return float(t[index] + share * (t[nxt] - t[index]))
        index = nxt
    return None


def index_at(t: np.ndarray, time: float) -> int:
    """The index of the last frame at or before ``time`` (0 when before the first)."""
    return max(0, int(np.searchsorted(t, time, side="right")) - 1)
