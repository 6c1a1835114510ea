"""Audio in: microphones, WAV files, and an energy endpointer that cuts speech into utterances.

Everything the recogniser hears goes through one :class:`UtterancePipeline`: 16 kHz mono
16-bit PCM in, one :class:`Utterance` out per stretch of speech. A microphone
(:class:`MicrophoneStream`, PortAudio via sounddevice) and a WAV file (:func:`feed_wav`) feed the
same pipeline, which is how the tests and ``bench/asr.py`` exercise the real path without a
sound card. Times are positions in the audio stream (seconds of samples fed), not wall time, so
a file replays the same way every time.
"""

from __future__ import annotations

import logging
import math
import queue
import threading
import time
import wave
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

import numpy as np

log = logging.getLogger(__name__)

#: what every recogniser in the kiosk takes: 16 kHz, mono, signed 16-bit little-endian
SAMPLE_RATE = 16_000
#: the endpointer's analysis frame: 30 ms, a usual speech frame length
FRAME_SAMPLES = 480


class AudioUnavailable(RuntimeError):
    """Audio input cannot work on this machine; the message is one sentence for the UI."""


@dataclass(frozen=True)
class InputDevice:
    """One audio input as `kiosk devices` shows it."""

    index: int
    name: str
    #: PortAudio's default input: the one the kiosk uses unless configured otherwise
    default: bool
    #: the device's own default sample rate (the kiosk records at 16 kHz regardless)
    sample_rate: float
    #: whether 16 kHz mono 16-bit recording is accepted by the device
    usable: bool
    #: why not, when not usable
    reason: str = ""


def _sounddevice():
    """Import sounddevice, turning a missing PortAudio library into one clear sentence."""
    try:
        import sounddevice
    except OSError as exc:  # sounddevice raises OSError when libportaudio cannot be loaded
        raise AudioUnavailable(f"PortAudio is not installed (libportaudio2): {exc}") from None
    return sounddevice


def describe_input(info: dict, default_index: int, check: Callable[[int], None]) -> InputDevice:
    """Turn one of sounddevice's device dicts into an :class:`InputDevice`.

    ``check(index)`` raises if the device refuses 16 kHz mono int16 (sounddevice's
    ``check_input_settings``); its message becomes the reason.
    """
    try:
        check(info["index"])
        usable, reason = True, ""
    except Exception as exc:  # PortAudio reports every refusal as its own error type
        usable, reason = False, f"cannot record 16 kHz mono: {exc}"
    return InputDevice(
        index=info["index"],
        name=info["name"],
        default=info["index"] == default_index,
        sample_rate=float(info["default_samplerate"]),
        usable=usable,
        reason=reason,
    )


def list_input_devices() -> list[InputDevice]:
    """Every audio input PortAudio knows (empty on a machine without one).

    Raises :class:`AudioUnavailable` when PortAudio itself cannot be loaded.
    """
    sd = _sounddevice()

    def check(index: int) -> None:
        """Raise unless the device takes 16 kHz mono int16."""
        sd.check_input_settings(device=index, channels=1, dtype="int16", samplerate=SAMPLE_RATE)

    default_index = sd.default.device[0]
    return [describe_input(info, default_index, check) for info in sd.query_devices() if info["max_input_channels"] > 0]


def default_input_device() -> InputDevice:
    """The input the kiosk would record from, or :class:`AudioUnavailable` saying why none."""
    devices = [d for d in list_input_devices() if d.usable]
    if not devices:
        raise AudioUnavailable("no microphone found")
    return next((d for d in devices if d.default), devices[0])


# --- WAV files -------------------------------------------------------------------------------


def resample(samples: np.ndarray, rate: int, target: int = SAMPLE_RATE) -> np.ndarray:
    """Resample mono int16 audio to ``target`` Hz (windowed-sinc low-pass, then interpolation).

    Good enough for speech recognition, which ignores everything above ~7 kHz anyway; it keeps
    the kiosk free of a SciPy dependency.
    """
    if rate == target:
        return samples.astype(np.int16, copy=False)
    x = samples.astype(np.float64)
    if target < rate:  # remove what would alias above the new Nyquist frequency
        cutoff = 0.95 * (target / 2) / rate
        taps = np.arange(-32, 33)
        kernel = np.sinc(2 * cutoff * taps) * np.hamming(len(taps))
        x = np.convolve(x, kernel / kernel.sum(), mode="same")
    n = int(len(x) * target / rate)
    y = np.interp(np.arange(n) * (rate / target), np.arange(len(x)), x)
    return np.clip(np.round(y), -32768, 32767).astype(np.int16)


