"""The Timed Up and Go from pose landmarks: the file format, the analysis, and a generator of
sequences with known times. Pure: no threads, no camera, no files (the command reads them)."""

from kiosk.core.tug.analysis import PHASES, Phase, TugAnalysis, analyse
from kiosk.core.tug.landmarks import FORMAT, PoseFileError, PoseFrame, PoseSequence, parse_pose_text

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
