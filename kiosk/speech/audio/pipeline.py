"""The pipeline: PCM in, one :class:`Utterance` out per stretch of speech, fed to a recogniser."""

from __future__ import annotations

import math
import time
from collections import deque
from collections.abc import Callable
from typing import Protocol

import numpy as np

from basis import record
from kiosk.speech.audio.endpointer import Endpointer, EndpointerSettings
from kiosk.speech.audio.pcm import FRAME_SAMPLES, SAMPLE_RATE


class StreamingRecogniser(Protocol):
    """What the pipeline needs from a recogniser (see :mod:`kiosk.speech.asr`)."""

    def reset(self) -> None:
        """Start a new utterance."""

    def accept(self, pcm: bytes) -> object:
        """Take more audio of the current utterance; may return a partial result whose
        ``complete`` attribute says it is already a whole answer."""

    def finish(self) -> object:
        """End the utterance and return the final result."""


@record
class Utterance:
    """One stretch of speech and what the recogniser made of it."""

    #: the recogniser's final result (a :class:`kiosk.speech.asr.Recognition`)
    result: object
    #: stream time (s) of the first voiced frame and of the last one
    speech_start: float
    speech_end: float
    #: stream time (s) the endpointer decided the utterance was over (speech_end + hangover)
    endpoint: float
    #: seconds of processor time the recogniser took for its final result after the endpoint
    #: (a measurement for ``bench/asr.py``; no decision depends on it)
    finish_seconds: float
    #: whether the utterance ended after the short hangover, its partial result being a whole answer
    complete: bool = False
    #: whether it ran to the endpointer's ``max_utterance_s`` instead of ending in quiet
    cut_off: bool = False
    #: the level (dBFS, mean power) of the utterance's frames that stood above the room's
    #: ceiling: the speaker's voice with whatever the room added to it (None: no such frame)
    speech_db: float | None = None
    #: the room's level as the utterance started (:attr:`Endpointer.room_db`; None: not known)
    room_db: float | None = None

    @property
    def above_room_db(self) -> float | None:
        """How far the speaker's voice stood above the room (dB): the speech's own power (its
        frames' power less the room's) over the room's. None where either is not known; a
        voice no louder than the room is -30."""
        if self.speech_db is None or self.room_db is None:
            return None
        speech, room = 10 ** (self.speech_db / 10), 10 ** (self.room_db / 10)
        return max(-30.0, 10 * math.log10(max(speech - room, room * 1e-3) / room))


class UtterancePipeline:
    """16 kHz PCM → endpointer → recogniser → one :class:`Utterance` per stretch of speech.

    Not thread-safe: one thread feeds it (the microphone worker, or the caller of
    :func:`feed_wav`). ``muted`` drops audio (the kiosk is talking) and forgets any
    utterance in progress.
    """

    def __init__(
        self,
        recogniser: StreamingRecogniser,
        on_utterance: Callable[[Utterance], None],
        settings: EndpointerSettings | None = None,
        timer: Callable[[], float] = time.perf_counter,
        endpointer: Endpointer | None = None,
    ) -> None:
        self.recogniser = recogniser
        self._timer = timer
        self.on_utterance = on_utterance
        self.endpointer = endpointer or Endpointer(settings)
        self._preroll: deque[bytes] = deque(
            maxlen=max(1, round(self.endpointer.settings.preroll_ms * SAMPLE_RATE / 1000 / FRAME_SAMPLES))
        )
        self._pending = b""
        self._samples = 0  # samples fed so far: the stream clock
        self._start = 0.0
        self._muted = False
        #: whether the recogniser's latest partial result is a whole answer
        self._complete = False

    @property
    def muted(self) -> bool:
        """Whether audio is currently being thrown away."""
        return self._muted

    @muted.setter
    def muted(self, value: bool) -> None:
        """Muting forgets the utterance in progress."""
        if value and not self._muted:
            self._drop_utterance()
        self._muted = value

    def _drop_utterance(self) -> None:
        self.endpointer.reset()
        self._complete = False
        self._preroll.clear()
        self._pending = b""
        self.recogniser.reset()

    @property
    def stream_time(self) -> float:
        """Seconds of audio fed so far."""
        return self._samples / SAMPLE_RATE

    def feed(self, pcm: bytes) -> None:
        """Take any amount of 16 kHz mono int16 audio."""
        if self._muted:
            self._samples += len(pcm) // 2
            return
        data = self._pending + pcm
        step = 2 * FRAME_SAMPLES
        whole = len(data) - len(data) % step
        self._pending = data[whole:]
        for offset in range(0, whole, step):
            self._frame(data[offset : offset + step])

    def _frame(self, chunk: bytes) -> None:
        self._samples += FRAME_SAMPLES
        event = self.endpointer.push(np.frombuffer(chunk, dtype="<i2"), self._complete)
        if event is None:
            if self.endpointer.in_speech:
                self._hear(chunk)
            else:
                self._preroll.append(chunk)
            return
        frame_s = FRAME_SAMPLES / SAMPLE_RATE
        if event == "start":
            # the run of voiced frames that triggered the start is already in the pre-roll
            self._start = self.stream_time - self.endpointer.start_frames * frame_s
            self.recogniser.reset()
            self._complete = False
            self._hear(b"".join(self._preroll) + chunk)
            self._preroll.clear()
            return
        # "end": the recogniser has heard the speech and the hangover; finish it now
        complete = self._complete
        self._hear(chunk)
        self._complete = False
        endpoint = self.stream_time
        began = self._timer()
        result = self.recogniser.finish()
        finish_seconds = self._timer() - began
        speech_end = endpoint - self.endpointer.quiet_frames * frame_s
        self.on_utterance(
            Utterance(
                result=result,
                speech_start=self._start,
                speech_end=speech_end,
                endpoint=endpoint,
                finish_seconds=finish_seconds,
                complete=complete,
                cut_off=self.endpointer.cut_off,
                speech_db=self.endpointer.speech_db,
                room_db=self.endpointer.room_at_start_db,
            )
        )

    def _hear(self, chunk: bytes) -> None:
        """Pass audio of the utterance to the recogniser and note whether it is a whole answer."""
        partial = self.recogniser.accept(chunk)
        self._complete = bool(getattr(partial, "complete", False))
