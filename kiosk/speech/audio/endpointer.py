"""The energy endpointer: where speech starts and ends in a stream of 30 ms frames."""

from __future__ import annotations

import math
from collections import deque

import numpy as np

from basis import record
from kiosk.speech.audio.pcm import FRAME_SAMPLES, SAMPLE_RATE, frame_level_db


@record
class EndpointerSettings:
    """How the endpointer decides where speech starts and ends."""

    #: a frame this loud (dBFS) or louder may be speech (a quiet speaker far from the
    #: microphone is about -45 dBFS; a microphone's own hiss about -70) ...
    min_speech_db: float = -55.0
    #: ... if it is also this far above the room's noise floor: to start an utterance ...
    margin_db: float = 9.0
    #: ... and to go on with one (hysteresis: the quiet ends of words still count)
    hold_margin_db: float = 6.0
    #: the noise floor is this percentile of the frame levels heard over the last
    #: ``floor_window_s``, in and out of speech: a steady fan is most of every window, an
    #: answer is not
    floor_percentile: float = 10.0
    floor_window_s: float = 3.0
    #: the room's noise also has a ceiling: this percentile of the levels heard outside
    #: utterances over the last ``floor_window_s`` (a fan's is within a dB of its floor; people
    #: talking nearby come and go, and theirs is 10-20 dB above it) ...
    ceiling_percentile: float = 90.0
    #: ... which a frame must pass by this much to start an utterance ...
    ceiling_margin_db: float = 2.0
    #: ... and by this much to go on with one
    ceiling_hold_db: float = 2.0
    #: this much continuous speech starts an utterance (short clicks do not)
    start_ms: int = 90
    #: this much quiet ends it while what was heard is not yet a whole answer: older speakers
    #: pause inside an answer ("needs ... help"), and the kiosk still replies inside the ~0.75 s
    #: that feels natural
    hangover_ms: int = 500
    #: this much quiet ends it once the recogniser's partial result is a whole phrase that
    #: nothing of another meaning continues (see :func:`kiosk.speech.grammar.final_phrases`):
    #: "independent" needs no half-second wait, and the reply comes well under 0.3 s
    complete_hangover_ms: int = 240
    #: audio kept from before the start, so the recogniser hears the first consonant
    preroll_ms: int = 300
    #: an utterance longer than this is cut (a radio, a conversation in the room)
    max_utterance_s: float = 10.0


