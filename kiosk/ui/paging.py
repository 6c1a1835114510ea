"""How a four-button remote reaches options 5 and 6: two pages of three answers and a page button.

On an item with more answers than the remote has answer buttons (5 or 6 options; remotes carry
1-4), while a remote is in use, the screen shows options 1-3 numbered 1-3 and "4 More answers";
pressing 4 shows options 4-6 numbered 1-3 and "4 Back". So the number the patient presses is
always the number on the screen. A touch on an answer on screen is that answer, a touch on the page
button turns the page; keys 1-4 press what the screen shows too (5 and 6 stay options 5 and 6),
and the voice says the options' own numbers. Plain code (no Textual) so the controller owns the state and tests it
without Pilot; the screen only draws :func:`shown`.
"""

from __future__ import annotations

from collections.abc import Hashable

from basis import record

#: the answer buttons a remote carries (:data:`kiosk.remote.buttons.ANSWER_BUTTONS`)
REMOTE_ANSWERS = 4
#: answers per page: the fourth button turns the page
PER_PAGE = REMOTE_ANSWERS - 1
#: the number of the page button, on the remote and on the screen
PAGE_BUTTON = REMOTE_ANSWERS


@record
class Shown:
    """One button on a paged screen: the ``number`` it shows (the remote's), and the ``option`` it
    stands for (None: the page button, "More answers" on the first page, "Back" on the second)."""

    number: int
    option: int | None


def needs_paging(options: int) -> bool:
    """Whether an item with ``options`` answers is paged for the remote (5 or 6 answers)."""
    return options > REMOTE_ANSWERS


def shown(page: int, options: int) -> tuple[Shown, ...]:
    """The buttons of ``page`` (0 or 1) of an item with ``options`` answers: up to three answers
    numbered from 1, then the page button numbered 4."""
    first = page * PER_PAGE
    answers = [Shown(n, first + n) for n in range(1, PER_PAGE + 1) if first + n <= options]
    return (*answers, Shown(PAGE_BUTTON, None))


class RemotePager:
    """The page shown for the item on screen. ``key`` names the item being asked (its id and
    attempt): a new question, or the same one asked again, starts on the first page."""

    def __init__(self) -> None:
        self._key: Hashable = None
        self._page = 0

    def page(self, key: Hashable) -> int:
        """The page shown for ``key`` (0 unless it was turned while ``key`` was asked)."""
        return self._page if key == self._key else 0

    def turn(self, key: Hashable) -> None:
        """The page button was pressed: show the other page."""
        self._page, self._key = 1 - self.page(key), key

    def press(self, key: Hashable, options: int, button: int) -> int | None:
        """What pressing remote ``button`` means on the item ``key`` with ``options`` answers: the
        option number it chooses (possibly one the item lacks: the session says so gently), or
        None when it turned the page. Items with at most four answers are never paged."""
        if not needs_paging(options):
            return button
        if button == PAGE_BUTTON:
            self.turn(key)
            return None
        return self.page(key) * PER_PAGE + button
