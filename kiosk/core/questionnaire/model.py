"""The instrument model: immutable items, options, band sets, timing, and scoring.

Built only by :func:`kiosk.core.questionnaire.load_questionnaire`, which has checked every rule,
so the model trusts its data: a ``Questionnaire`` that exists is one the kiosk can run.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, fields, replace
from typing import Any

#: the longest a timing setting may be: a day (a longer wait is a typo, and no session lasts it)
MAX_TIMING_S = 86400.0


@dataclass(frozen=True)
class Code:
    """A coding for export, e.g. a LOINC code."""

    system: str
    code: str
    #: the code system's own display for the code (LOINC's), exported as ``Coding.display``
    display: str = ""


@dataclass(frozen=True)
class Option:
    """One answer option of a question. ``number`` is its 1-based position (button and remote)."""

    number: int
    label: Mapping[str, str]
    synonyms: Mapping[str, tuple[str, ...]]
    #: points scored (None for practice questions, which are not scored)
    points: int | None = None
    #: the patient's wording, when it differs from the clinical ``label`` (empty: the label)
    patient: Mapping[str, str] = field(default_factory=dict)
    #: a published answer code (LOINC LA...) for export; None: exports use a local code
    code: Code | None = None

    def label_in(self, language: str) -> str:
        """The option's clinical label in ``language`` (clinicians' screens, exports)."""
        return self.label[language]

    def patient_label_in(self, language: str) -> str:
        """The option as the patient's screen shows it in ``language``."""
        return self.patient.get(language) or self.label[language]

    def synonyms_in(self, language: str) -> tuple[str, ...]:
        """Extra words a patient may say for this option in ``language`` (may be empty)."""
        return self.synonyms.get(language, ())


@dataclass(frozen=True)
class Item:
    """One scored item of an instrument (the Barthel's feeding, a mood scale's question, ...)."""

    id: str
    #: 1-based position in the questionnaire
    number: int
    text: Mapping[str, str]
    spoken: Mapping[str, str]
    options: tuple[Option, ...]
    code: Code | None = None
    #: the question as the patient's screen shows it, when it differs from ``text`` (clinical)
    patient: Mapping[str, str] = field(default_factory=dict)

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
        """The points this item's options can score."""
        return frozenset(o.points for o in self.options if o.points is not None)

    @property
    def max_points(self) -> int:
        """The most this item can score."""
        return max(self.points)

    @property
    def min_points(self) -> int:
        """The least this item can score."""
        return min(self.points)


@dataclass(frozen=True)
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


@dataclass(frozen=True)
class Band:
    """An interpretation band: totals from ``min`` to ``max`` inclusive."""

    id: str
    min: int
    max: int
    label: Mapping[str, str]


@dataclass(frozen=True)
class BandSet:
    """A named set of interpretation bands covering every possible total, with its source."""

    id: str
    #: where the cut-offs come from (a citation, or a warning that the source is unconfirmed)
    source: str
    #: in ascending order of totals
    bands: tuple[Band, ...]

    def band_for(self, total: int) -> Band | None:
        """The band containing ``total`` (None outside every band)."""
        for band in self.bands:
            if band.min <= total <= band.max:
                return band
        return None


@dataclass(frozen=True)
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


@dataclass(frozen=True)
class Score:
    """The result of scoring a set of item answers."""

    #: sum of the points of the answered items
    total: int
    #: every item answered
    complete: bool
    #: the band of ``total`` when complete, else None (an incomplete total is not interpreted)
    band: Band | None
    #: item ids answered, in questionnaire order
    answered: tuple[str, ...]
    #: item ids not answered, in questionnaire order
    missing: tuple[str, ...]
    #: the highest possible total
    max_total: int
    #: the id of the band set ``band`` comes from
    band_set: str = ""


@dataclass(frozen=True)
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
        this instrument spans (its own scale, never the Barthel's 0-100)."""
        return sum(i.min_points for i in self.items), sum(i.max_points for i in self.items)

    def band_for(self, total: int, band_set: str | None = None) -> Band | None:
        """The band containing ``total`` in ``band_set`` (None: the set scoring uses)."""
        return self.bands_named(band_set).band_for(total)

    def score(self, points: Mapping[str, int], band_set: str | None = None) -> Score:
        """Score answers given as item id -> points, interpreted with ``band_set`` (None: the set
        scoring uses, normally the file's default).

        Raises ValueError for an unknown item or points that are not one of that item's options,
        KeyError for an unknown band set. Missing items make the score incomplete (and leave it
        without a band); they never count as 0 silently.
        """
        bands = self.bands_named(band_set)
        known = {item.id: item for item in self.items}
        for item_id, value in points.items():
            if item_id not in known:
                raise ValueError(f"unknown item {item_id!r}")
            item = known[item_id]
            if isinstance(value, bool) or value not in item.points:
                allowed = ", ".join(str(p) for p in sorted(item.points))
                raise ValueError(f"{value!r} points is not an option of item {item_id!r} (options: {allowed})")
        answered = tuple(i.id for i in self.items if i.id in points)
        missing = tuple(i.id for i in self.items if i.id not in points)
        total = sum(int(points[i]) for i in answered)
        complete = not missing
        return Score(
            total=total,
            complete=complete,
            band=bands.band_for(total) if complete else None,
            answered=answered,
            missing=missing,
            max_total=sum(i.max_points for i in self.items),
            band_set=bands.id,
        )
