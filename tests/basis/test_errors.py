"""Errors a person is meant to read share one base, basis.errors.KioskError, and keep the base
they had (ValueError, RuntimeError), so every ``except`` written before still catches them."""

from __future__ import annotations

import pytest

from basis.errors import KioskError
from fileio.bounded import BadFile
from kiosk.camera.frames import CameraUnavailable
from kiosk.commands.run import SetupError
from kiosk.config import ConfigError
from kiosk.core.adaptation import PolicyError
from kiosk.core.pin import PinError
from kiosk.core.questionnaire.loading import QuestionnaireError
from kiosk.core.words import WordsError
from kiosk.export.result import ExportError
from kiosk.remote.profiles import ProfileError
from kiosk.speech.models import SpeechModelError
from kiosk.store.connection import StorageError
from qos import ContextError, ModelError, QosError


@pytest.mark.parametrize(
    ("error", "was"),
    [
        (BadFile, ValueError),
        (ConfigError, ValueError),
        (PolicyError, ValueError),
        (PinError, ValueError),
        (QuestionnaireError, ValueError),
        (WordsError, ValueError),
        (ExportError, ValueError),
        (ProfileError, ValueError),
        (QosError, ValueError),
        (ContextError, ValueError),
        (StorageError, RuntimeError),
        (SpeechModelError, Exception),
        (CameraUnavailable, Exception),
        (SetupError, Exception),
    ],
)
def test_a_user_facing_error_is_a_kiosk_error_and_still_what_it_was(error, was):
    assert issubclass(error, KioskError) and issubclass(error, was)


def test_the_two_model_errors_are_two_names():
    assert SpeechModelError is not ModelError and not issubclass(SpeechModelError, QosError)
    assert SpeechModelError.__name__ != ModelError.__name__
