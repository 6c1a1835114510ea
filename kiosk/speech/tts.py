"""The kiosk's voice: questions read aloud by espeak-ng, in each language's voice (its words file).

All synthesis and playback happen on one worker thread. :class:`Speaker` reports when it
starts and stops talking (``on_speech(True/False)``) so the recogniser can be muted: the kiosk
must never take its own voice for an answer.

:class:`Synthesiser` runs the ``espeak-ng`` program once per phrase, with voice, rate and
volume passed per call, writing a WAV; a :class:`Player` plays it through PortAudio
(sounddevice), knowing when playback ends and able to stop it. (Why not pyttsx3:
docs/speech-tuning.md.)

Slower speech is pauses, not slower words. Speech around 150-200 words per minute was rated
most comfortable by older listeners, and slowing synthetic speech further made its words harder
to identify; full sentences are better than isolated words. So :func:`delivery` maps a
requested rate (the app asks for ``DEFAULT_RATE`` times the session's ``speech_rate``: 0.85 while
the ``slow_speech`` adaptation is on, 136 wpm) to:

- words spoken at ``max(MIN_RATE, rate)``, never below 150 wpm;
- the time the requested rate would have added, ``words * (60/rate - 60/MIN_RATE)`` seconds,
  placed as longer breaks where the sentence already pauses: after each sentence end (two
  shares) and comma (one share), on top of :data:`SENTENCE_BREAK_MS` / :data:`COMMA_BREAK_MS`
  (SSML ``<break>``, which replaces espeak-ng's own pause there). "Let me ask again. How do
  you manage eating your meals?" keeps its words whole and gains time between its sentences.

Not used: a gap between every word, which makes espeak-ng speak isolated words
(docs/speech-tuning.md); a prompt with no sentence end or comma inside is only slowed to 150 wpm.

A rate of 150 wpm or more is spoken as asked, with espeak-ng's own pauses.
"""

from __future__ import annotations

import contextlib
import logging
import os
import queue
import re
import shutil
import subprocess
import tempfile
import threading
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Protocol

from basis import record
from basis.errors import KioskError
from kiosk.core.channels import Channel, ChannelState, ChannelStatus
from kiosk.core.words import Table

if TYPE_CHECKING:  # numpy loads on the speaker's worker thread, not before the first screen
    import numpy as np

log = logging.getLogger(__name__)

#: espeak-ng voice per kiosk language (``language.voice`` in its words file)
VOICES: Mapping[str, str] = Table(lambda words: words.voice)
#: words per minute: older listeners rate 150-200 wpm most comfortable, slower is harder
DEFAULT_RATE = 160
#: words per minute never spoken slower than this: slower is made of pauses (see the docstring)
MIN_RATE = 150
#: a slowed prompt's break after a sentence end and after a comma before its share of the
#: added time (ms): about espeak-ng's own pauses there at 150 wpm, which a <break> replaces
SENTENCE_BREAK_MS, COMMA_BREAK_MS = 400, 150
#: volume as espeak-ng's amplitude / 100 (0-200 %): the patient steps it with louder/quieter
DEFAULT_VOLUME, VOLUME_STEP, MIN_VOLUME, MAX_VOLUME = 1.0, 0.25, 0.25, 2.0
#: how long one phrase may take to synthesise before voice out is declared broken
SYNTH_TIMEOUT_S = 30.0


class TtsUnavailable(KioskError, RuntimeError):
    """Voice out cannot work here; the message is one sentence for the UI."""


def _xml_text(text: str) -> str:
    """``text`` as SSML character data: ``&``, ``<`` and ``>`` escaped (html.escape without quotes,
    whose module brings the whole HTML entity table to a start)."""
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")


#: a sentence end or a comma followed by more words: where a slowed prompt pauses longer
_BOUNDARY = re.compile(r"([.?!;:,])(\s+)(?=\S)")


