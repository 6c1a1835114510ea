"""The voice-activity detectors ``bench/asr.py`` compares, each inside the kiosk's endpointer
(same start run, hangovers, pre-roll and cut-off; only the speech/not-speech call per 30 ms frame
differs):

- ``energy``: the kiosk's own (:class:`kiosk.speech.audio.Endpointer`), level against a noise
  floor that keeps learning;
- ``webrtc``: webrtcvad's GMM detector (``uv pip install webrtcvad-wheels``), mode 3;
- ``silero``: silero-vad's ONNX model run by onnxruntime, without torch. The model ships in
  the ``silero-vad`` wheel, whose hard dependency on torch (~800 MB) keeps it out of the
  kiosk's dependencies; to measure it: ``uv pip install onnxruntime`` and
  ``pip download --no-deps silero-vad`` then unzip ``silero_vad/data/silero_vad.onnx`` and pass
  ``--silero-onnx PATH`` (or ``uv pip install --no-deps silero-vad``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from kiosk.speech.audio import SAMPLE_RATE, Endpointer, EndpointerSettings


class WebRtcEndpointer(Endpointer):
    """The endpointer with webrtcvad deciding speech per frame (the level floor still applies
    to the absolute minimum, so digital silence is never speech)."""

    def __init__(self, settings: EndpointerSettings | None = None, mode: int = 3) -> None:
        import webrtcvad

        super().__init__(settings)
        self._vad = webrtcvad.Vad(mode)

    def speech_in(self, frame: np.ndarray, level_db: float, starting: bool) -> bool:
        """webrtcvad's call on the 30 ms frame."""
        return level_db >= self.settings.min_speech_db and self._vad.is_speech(frame.tobytes(), SAMPLE_RATE)


def find_silero_onnx(path: str | None) -> Path:
    """The silero-vad ONNX model: ``path``, or the one inside an installed silero_vad package."""
    if path:
        return Path(path)
    import importlib.util

    spec = importlib.util.find_spec("silero_vad")
    if spec is None or spec.origin is None:
        raise FileNotFoundError("silero-vad is not installed: pass --silero-onnx (see bench/_vads.py)")
    return Path(spec.origin).parent / "data" / "silero_vad.onnx"


class SileroEndpointer(Endpointer):
    """The endpointer with silero-vad's speech probability per frame (onnxruntime, no torch).

    The model takes 512-sample windows with 64 samples of context and a recurrent state; the
    kiosk's 480-sample frames are re-cut into such windows as they arrive, and a frame takes
    the probability of the latest window. Start above ``threshold``, hold above ``threshold - 0.15``
    (silero's own recommendation).
    """

    WINDOW, CONTEXT = 512, 64

    def __init__(self, onnx: Path, settings: EndpointerSettings | None = None, threshold: float = 0.5) -> None:
        import onnxruntime

        super().__init__(settings)
        options = onnxruntime.SessionOptions()
        options.inter_op_num_threads = options.intra_op_num_threads = 1
        self._session = onnxruntime.InferenceSession(str(onnx), options, providers=["CPUExecutionProvider"])
        self._state = np.zeros((2, 1, 128), dtype=np.float32)
        self._buffer = np.zeros(self.CONTEXT, dtype=np.float32)
        self._probability = 0.0
        self.threshold = threshold

    def speech_in(self, frame: np.ndarray, level_db: float, starting: bool) -> bool:
        """silero's probability of the latest 32 ms window against the start/hold threshold."""
        self._buffer = np.concatenate([self._buffer, frame.astype(np.float32) / 32768.0])
        while len(self._buffer) >= self.CONTEXT + self.WINDOW:
            chunk = self._buffer[: self.CONTEXT + self.WINDOW][None, :]
            out, self._state = self._session.run(
                None, {"input": chunk, "state": self._state, "sr": np.array(SAMPLE_RATE, dtype=np.int64)}
            )
            self._probability = float(out[0][0])
            self._buffer = self._buffer[self.WINDOW :]
        threshold = self.threshold if starting else self.threshold - 0.15
        return level_db >= self.settings.min_speech_db and self._probability >= threshold


def endpointer_factory(name: str, silero_onnx: str | None = None):
    """A zero-argument factory of the named endpointer for :class:`VoiceChannel`."""
    if name == "energy":
        return Endpointer
    if name == "webrtc":
        return WebRtcEndpointer
    if name == "silero":
        onnx = find_silero_onnx(silero_onnx)
        return lambda: SileroEndpointer(onnx)
    raise ValueError(f"unknown voice-activity detector {name!r} (energy, webrtc, silero)")
