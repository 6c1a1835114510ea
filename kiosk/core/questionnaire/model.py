"""The instrument model: immutable items, options, band sets, timing, and scoring.

Built only by :func:`kiosk.core.questionnaire.load_questionnaire`, which has checked every rule,
so the model trusts its data: a ``Questionnaire`` that exists is one the kiosk can run. Scoring
(the sum or a FHIRPath formula, subscales, bands) is :mod:`.scoring`'s.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import field, fields, replace
from typing import Any

from basis import record
from kiosk.core.questionnaire.parts import PATIENT, STAFF, Band, BandSet, Code, Entry, Option
from kiosk.core.questionnaire.scoring import Formula, Score, Subscale, compute_score

#: the longest a timing setting may be: a day (a longer wait is a typo, and no session lasts it)
MAX_TIMING_S = 86400.0


@record
class Item:
    """One item of an instrument: a question with options, or a number staff enter (``entry``)."""

    id: str
    #: 1-based position in the questionnaire
    number: int
    text: Mapping[str, str]
    spoken: Mapping[str, str]
    #: the answer options (empty for an item answered by an ``entry``)
    options: tuple[Option, ...]
    code: Code | None = None
    #: the question as the patient's screen shows it, when it differs from ``text`` (clinical)
    patient: Mapping[str, str] = field(default_factory=dict)
    #: :data:`PATIENT` (asked at the kiosk) or :data:`STAFF` (never shown or spoken to the patient)
    answered_by: str = PATIENT
    #: a number staff type in instead of choosing an option (staff items only)
    entry: Entry | None = None
    #: items this one is answered instead of, when they cannot be (empty: none): the result
    #: is complete with either this item or all of those answered
    instead_of: tuple[str, ...] = ()

    @property
    def staff(self) -> bool:
        """Answered by staff, never shown or spoken to the patient."""
        return self.answered_by == STAFF

    def option(self, number: int) -> Option:
        """The option with this 1-based number; ``KeyError`` if there is none."""
        if 1 <= number <= len(self.options):
            return self.options[number - 1]
        raise KeyError(f"item {self.id!r} has no option {number} (it has {len(self.options)})")

    def patient_text_in(self, language: str) -> str:
        """The question as the patient's screen shows it in ``language``."""
        return self.patient.get(language) or self.text[language]

    @property
    def points(self) -> frozenset[int]:
        """The points this item's options can score (empty for an entry)."""
        return frozenset(o.points for o in self.options if o.points is not None)

    @property
    def max_points(self) -> int:
        """The most this item's options score (0 for an entry, which adds nothing to a sum)."""
        return max(self.points, default=0)

    @property
    def min_points(self) -> int:
        """The least this item's options score (0 for an entry)."""
        return min(self.points, default=0)


@record
class PracticeQuestion:
    """A familiarisation question checking the patient can hear, read or select. Not scored."""

    id: str
    #: what it checks: "hear", "read" or "select"
    checks: str
    text: Mapping[str, str]
    spoken: Mapping[str, str]
    options: tuple[Option, ...]
    #: the option number a patient who understood would choose
    expected: int

    def patient_text_in(self, language: str) -> str:
        """The question as the screen shows it (practice questions have one wording)."""
        return self.text[language]

    def option(self, number: int) -> Option:
        """The option with this 1-based number; ``KeyError`` if there is none."""
        if 1 <= number <= len(self.options):
            return self.options[number - 1]
        raise KeyError(f"practice question {self.id!r} has no option {number}")


