"""The speech channel: the kiosk's voice (``tts``) and the patient's voice (``audio``, ``asr``,
``matching``, ``voice``).

Sub-modules import their heavy libraries (sounddevice, pocketsphinx, vosk) lazily, so
importing this package is cheap and never fails on a machine without audio.
"""