@record
class Delivery:
    """How espeak-ng says one phrase for a requested rate (see the module docstring)."""

    #: espeak-ng's -s: the words' own pace
    words_per_minute: int
    #: break after a sentence end and after a comma inside the phrase (ms); 0: espeak-ng's own
    sentence_break_ms: int = 0
    comma_break_ms: int = 0

    def markup(self, text: str) -> str:
        """``text`` as SSML with the breaks (escaped, so "<" or "&" are read as text)."""
        out, done = [], 0
        for m in _BOUNDARY.finditer(text):
            ms = self.comma_break_ms if m.group(1) == "," else self.sentence_break_ms
            out += [
                _xml_text(text[done : m.end(1)]),
                f'<break time="{ms}ms"/>' if ms else "",
                m.group(2),
            ]
            done = m.end()
        return f"<speak>{''.join(out)}{_xml_text(text[done:])}</speak>"


def delivery(rate: int, text: str) -> Delivery:
    """The :class:`Delivery` of ``text`` for a requested rate in words per minute: as asked from
    MIN_RATE up; below it words at MIN_RATE and the time the slower rate would take as pauses."""
    if rate >= MIN_RATE:
        return Delivery(rate)
    added_ms = 1000 * len(text.split()) * (60 / max(rate, 1) - 60 / MIN_RATE)
    marks = [m.group(1) for m in _BOUNDARY.finditer(text)]
    shares = sum(1 if mark == "," else 2 for mark in marks)
    if not shares:
        return Delivery(MIN_RATE)
    share = added_ms / shares
    return Delivery(MIN_RATE, round(SENTENCE_BREAK_MS + 2 * share), round(COMMA_BREAK_MS + share))


class Synthesiser:
    """espeak-ng, text → WAV file (22.05 kHz mono 16-bit). Thread-safe: one process per phrase."""

    def __init__(self) -> None:
        command = shutil.which("espeak-ng")
        if command is None:
            raise TtsUnavailable("espeak-ng is not installed")
        self._command = command
        listing = subprocess.run(
            [self._command, "--voices"], capture_output=True, text=True, timeout=SYNTH_TIMEOUT_S
        ).stdout
        # columns: Pty Language Age/Gender VoiceName File Other; File is the voice id
        available = {line.split()[4].lower() for line in listing.splitlines()[1:] if len(line.split()) > 4}
        self.languages = tuple(lang for lang, voice in VOICES.items() if voice in available)

    def synthesise(
        self, text: str, language: str, path: str | Path, rate: int = DEFAULT_RATE, volume: float = DEFAULT_VOLUME
    ) -> Path:
        """Speak ``text`` in ``language`` into the WAV file ``path`` at the requested ``rate``
        (words per minute, see :func:`delivery`)."""
        if language not in self.languages:
            raise TtsUnavailable(f"espeak-ng has no voice for language {language!r}")
        amplitude = str(int(round(volume * 100)))  # espeak-ng's 0-200 % amplitude
        how = delivery(rate, text)
        return self._run(text, VOICES[language], how.words_per_minute, amplitude, path, how.markup(text))

    def speak_as(self, text: str, voice: str, rate: int, path: str | Path) -> Path:
        """Say ``text`` with any espeak-ng voice ("en-us+f3", "en+croak", "roa/es+klatt") at
        exactly ``rate`` words per minute, slow or not, into ``path``: the many patients whose
        answers the tests and ``bench/asr.py`` feed to voice in, never the kiosk's own voice."""
        return self._run(text, voice, rate, "100", path, _xml_text(text))

    def _run(self, text: str, voice: str, rate: int, amplitude: str, path: str | Path, markup: str) -> Path:
        subprocess.run(
            [self._command, "-v", voice, "-s", str(rate), "-a", amplitude, "-m", "-w", str(path), "--", markup],
            check=True,
            capture_output=True,
            timeout=SYNTH_TIMEOUT_S,
        )
        if not _has_audio(path):
            raise TtsUnavailable(f"espeak-ng produced no audio for {text[:40]!r}")
        return Path(path)