@record
class Timing:
    """How long the session waits, in seconds. Defaults come from the questionnaire file."""

    #: each of the two attempts of a question waits this long for an answer
    attempt_window_s: float = 20.0
    #: after an answer or an unanswered question, before the next question's attempt 1 opens
    between_questions_s: float = 2.0
    #: after pause/resume or call-doctor/continue, the attempt has at least this long left
    resume_grace_s: float = 10.0
    #: after the patient comes back, the attempt has at least this long left
    person_back_grace_s: float = 5.0
    #: after the last question, before FINISHED and the summary
    closing_s: float = 5.0
    #: how long "I heard: ... Is that right?" waits for Yes or No; no reply stores nothing and
    #: ends the attempt as if it had timed out
    confirm_window_s: float = 10.0

    def with_overrides(self, overrides: Mapping[str, Any] | None) -> Timing:
        """A copy with some values replaced; unknown names or negative values raise ValueError."""
        if not overrides:
            return self
        known = {f.name for f in fields(self)}
        changes: dict[str, float] = {}
        for name, value in overrides.items():
            if name not in known:
                raise ValueError(f"unknown timing setting {name!r} (known: {', '.join(sorted(known))})")
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0 <= value <= MAX_TIMING_S:
                raise ValueError(
                    f"timing setting {name!r} must be a number of seconds from 0 to "
                    f"{MAX_TIMING_S:g} (a day), got {value!r}"
                )
            changes[name] = float(value)
        for name in ("attempt_window_s", "confirm_window_s"):
            if changes.get(name, getattr(self, name)) <= 0:
                raise ValueError(f"timing setting {name!r} must be more than 0 seconds")
        return replace(self, **changes)


@record
class Translation:
    """Where one language's text of an instrument comes from, and whether it is a published,
    validated translation (an unvalidated one needs the site's acceptance for clinical use)."""

    source: str
    validated: bool


