"""The questionnaire: YAML file -> validated, immutable dataclasses; scoring and interpretation.

Clinicians edit the instruments (``kiosk/core/questionnaire/instruments/*.yaml``) by hand, so
loading is strict: every problem (YAML syntax, unknown keys, missing translations, duplicate ids,
an item without options, a formula that is not FHIRPath, bands with gaps...) is collected with its
``file:line:col`` position and reported together, and nothing is half-loaded. The structural
rules live in ``questionnaire.schema.json`` (which editors can also use while typing); the rules a
JSON Schema cannot express (translations for the declared languages, unique ids, band coverage,
the formula) are checked in :mod:`.checks` and :mod:`.rules`.

Interpretation bands come as named band sets (Shah 1989, a Spanish clinical-practice set...), one
of them the file's default. A kiosk may choose another (``bands:`` in its config,
:meth:`Questionnaire.with_band_set`); scoring then uses that set everywhere.

Format v2 (every v1 file, the Barthel's, stays valid and means the same): points any integer,
shared by several options if need be, 2 to 6 options; ``answers: yes_no`` items; items staff
answer (``answered_by: staff``, with options or an ``input`` number); ``source:`` and
``translations:``; ``scoring:`` with a ``total`` (``sum`` or a FHIRPath formula with its range)
and ``subscales``.

The parts: :mod:`.model` (the immutable instrument), :mod:`.scoring` (total, formula, subscales,
band), :mod:`.loading` (file -> model, all or nothing), :mod:`.checks` and :mod:`.rules` (the rules
beyond the schema), :mod:`.definition` (the canonical JSON a session stores). Import the public names from this package.
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
    Item,
    PracticeQuestion,
    Questionnaire,
    Timing,
    Translation,
)
from kiosk.core.questionnaire.outcome import item_name, pending_words, result_words
from kiosk.core.questionnaire.parts import CONCERNS, PATIENT, STAFF, Band, BandSet, Code, Entry, Option
from kiosk.core.questionnaire.scoring import (
    ITEM_WEIGHT,
    Formula,
    Score,
    ScoringError,
    Subscale,
    evaluate,
    response_items,
)

__all__ = [
    "DEFAULT_FILE",
    "ITEM_WEIGHT",
    "MAX_TIMING_S",
    "PATIENT",
    "SCHEMA_FILE",
    "SCREEN_LANGUAGES",
    "STAFF",
    "Band",
    "CONCERNS",
    "BandSet",
    "Code",
    "Entry",
    "Formula",
    "Item",
    "Option",
    "PracticeQuestion",
    "Questionnaire",
    "QuestionnaireError",
    "Score",
    "ScoringError",
    "Subscale",
    "Timing",
    "Translation",
    "bundled_path",
    "check_questionnaire",
    "check_questionnaire_file",
    "check_questionnaire_text",
    "evaluate",
    "item_name",
    "load_questionnaire",
    "pending_words",
    "response_items",
    "result_words",
]