def _has_audio(path: str | Path) -> bool:
    """Whether a WAV file holds any samples (a bare 44-byte header does not)."""
    return Path(path).is_file() and Path(path).stat().st_size > 44


class Player(Protocol):
    """Plays audio to the patient; ``play`` blocks until done or stopped."""

    def play(self, samples: np.ndarray, rate: int) -> None:
        """Play mono int16 samples at ``rate`` Hz and return when done or stopped."""

    def stop(self) -> None:
        """Cut the current playback short (called from another thread)."""


class PortAudioPlayer:
    """The default audio output through sounddevice."""

    def __init__(self) -> None:
        try:
            import sounddevice
        except OSError as exc:
            raise TtsUnavailable(f"PortAudio is not installed (libportaudio2): {exc}") from None
        if sounddevice.default.device[1] < 0 and not any(
            d["max_output_channels"] > 0 for d in sounddevice.query_devices()
        ):
            raise TtsUnavailable("no audio output found")
        self._sd = sounddevice

    def play(self, samples: np.ndarray, rate: int) -> None:
        """Play and wait (``sounddevice.wait`` returns early when :meth:`stop` is called)."""
        self._sd.play(samples, rate)
        self._sd.wait()

    def stop(self) -> None:
        """Stop sounddevice's current playback."""
        self._sd.stop()


@record(frozen=False)
class _Job:
    text: str
    language: str
    path: Path | None = None  # save here instead of playing
    done: threading.Event | None = None
    error: Exception | None = None
    #: the speaker's generation when queued: a later stop_speaking supersedes the phrase
    generation: int = 0