@record
class Questionnaire:
    """A validated questionnaire. Build it with :func:`load_questionnaire`."""

    id: str
    version: str
    title: Mapping[str, str]
    languages: tuple[str, ...]
    items: tuple[Item, ...]
    #: every band set of the file, by id
    band_sets: Mapping[str, BandSet]
    #: the band set scoring uses: the file's default unless :meth:`with_band_set` chose another
    band_set: str
    messages: Mapping[str, Mapping[str, str]]
    familiarisation: tuple[PracticeQuestion, ...]
    timing: Timing
    code: Code | None = None
    total_code: Code | None = None
    #: where it was loaded from (for messages and records)
    source: str = field(default="", compare=False)
    #: SHA-256 of the file's content (as parsed: comments and layout do not count), so exports
    #: can tell two edits of the same questionnaire apart
    digest: str = ""
    #: the published source of the instrument and its scoring (the file's ``source:``)
    reference: str = ""
    #: language -> its translation's source and status (the file's ``translations:``)
    translations: Mapping[str, Translation] = field(default_factory=dict)
    #: the total as a FHIRPath formula (None: the sum of the chosen options' points)
    formula: Formula | None = None
    #: sums of some items' points, reported beside the total
    subscales: tuple[Subscale, ...] = ()
    #: what the patient's screens call it, in plain words (the file's ``patient_title:``; empty:
    #: the title): "Questions about how you feel", never "Geriatric Depression Scale"
    patient_title: Mapping[str, str] = field(default_factory=dict)
    #: who answers the instrument (the file's ``answered_by:``): "patient", "caregiver" (about the
    #: patient: never started by a walk-up patient) or "staff"
    answered_by: str = PATIENT

    def title_for_patient(self, language: str) -> str:
        """The instrument's name on the patient's screens in ``language``."""
        return self.patient_title.get(language) or self.title.get(language, "")

    def validated(self, language: str) -> bool:
        """Whether the text in ``language`` is a published, validated translation (a language
        the file does not list under ``translations``, or lists unvalidated, is not)."""
        entry = self.translations.get(language)
        return entry is not None and entry.validated

    @property
    def patient_items(self) -> tuple[Item, ...]:
        """The items the patient answers at the kiosk, in order (staff items left out)."""
        return tuple(i for i in self.items if not i.staff)

    @property
    def staff_items(self) -> tuple[Item, ...]:
        """The items staff answer (clinician screen or station), in order."""
        return tuple(i for i in self.items if i.staff)

    @property
    def min_total(self) -> int:
        """The lowest possible total."""
        return self.formula.min if self.formula else sum(i.min_points for i in self.items)

    @property
    def max_total(self) -> int:
        """The highest possible total."""
        return self.formula.max if self.formula else sum(i.max_points for i in self.items)

    def item(self, item_id: str) -> Item:
        """The item with this id; ``KeyError`` if unknown."""
        for item in self.items:
            if item.id == item_id:
                return item
        raise KeyError(f"unknown item {item_id!r}")

    def message(self, name: str, language: str) -> str:
        """A message (welcome, explanation, paused...) in ``language``; '' if the file has none."""
        return self.messages.get(name, {}).get(language, "")

    @property
    def bands(self) -> tuple[Band, ...]:
        """The bands scoring uses (those of :attr:`band_set`)."""
        return self.band_sets[self.band_set].bands

    @property
    def band_source(self) -> str:
        """Where the bands scoring uses come from."""
        return self.band_sets[self.band_set].source

    def bands_named(self, band_set: str | None = None) -> BandSet:
        """The band set with this id (None: the one scoring uses); ``KeyError`` naming the sets."""
        name = self.band_set if band_set is None else band_set
        if name not in self.band_sets:
            raise KeyError(f"no band set {name!r} in {self.id} (it has {', '.join(self.band_sets)})")
        return self.band_sets[name]

    def with_band_set(self, band_set: str) -> Questionnaire:
        """A copy that scores with another of its band sets; ``KeyError`` if there is none of that id."""
        return replace(self, band_set=self.bands_named(band_set).id)

    @property
    def total_range(self) -> tuple[int, int]:
        """The lowest and the highest total a complete answer can reach: what a chart's axis of
        this instrument spans (its own scale, never the Barthel's 0-100; a formula's declared range)."""
        return self.min_total, self.max_total

    def band_for(self, total: int, band_set: str | None = None) -> Band | None:
        """The band containing ``total`` in ``band_set`` (None: the set scoring uses)."""
        return self.bands_named(band_set).band_for(total)

    def score(self, points: Mapping[str, int], band_set: str | None = None) -> Score:
        """Score answers given as item id -> points (the form before option numbers were needed):
        each points value stands for the first option scoring it. Prefer :meth:`score_answers`,
        which a formula on answer codes needs when options share a score.

        ValueError for an unknown item or points that are not one of that item's options.
        """
        options: dict[str, int] = {}
        for item_id, value in points.items():
            item = self._known(item_id)
            number = next((o.number for o in item.options if o.points == value and not isinstance(value, bool)), None)
            if number is None:
                allowed = ", ".join(str(p) for p in sorted(item.points))
                raise ValueError(f"{value!r} points is not an option of item {item_id!r} (options: {allowed})")
            options[item_id] = number
        return self.score_answers(options, band_set)

    def score_answers(
        self, options: Mapping[str, int], band_set: str | None = None, *, values: Mapping[str, float] | None = None
    ) -> Score:
        """Score the answers: ``options`` item id -> option number (choice items), ``values`` item
        id -> the number staff entered (entry items), interpreted with ``band_set`` (None: the set
        scoring uses, normally the file's default).

        ValueError for an unknown item, option or a value outside its entry's range (and for a
        formula giving no whole number in its declared range); KeyError for an unknown band set.
        A missing item makes the score incomplete, without a band, and a missing staff item is
        named in ``awaiting_staff``: nothing ever counts as 0 silently.
        """
        bands = self.bands_named(band_set)
        for item_id, number in options.items():
            item = self._known(item_id)
            if item.entry is not None or isinstance(number, bool) or not isinstance(number, int):
                raise ValueError(f"item {item_id!r} takes {'an entered value' if item.entry else 'an option number'}")
            if not 1 <= number <= len(item.options):
                raise ValueError(f"item {item_id!r} has no option {number} (it has {len(item.options)})")
        for item_id, value in (values or {}).items():
            item = self._known(item_id)
            if item.entry is None:
                raise ValueError(f"item {item_id!r} has options, not an entered value")
            if not item.entry.fits(value):
                raise ValueError(
                    f"{value!r} is not a{'n integer' if item.entry.type == 'integer' else ' number'} from "
                    f"{item.entry.min:g} to {item.entry.max:g} for item {item_id!r}"
                )
        return compute_score(self, options, values or {}, bands)

    def _known(self, item_id: str) -> Item:
        for item in self.items:
            if item.id == item_id:
                return item
        raise ValueError(f"unknown item {item_id!r}")