class Endpointer:
    """Energy-based speech start/end detection against a noise floor that keeps learning.

    ``push(frame, complete)`` returns ``"start"``, ``"end"`` or ``None``; ``complete`` says
    whether what was heard so far is already a whole answer, which ends it after the shorter
    ``complete_hangover_ms``.

    The noise floor is a low percentile of the levels of the last few seconds, taken over
    every frame pushed, speech or not, and kept across utterances and mutes (:meth:`reset`
    forgets the speech in progress, not the room): a fan, even one switched on mid-answer,
    becomes the floor once it fills most of the window, so the utterance still ends.

    People talking nearby are not a floor: their level comes and goes 10-20 dB above its
    quietest moments. So the room also has a ceiling, a high percentile of the levels heard
    outside utterances, and speech must stand above both; a quiet room or a fan, whose ceiling
    lies within a dB or two of its floor, is endpointed by the floor alone. Until a whole
    window of the room has been heard (the microphone has just opened) an utterance longer than
    the window teaches the ceiling too, or talk heard as the microphone opens would start an
    utterance that no quiet could end.

    Energy rather than webrtcvad or silero-vad: they hear people talking as speech, so an
    answer in background talk never ends. Measurements and the detectors compared:
    docs/speech-tuning.md.
    """

    def __init__(self, settings: EndpointerSettings | None = None) -> None:
        self.settings = settings or EndpointerSettings()
        frame_ms = 1000 * FRAME_SAMPLES / SAMPLE_RATE
        #: voiced frames in a row that start an utterance
        self.start_frames = max(1, round(self.settings.start_ms / frame_ms))
        self._end_frames = max(1, round(self.settings.hangover_ms / frame_ms))
        self._complete_end_frames = max(1, round(self.settings.complete_hangover_ms / frame_ms))
        self._max_frames = round(self.settings.max_utterance_s * 1000 / frame_ms)
        self._levels: deque[float] = deque(maxlen=max(1, round(self.settings.floor_window_s * 1000 / frame_ms)))
        self.noise_db = -90.0
        #: the levels of the frames heard outside utterances, for the ceiling
        self._window = max(1, round(self.settings.floor_window_s * 1000 / frame_ms))
        self._room: deque[float] = deque(maxlen=self._window)
        self.ceiling_db = -90.0
        self.reset()

    def reset(self) -> None:
        """Forget any speech in progress (after a mute, or between questions); the room's
        noise floor is kept."""
        self.in_speech = False
        self._voiced_run = 0
        self._quiet_run = 0
        self._speech_frames = 0
        #: the room's level and ceiling as the utterance started, and the levels of its frames
        #: above that ceiling (see :attr:`speech_db`, :attr:`room_at_start_db`)
        self.room_at_start_db: float | None = None
        self._start_ceiling_db = -90.0
        self._loud: list[float] = []

    def is_voiced(
        self, level_db: float, margin_db: float | None = None, ceiling_margin_db: float | None = None
    ) -> bool:
        """Whether a frame at ``level_db`` stands ``margin_db`` out of the current noise floor and
        ``ceiling_margin_db`` above its ceiling (the start margins by default) as speech."""
        margin = self.settings.margin_db if margin_db is None else margin_db
        above = self.settings.ceiling_margin_db if ceiling_margin_db is None else ceiling_margin_db
        return level_db >= max(self.settings.min_speech_db, self.noise_db + margin, self.ceiling_db + above)

    def _learn(self, level_db: float) -> None:
        self._levels.append(max(level_db, -90.0))
        if len(self._levels) < self.start_frames * 3:
            # too little heard to know the room: a quiet one, so an answer spoken as the
            # microphone opens is heard from its first sound
            self.noise_db = -90.0
        elif len(self._levels) < self._window:
            # until a whole window is heard, the quietest frame so far: a fan running as the
            # microphone opens is learned within a third of a second
            self.noise_db = min(self._levels)
        else:
            self.noise_db = float(np.percentile(self._levels, self.settings.floor_percentile))
        if not self.in_speech or (len(self._room) < self._window and self._speech_frames >= self._window):
            # until a whole window of the room is known, an utterance longer than the window
            # counts too: a microphone opened in a noisy room starts an "utterance" on its first
            # frames, and an answer given as it opens is shorter than that
            self._room.append(max(level_db, -90.0))
            self._update_ceiling()

    def _update_ceiling(self) -> None:
        if len(self._room) >= self.start_frames * 3:
            self.ceiling_db = float(np.percentile(self._room, self.settings.ceiling_percentile))

    def speech_in(self, frame: np.ndarray, level_db: float, starting: bool) -> bool:
        """Whether ``frame`` (at ``level_db``) is speech: it stands out of the noise floor by
        the start margin (``starting``) or the hold margin. ``bench/asr.py`` overrides this to
        measure other voice-activity detectors in the same endpointer."""
        if starting:
            return self.is_voiced(level_db)
        return self.is_voiced(level_db, self.settings.hold_margin_db, self.settings.ceiling_hold_db)

    def push(self, frame: np.ndarray, complete: bool = False) -> str | None:
        """Classify one frame of :data:`FRAME_SAMPLES` samples; report a start or an end."""
        level = frame_level_db(frame)
        self._learn(level)
        if not self.in_speech:
            if self.speech_in(frame, level, starting=True):
                self._voiced_run += 1
                if self._voiced_run >= self.start_frames:
                    self.in_speech, self._quiet_run = True, 0
                    for _ in range(min(self._voiced_run, len(self._room))):
                        self._room.pop()  # the run that started it was speech, not the room
                    self._update_ceiling()
                    self._speech_frames = self._voiced_run
                    # the room as the patient began, and the run that started it (the last levels
                    # learned, all above min_speech_db), which is speech
                    self.room_at_start_db, self._start_ceiling_db = self.room_db, self.ceiling_db
                    run = list(self._levels)[-self._voiced_run :]
                    self._loud = [v for v in run if v >= self._start_ceiling_db]
                    return "start"
            else:
                self._voiced_run = 0
            return None
        self._speech_frames += 1
        self._quiet_run = 0 if self.speech_in(frame, level, starting=False) else self._quiet_run + 1
        end_frames = self._complete_end_frames if complete else self._end_frames
        if self._quiet_run >= end_frames or self._speech_frames >= self._max_frames:
            self.in_speech, self._voiced_run = False, 0
            return "end"
        if level >= self._start_ceiling_db:
            self._loud.append(level)
        return None

    @property
    def speech_db(self) -> float | None:
        """The level (dBFS, mean power) of the current or last utterance's frames that stood
        above the room's ceiling as it started (None: no such frame)."""
        if not self._loud:
            return None
        return 10 * math.log10(float(np.mean(np.power(10.0, np.asarray(self._loud) / 10))))

    @property
    def room_db(self) -> float | None:
        """The room's level (dBFS, mean power) over the frames heard outside utterances in the
        last ``floor_window_s``: a fan's, or people talking nearby. None until a third of a
        second of it has been heard (the microphone has just opened)."""
        if len(self._room) < self.start_frames * 3:
            return None
        power = float(np.mean(np.power(10.0, np.asarray(self._room) / 10)))
        return 10 * math.log10(max(power, 1e-10))

    @property
    def quiet_frames(self) -> int:
        """Quiet frames since the last voiced one while in speech (the hangover so far)."""
        return self._quiet_run

    @property
    def cut_off(self) -> bool:
        """Whether the last utterance ended at ``max_utterance_s`` rather than in quiet."""
        return self._speech_frames >= self._max_frames