def read_wav(path: str | Path) -> np.ndarray:
    """A 16-bit PCM WAV file as 16 kHz mono int16 samples (channels averaged, resampled).

    Raises ``ValueError`` naming the file for anything else (8-bit, float, not a WAV).
    """
    try:
        with wave.open(str(path), "rb") as wav:
            if wav.getsampwidth() != 2:
                raise ValueError(f"{path}: {8 * wav.getsampwidth()}-bit WAV, expected 16-bit PCM")
            channels, rate = wav.getnchannels(), wav.getframerate()
            data = np.frombuffer(wav.readframes(wav.getnframes()), dtype="<i2")
    except (wave.Error, EOFError) as exc:
        raise ValueError(f"{path}: not a PCM WAV file ({exc})") from None
    if channels > 1:
        data = data.reshape(-1, channels).mean(axis=1).astype(np.int16)
    return resample(data, rate)


# --- endpointing -----------------------------------------------------------------------------


def frame_powers(samples: np.ndarray) -> np.ndarray:
    """Mean power of each whole 10 ms frame of int16 samples (int16 units squared): the frame
    rate of the recognisers' features and of :mod:`kiosk.speech.rooms`' levels."""
    x = samples.astype(np.float64)
    step = SAMPLE_RATE // 100
    return (x[: len(x) - len(x) % step].reshape(-1, step) ** 2).mean(axis=1)


def frame_level_db(frame: np.ndarray) -> float:
    """RMS level of int16 samples in dB relative to full scale (-100 for digital silence)."""
    if len(frame) == 0:
        return -100.0
    rms = math.sqrt(float(np.mean(frame.astype(np.float64) ** 2))) / 32768.0
    return max(-100.0, 20 * math.log10(rms)) if rms > 0 else -100.0


@dataclass(frozen=True)
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
    forgets the speech in progress, not the room). An earlier floor that learned only while
    nobody spoke, and was reset after every prompt, never learned a fan louder than its fixed
    speech threshold: every frame was "speech" and every utterance ran to the cut-off.
    Here a fan switched on mid-answer becomes the floor once it fills most of the window, so
    even then the utterance ends within ``floor_window_s``.

    People talking nearby are not a floor: their level comes and goes 10-20 dB above its
    quietest moments, and with the floor alone an answer in background talk went on until the
    talkers paused (bench/asr.py's dev voices, 78 answers at SNR 10 dB: 17 ran to the 10 s
    cut-off, 30 more ended over a second after the words, 25 ended in time). So the room also
    has a ceiling, a high percentile of the levels heard outside utterances, and speech must
    stand above both: with it 0 ran to the cut-off and 70 ended in time (20 dB: 71 of 79, 5 dB:
    72 of 80), and a quiet room or a fan, whose ceiling lies within a dB or two of its floor,
    is endpointed as before. Right answers in background talk at SNR 10 dB went from 0.15 to
    0.42 (dev voices, 10 cases each). Until a whole window of the room has been heard (the
    microphone has just opened) an utterance longer than the window teaches the ceiling too, or
    talk heard as the microphone opens would start an utterance that no quiet could end.

    Chosen by measurement against webrtcvad (mode 3) and silero-vad's ONNX model in this same
    endpointer (``bench/asr.py --vad X --voices dev --cases 10``, 8 voices, 80 utterances per
    condition, with the ceiling): right answers clean 0.81 for all three, white noise at SNR
    10 dB energy 0.65, webrtc 0.67, silero 0.67, none run to the cut-off; in babble at SNR
    10 dB energy 0.48 with no cut-off, webrtc and silero 0.02 with 223 cut-offs each (people
    talking are speech to both detectors, so the answer never ends). silero-vad's wheel
    requires torch (~800 MB) and webrtcvad a compiled extension, for no gain anywhere.
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
        self._room: deque[float] = deque(maxlen=self._levels.maxlen)
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
        elif len(self._levels) < self._levels.maxlen:
            # until a whole window is heard, the quietest frame so far: a fan running as the
            # microphone opens is learned within a third of a second
            self.noise_db = min(self._levels)
        else:
            self.noise_db = float(np.percentile(self._levels, self.settings.floor_percentile))
        if not self.in_speech or (len(self._room) < self._room.maxlen and self._speech_frames >= self._room.maxlen):
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