class Speaker:
    """Reads phrases aloud on a worker thread; the session calls :meth:`say` and returns at once.

    ``on_status`` receives one :class:`ChannelStatus` for voice out (ON, or OFF with the reason);
    ``on_speech(True)`` is called just before the kiosk starts talking and ``on_speech(False)``
    right after it stops, from the worker thread.
    """

    source = "espeak-ng"

    def __init__(
        self,
        on_status: Callable[[ChannelStatus], None] = lambda status: None,
        on_speech: Callable[[bool], None] = lambda speaking: None,
        player_factory: Callable[[], Player] = PortAudioPlayer,
        rate: int = DEFAULT_RATE,
    ) -> None:
        self.on_status = on_status
        self.on_speech = on_speech
        self._player_factory = player_factory
        self.rate = rate
        self.volume = DEFAULT_VOLUME
        self._jobs: queue.Queue[_Job | None] = queue.Queue()
        self._player: Player | None = None
        self._worker: threading.Thread | None = None
        self._ready = threading.Event()
        #: bumped by stop_speaking; a phrase queued under an older generation is not played
        self._generation = 0
        self._generation_lock = threading.Lock()
        #: whether the last phrase failed (LOST was reported): the next one played reports ON
        self._lost = False
        self.available = False
        self.reason = ""

    # -- lifecycle ---------------------------------------------------------------------------

    def start(self) -> None:
        """Start the worker; it reports ON or OFF through ``on_status``. Does not block."""
        self._worker = threading.Thread(target=self._run, name="kiosk-tts", daemon=True)
        self._worker.start()

    def wait_ready(self, timeout: float = 10.0) -> bool:
        """Wait until the worker knows whether voice out works; returns ``available``."""
        self._ready.wait(timeout)
        return self.available

    def close(self) -> None:
        """Stop talking and end the worker; safe to call twice."""
        if self._worker is not None:
            self.stop_speaking()
            self._jobs.put(None)
            self._worker.join(timeout=SYNTH_TIMEOUT_S)
            self._worker = None

    # -- what the session asks for -----------------------------------------------------------

    def say(self, text: str, language: str) -> None:
        """Queue a phrase to be read aloud; ignored (and logged) when voice out is off."""
        if self._ready.is_set() and not self.available:
            log.info("voice out is off (%s); not saying %r", self.reason, text[:40])
            return
        self._jobs.put(_Job(text, language, generation=self._generation))

    def stop_speaking(self) -> None:
        """Cut the current phrase short and drop queued ones (the patient already answered),
        including one being synthesised: it is never played."""
        with self._generation_lock:
            self._generation += 1
        with contextlib.suppress(queue.Empty):
            while True:
                job = self._jobs.get_nowait()
                if job is None:  # keep a pending shutdown
                    self._jobs.put(None)
                    break
                if job.done is not None:  # a save waits on it; never drop it
                    self._jobs.put(job)
                    break
        if self._player is not None:
            self._player.stop()

    def volume_up(self) -> float:
        """One step louder (from the next phrase on); returns the new volume."""
        self.volume = min(MAX_VOLUME, self.volume + VOLUME_STEP)
        return self.volume

    def volume_down(self) -> float:
        """One step quieter (from the next phrase on); returns the new volume."""
        self.volume = max(MIN_VOLUME, self.volume - VOLUME_STEP)
        return self.volume

    def save_to_file(self, text: str, language: str, path: str | Path, timeout: float = SYNTH_TIMEOUT_S) -> Path:
        """Synthesise ``text`` to a WAV file on the worker (works without an audio output)."""
        done = threading.Event()
        job = _Job(text, language, Path(path), done)
        self._jobs.put(job)
        if not done.wait(timeout):
            raise TtsUnavailable(f"espeak-ng did not finish within {timeout:.0f} s")
        if job.error is not None:
            raise job.error
        return Path(path)

    # -- the worker --------------------------------------------------------------------------

    def _run(self) -> None:
        synth = self._start_synthesiser()
        while (job := self._jobs.get()) is not None:
            if synth is None:
                if job.done is not None:
                    job.error = TtsUnavailable(self.reason)
                    job.done.set()
                continue
            try:
                if job.path is not None:
                    synth.synthesise(job.text, job.language, job.path, self.rate, self.volume)
                else:
                    self._speak(synth, job)
            except Exception as exc:  # one bad phrase must not end the kiosk's voice
                log.warning("voice out failed for %r: %s", job.text[:40], exc)
                if job.path is None:  # the patient did not hear it: the UI must say so
                    self._lost = True
                    self.on_status(
                        ChannelStatus(
                            Channel.VOICE, ChannelState.LOST, source=self.source, reason=f"voice out failed: {exc}"
                        )
                    )
                job.error = exc if isinstance(exc, TtsUnavailable) else TtsUnavailable(str(exc))
            finally:
                if job.done is not None:
                    job.done.set()

    def _start_synthesiser(self) -> Synthesiser | None:
        synth = None
        try:
            synth = Synthesiser()
            self._player = self._player_factory()
            self.available, state = True, ChannelState.ON
        except TtsUnavailable as exc:
            self.reason, state = str(exc), ChannelState.OFF
        self._ready.set()
        self.on_status(
            ChannelStatus(
                Channel.VOICE, state, source=self.source, reason=self.reason and f"voice out off: {self.reason}"
            )
        )
        # synthesis to files still works without an audio output
        return synth

    def _speak(self, synth: Synthesiser, job: _Job) -> None:
        if self._player is None:
            return
        fd, name = tempfile.mkstemp(suffix=".wav", prefix="kiosk-tts-")
        os.close(fd)
        try:
            import wave  # here, on the speaker's thread: never before the welcome

            import numpy as np

            synth.synthesise(job.text, job.language, name, self.rate, self.volume)
            with wave.open(name, "rb") as wav:
                rate = wav.getframerate()
                samples = np.frombuffer(wav.readframes(wav.getnframes()), dtype="<i2")
        finally:
            os.unlink(name)
        with self._generation_lock:
            # stop_speaking while it was synthesised: it is off the queue and the player idle
            if job.generation != self._generation:
                return
        self.on_speech(True)
        try:
            self._player.play(samples, rate)
        finally:
            self.on_speech(False)
        if self._lost:  # a phrase failed before; this one was heard, so voice out works again
            self._lost = False
            self.on_status(ChannelStatus(Channel.VOICE, ChannelState.ON, source=self.source))
