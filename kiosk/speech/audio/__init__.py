"""Audio in: microphones, WAV files, and an energy endpointer that cuts speech into utterances.

Everything the recogniser hears goes through one :class:`UtterancePipeline`: 16 kHz mono
16-bit PCM in, one :class:`Utterance` out per stretch of speech. A microphone
(:class:`MicrophoneStream`, PortAudio via sounddevice) and a WAV file (:func:`feed_wav`) feed the
same pipeline, which is how the tests and ``bench/asr.py`` exercise the real path without a
sound card. Times are positions in the audio stream (seconds of samples fed), not wall time, so
a file replays the same way every time.

The parts: :mod:`.pcm` (the format, WAV files, frame levels), :mod:`.endpointer`,
:mod:`.pipeline`, :mod:`.devices` (microphones). Import the public names from this package.
"""

from __future__ import annotations

from kiosk.speech.audio.devices import (
    AudioUnavailable,
    InputDevice,
    MicrophoneStream,
    default_input_device,
    describe_input,
    list_input_devices,
)
from kiosk.speech.audio.endpointer import Endpointer, EndpointerSettings
from kiosk.speech.audio.pcm import (
    FRAME_SAMPLES,
    SAMPLE_RATE,
    PcmConsumer,
    feed_samples,
    feed_wav,
    frame_level_db,
    frame_powers,
    read_wav,
    resample,
)
from kiosk.speech.audio.pipeline import StreamingRecogniser, Utterance, UtterancePipeline

__all__ = [
    "FRAME_SAMPLES",
    "SAMPLE_RATE",
    "AudioUnavailable",
    "Endpointer",
    "EndpointerSettings",
    "InputDevice",
    "MicrophoneStream",
    "PcmConsumer",
    "StreamingRecogniser",
    "Utterance",
    "UtterancePipeline",
    "default_input_device",
    "describe_input",
    "feed_samples",
    "feed_wav",
    "frame_level_db",
    "frame_powers",
    "list_input_devices",
    "read_wav",
    "resample",
]
