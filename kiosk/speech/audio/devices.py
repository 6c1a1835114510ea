"""Microphones: the inputs PortAudio offers (`kiosk devices`) and the stream that feeds a pipeline.

The PortAudio callback thread only queues audio; one reader thread feeds the pipeline, so a slow
recogniser never blocks the sound card."""

from __future__ import annotations

import logging
import queue
import threading
from collections.abc import Callable
from typing import Any

from basis import record
from basis.errors import KioskError
from kiosk.speech.audio.pcm import FRAME_SAMPLES, SAMPLE_RATE, PcmConsumer

log = logging.getLogger(__name__)


class AudioUnavailable(KioskError, RuntimeError):
    """Audio input cannot work on this machine; the message is one sentence for the UI."""


@record
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
        self._stream: Any = None  # a sounddevice.RawInputStream once started
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
