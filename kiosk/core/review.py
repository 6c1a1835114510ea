"""A clinician's review of a stored session: the contract between the ward station and exports.

The station owns validation (who corrected what, who signed off, who reopened a signed result to
amend it); exports (FHIR, CSV) take a :class:`Review` so that a result says which state it is in
and carries the clinician's corrections. The kiosk on its own knows no review: it exports
:meth:`Review.unreviewed`. Two functions are the one story every export and page tells:
:func:`review_from_steps` (the review an audit trail amounts to) and :func:`review_state` (where a
result stands, from its review and the kiosk's answers). Pure data, no I/O.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import replace
from enum import Enum
from typing import Protocol

from basis import record

#: the default system of staff account names (the signer's and corrector's Practitioner identifier)
STAFF_SYSTEM = "urn:barthel-kiosk:station:staff"


class ReviewState(str, Enum):
    """Where a result stands. Only ``SIGNED_OFF`` and ``AMENDED`` are final."""

    UNREVIEWED = "unreviewed"
    #: staff changed an answer, and no doctor has signed the result off (or a doctor reopened a
    #: signed result to amend it and has not signed it again)
    CORRECTED = "corrected"
    #: a doctor accepted the result as the kiosk recorded it
    SIGNED_OFF = "signed_off"
    #: a doctor signed off a result with at least one correction or filled item
    AMENDED = "amended"


@record
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


@record
class Reopening:
    """A doctor reopened a signed-off result to amend it (it is final again once signed again)."""

    author: str
    at: str
    reason: str
    #: the sign-off it set aside
    signed_by: str
    signed_at: str


@record
class Review:
    """The review of one session: its state, corrections (oldest first) and sign-off."""

    state: ReviewState = ReviewState.UNREVIEWED
    corrections: tuple[Correction, ...] = ()
    signed_by: str | None = None
    signed_at: str | None = None
    #: signed results reopened for amendment, oldest first
    reopenings: tuple[Reopening, ...] = ()
    #: the system of the staff names above (FHIR Practitioner identifiers)
    staff_system: str = STAFF_SYSTEM
    #: signed off with items unanswered: the doctor's reason ('' for a complete result, or none
    #: signed); exports say the result is incomplete and why
    incomplete: str = ""

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


class Step(Protocol):
    """One row of a station's audit trail, as :func:`review_from_steps` reads it."""

    # read-only: a frozen dataclass (the station's AuditEntry) is a Step

    @property
    def at(self) -> str: ...
    @property
    def author(self) -> str: ...
    #: "correct", "fill", "sign_off" (its reason: why a result with unanswered items was signed
    #: off as incomplete, '' otherwise), "amend" (reopen a signed result); others are ignored
    @property
    def action(self) -> str: ...
    @property
    def item_id(self) -> str | None: ...
    @property
    def option(self) -> int | None: ...
    @property
    def previous_option(self) -> int | None: ...
    @property
    def reason(self) -> str: ...


def review_from_steps(steps: Iterable[Step], staff_system: str = STAFF_SYSTEM) -> Review:
    """The review an audit trail (oldest first) amounts to: every correction, the last sign-off
    unless a later "amend" reopened it, and each reopening with the sign-off it set aside."""
    corrections: list[Correction] = []
    reopenings: list[Reopening] = []
    sign: Step | None = None
    for step in steps:
        if step.action in ("correct", "fill"):
            corrections.append(
                Correction(
                    step.item_id or "", step.option or 0, step.previous_option, step.reason, step.author, step.at
                )
            )
        elif step.action == "sign_off":
            sign = step
        elif step.action == "amend" and sign is not None:
            reopenings.append(Reopening(step.author, step.at, step.reason, sign.author, sign.at))
            sign = None
    if sign is None:
        state = ReviewState.CORRECTED if corrections or reopenings else ReviewState.UNREVIEWED
        return Review(state, tuple(corrections), reopenings=tuple(reopenings), staff_system=staff_system)
    state = ReviewState.AMENDED if corrections else ReviewState.SIGNED_OFF
    return Review(state, tuple(corrections), sign.author, sign.at, tuple(reopenings), staff_system, sign.reason)


def review_state(review: Review, recorded: Mapping[str, int]) -> ReviewState:
    """Where a result stands, the one answer every export and page gives: ``amended`` (signed off
    with answers other than the kiosk ``recorded``), ``signed_off`` (signed off as recorded),
    ``corrected`` (answers changed, or a signed result reopened to amend, and not signed off)
    or ``unreviewed``. Changes that came back to the kiosk's answer count as none, so a changed
    answer is never reported as the kiosk's and an unchanged one never as changed."""
    changed = review.options(dict(recorded)) != dict(recorded)
    if review.final:
        return ReviewState.AMENDED if changed else ReviewState.SIGNED_OFF
    return ReviewState.CORRECTED if changed or review.reopenings else ReviewState.UNREVIEWED


def state_once_signed(review: Review, recorded: Mapping[str, int]) -> ReviewState:
    """What :func:`review_state` will say once a doctor signs ``review`` off: ``AMENDED`` when
    the answers differ from the kiosk's, else ``SIGNED_OFF`` (what a sign-off button and its
    confirmation announce, so they never promise another state than the badge shows after)."""
    return review_state(replace(review, state=ReviewState.SIGNED_OFF), recorded)
