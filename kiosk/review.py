"""A clinician's review of a stored session: the contract between the ward station and exports.

The station owns validation (who corrected what, who signed off); exports (FHIR, CSV) take a
:class:`Review` so that a result says which state it is in and carries the clinician's
corrections. The kiosk on its own knows no review: it exports :meth:`Review.unreviewed`.
Pure data, no I/O.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum


class ReviewState(str, Enum):
    """Where a result stands. Only ``SIGNED_OFF`` and ``AMENDED`` are final."""

    UNREVIEWED = "unreviewed"
    #: a doctor accepted the result as the kiosk recorded it
    SIGNED_OFF = "signed_off"
    #: a doctor signed off a result with at least one correction or filled item
    AMENDED = "amended"


@dataclass(frozen=True)
class Correction:
    """One clinician change to an item: a corrected answer, or an unanswered item filled."""

    item_id: str
    #: the new 1-based option
    option: int
    #: what the kiosk (or an earlier correction) had; None: the item was unanswered
    previous_option: int | None
    reason: str
    #: the clinician's user name on the station
    author: str
    #: ISO-8601 UTC
    at: str


@dataclass(frozen=True)
class Review:
    """The review of one session: its state, corrections (oldest first) and sign-off."""

    state: ReviewState = ReviewState.UNREVIEWED
    corrections: tuple[Correction, ...] = ()
    signed_by: str | None = None
    signed_at: str | None = None

    @classmethod
    def unreviewed(cls) -> Review:
        """A result no clinician has looked at yet (what a kiosk exports on its own)."""
        return cls()

    @property
    def final(self) -> bool:
        """Signed off, with or without corrections."""
        return self.state in (ReviewState.SIGNED_OFF, ReviewState.AMENDED)

    def options(self, recorded: dict[str, int]) -> dict[str, int]:
        """The answers after corrections: ``recorded`` (item id -> option) with the latest
        correction of each item applied."""
        result = dict(recorded)
        for correction in self.corrections:
            result[correction.item_id] = correction.option
        return result