# --- the pipeline ----------------------------------------------------------------------------


class StreamingRecogniser(Protocol):
    """What the pipeline needs from a recogniser (see :mod:`kiosk.speech.asr`)."""

    def reset(self) -> None:
        """Start a new utterance."""

    def accept(self, pcm: bytes) -> object:
        """Take more audio of the current utterance; may return a partial result whose
        ``complete`` attribute says it is already a whole answer."""

    def finish(self) -> object:
        """End the utterance and return the final result."""


@dataclass(frozen=True)
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


class PcmConsumer(Protocol):
    """Anything that takes 16 kHz mono int16 audio: a pipeline, a voice channel."""

    def feed(self, pcm: bytes) -> None:
        """Take more audio."""


def feed_wav(path: str | Path, pipeline: PcmConsumer, chunk_ms: int = 100) -> float:
    """Play a WAV file into ``pipeline`` as a microphone would deliver it; returns its length (s).

    The file is followed by a second of silence, as a room falls quiet after an answer, so the
    endpointer can close the last utterance.
    """
    samples = read_wav(path)
    feed_samples(np.concatenate([samples, np.zeros(SAMPLE_RATE, dtype=np.int16)]), pipeline, chunk_ms)
    return len(samples) / SAMPLE_RATE


def feed_samples(samples: np.ndarray, pipeline: PcmConsumer, chunk_ms: int = 100) -> None:
    """Feed 16 kHz mono int16 samples into ``pipeline`` in microphone-sized chunks."""
    pcm = samples.astype("<i2", copy=False).tobytes()
    step = 2 * SAMPLE_RATE * chunk_ms // 1000
    for offset in range(0, len(pcm), step):
        pipeline.feed(pcm[offset : offset + step])


class MicrophoneStream:
    """Records 16 kHz mono int16 from a PortAudio input into a pipeline (or a voice channel,
    which locks around it), on its own thread.

    PortAudio's callback only queues the audio; a worker thread runs the pipeline (and so the
    recogniser), which must never block the audio callback.
    """

    def __init__(self, pipeline: PcmConsumer, device: int | None = None) -> None:
        self.pipeline = pipeline
        self.device = device
        self._queue: queue.Queue[bytes | None] = queue.Queue()
        self._stream = None
        self._worker: threading.Thread | None = None

    def start(self) -> None:
        """Open the input and start feeding; :class:`AudioUnavailable` if there is none."""
        sd = _sounddevice()
        device = self.device if self.device is not None else default_input_device().index
        try:
            self._stream = sd.RawInputStream(
                samplerate=SAMPLE_RATE,
                channels=1,
                dtype="int16",
                blocksize=FRAME_SAMPLES,
                device=device,
                callback=self._on_audio,
            )
            self._stream.start()
        except Exception as exc:  # PortAudio errors: busy device, unplugged, refused format
            raise AudioUnavailable(f"cannot open microphone {device}: {exc}") from None
        self._worker = threading.Thread(target=self._drain, name="kiosk-microphone", daemon=True)
        self._worker.start()

    def _on_audio(self, indata, frames, time_info, status) -> None:
        if status:
            log.debug("audio input status: %s", status)
        self._queue.put(bytes(indata))

    def _drain(self) -> None:
        while (chunk := self._queue.get()) is not None:
            self.pipeline.feed(chunk)

    def stop(self) -> None:
        """Close the input and stop the worker; safe to call twice."""
        if self._stream is not None:
            self._stream.stop()
            self._stream.close()
            self._stream = None
        if self._worker is not None:
            self._queue.put(None)
            self._worker.join(timeout=2)
            self._worker = None
