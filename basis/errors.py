"""The project's one base for errors a person is meant to read: :class:`KioskError`.

Every layer raises its own kinds (ConfigError, QuestionnaireError, qos's ModelError, ...), each
still a ValueError or RuntimeError as before; they share this base so a command can report any
of them as the one clear message its contract promises (where and what, no traceback) with a
single ``except KioskError``, while a programming error still shows its traceback.
"""

from __future__ import annotations


class KioskError(Exception):
    """An error whose message is for the user: one sentence naming where and what is wrong."""
