"""The Timed Up and Go from pose landmarks: the file format, the analysis, and a generator of
sequences with known times. Pure: no threads, no camera, no files (the command reads them).

Names load on first use: the camera channel's status is read before the kiosk's welcome, and the
analysis' numpy must not be (docs/startup.md)."""

from typing import TYPE_CHECKING

from basis.lazy import lazy_names

__all__ = [
    "FORMAT",
    "PHASES",
    "Phase",
    "PoseFileError",
    "PoseFrame",
    "PoseSequence",
    "TugAnalysis",
    "analyse",
    "parse_pose_text",
]

_ANALYSIS = "kiosk.core.tug.analysis"
_LANDMARKS = "kiosk.core.tug.landmarks"
__getattr__, __dir__ = lazy_names(
    globals(),
    {
        "PHASES": _ANALYSIS,
        "Phase": _ANALYSIS,
        "TugAnalysis": _ANALYSIS,
        "analyse": _ANALYSIS,
        "FORMAT": _LANDMARKS,
        "PoseFileError": _LANDMARKS,
        "PoseFrame": _LANDMARKS,
        "PoseSequence": _LANDMARKS,
        "parse_pose_text": _LANDMARKS,
    },
    __all__,
)

if TYPE_CHECKING:
    from kiosk.core.tug.analysis import PHASES, Phase, TugAnalysis, analyse
    from kiosk.core.tug.landmarks import FORMAT, PoseFileError, PoseFrame, PoseSequence, parse_pose_text
