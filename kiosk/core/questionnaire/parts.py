"""The parts an instrument is made of that scoring needs too: codes, answer options, a number
staff enter, and interpretation bands. Plain frozen values; :mod:`.model` builds instruments of
them and :mod:`.scoring` scores with them, so neither imports the other's module for them.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import field
from typing import Any

from basis import record

__all__ = ["PATIENT", "STAFF", "Band", "BandSet", "Code", "Entry", "Option"]


@record
class Code:
    """A coding for export, e.g. a LOINC code."""

    system: str
    code: str
    #: the code system's own display for the code (LOINC's), exported as ``Coding.display``
    display: str = ""


@record
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


#: who answers an item: the patient at the kiosk (default) or staff on the clinician screen or station
PATIENT = "patient"
STAFF = "staff"


@record
class Entry:
    """A number staff type in for an item (``input:``): years of education, weight in kg."""

    #: "integer" or "decimal"
    type: str
    min: float
    max: float
    #: the unit shown beside the field and exported (UCUM-like text, "kg"); may be empty
    unit: str = ""

    def fits(self, value: Any) -> bool:
        """Whether ``value`` is a number of this entry's type within its range."""
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            return False
        if self.type == "integer" and not float(value).is_integer():
            return False
        return self.min <= value <= self.max


@record
class Band:
    """An interpretation band: totals from ``min`` to ``max`` inclusive, and what it means for
    the patient (``concern``, one of :data:`CONCERNS`, as the instrument's author declared it;
    None: not declared, or a band that judges nothing, such as "no cut-off")."""

    id: str
    min: int
    max: int
    label: Mapping[str, str]
    concern: str | None = None


#: what a band may say about the patient, from nothing to worry about to a lot: staff's plots
#: colour a band by this, never by its place in the list
CONCERNS = ("none", "low", "moderate", "high")


@record
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
