"""The questionnaire: YAML file -> validated, immutable dataclasses; scoring and interpretation.

Clinicians edit ``kiosk/core/questionnaire/instruments/barthel.yaml`` by hand, so loading is strict: every problem
(YAML syntax, unknown keys, missing translations, duplicate ids, points that are not multiples of 5,
bands with gaps...) is collected with its ``file:line:col`` position and reported together, and
nothing is half-loaded. The structural rules live in ``questionnaire.schema.json`` (which editors
can also use while typing); the rules a JSON Schema cannot express (translations for the declared
languages, unique ids, band coverage) are checked in :mod:`.checks`.

Interpretation bands come as named band sets (Shah 1989, a Spanish clinical-practice set...), one
of them the file's default. A kiosk may choose another (``bands:`` in its config,
:meth:`Questionnaire.with_band_set`); scoring then uses that set everywhere.

The parts: :mod:`.model` (the immutable instrument and its scoring), :mod:`.loading` (file ->
model, all or nothing), :mod:`.checks` (the rules beyond the schema), :mod:`.definition` (the
canonical JSON a session stores). Import the public names from this package.
"""

from kiosk.core.questionnaire.checks import SCREEN_LANGUAGES
from kiosk.core.questionnaire.loading import (
    DEFAULT_FILE,
    SCHEMA_FILE,
    QuestionnaireError,
    bundled_path,
    check_questionnaire,
    check_questionnaire_file,
    check_questionnaire_text,
    load_questionnaire,
)
from kiosk.core.questionnaire.model import (
    MAX_TIMING_S,
    Band,
    BandSet,
    Code,
    Item,
    Option,
    PracticeQuestion,
    Questionnaire,
    Score,
    Timing,
)

__all__ = [
    "DEFAULT_FILE",
    "MAX_TIMING_S",
    "SCHEMA_FILE",
    "SCREEN_LANGUAGES",
    "Band",
    "BandSet",
    "Code",
    "Item",
    "Option",
    "PracticeQuestion",
    "Questionnaire",
    "QuestionnaireError",
    "Score",
    "Timing",
    "bundled_path",
    "check_questionnaire",
    "check_questionnaire_file",
    "check_questionnaire_text",
    "load_questionnaire",
]
