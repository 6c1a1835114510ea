"""How an item's answers share the rows a display leaves them, every answer's whole text shown.

All the answers on one page when their wrapped texts fit, stacked or two-by-two; otherwise the
answers go on pages (each answer keeps its own number, so every key and spoken number still means
the same option), with a "More answers" button on each page but the last, whose button goes back
to the first. Plain code (no Textual): the answer list measures the texts and draws the plan.
"""

from __future__ import annotations

from collections.abc import Callable

from basis import record

#: rows between two answers (stacked or two-by-two)
GAP = 1
#: columns between the two columns of a two-by-two layout (kiosk.tcss: grid-gutter)
GUTTER = 2
#: the fewest rows an answer gets before the answers go two-by-two; at 3 rows and wide enough, the
#: number is drawn in big block digits
MIN_ROWS = 3
#: the cells of an answer button around its text: the thick left edge and the label's padding
EDGE = 1 + 2
#: the width of the number beside the text: small bold figures, or the big block digits
SMALL_NUMBER, BIG_NUMBER = 4, 8


@record
class Plan:
    """Where the answers go: ``pages`` of answer indices (0-based, in order; one page: no page
    button), laid out in ``columns`` with every button ``height`` rows tall; ``fits`` is False only
    when not even one answer a page fits the rows (the display is below the kiosk's floor)."""

    columns: int
    height: int
    pages: tuple[tuple[int, ...], ...]
    fits: bool = True

    @property
    def paged(self) -> bool:
        return len(self.pages) > 1


def _height(buttons: int, columns: int, rows: int) -> int:
    """Rows each of ``buttons`` equal buttons gets in ``columns`` columns of ``rows`` rows."""
    lines = -(-buttons // columns)
    return (rows - GAP * (lines - 1)) // lines


def _text_width(width: int, columns: int, height: int, roomy: bool) -> int:
    """The columns an answer's text wraps in, in a column of a ``width``-wide list."""
    column = (width - GUTTER * (columns - 1)) // columns
    number = BIG_NUMBER if roomy and height >= MIN_ROWS else SMALL_NUMBER
    return column - EDGE - number


def plan(
    count: int,
    rows: int,
    width: int,
    lines: Callable[[int | None, int], int],
    *,
    roomy: bool = False,
) -> Plan:
    """The plan for ``count`` answers in ``rows`` x ``width`` cells. ``lines(index, text_width)``:
    the rows answer ``index``'s text takes wrapped at that width (index None: the page button's).
    The most answers a page first (all of them if they fit); one column while each answer gets
    :data:`MIN_ROWS`, else two-by-two, else whichever fits."""
    for per_page in range(count, 0, -1):
        pages = tuple(tuple(range(start, min(start + per_page, count))) for start in range(0, count, per_page))
        paged = len(pages) > 1
        buttons = per_page + paged
        first = 1 if _height(buttons, 1, rows) >= MIN_ROWS else 2
        for columns in (first, 3 - first):
            if columns > buttons:
                continue
            height = _height(buttons, columns, rows)
            if height < 1:
                continue
            text = _text_width(width, columns, height, roomy)
            shown = [*(i for page in pages for i in page), *([None] if paged else [])]
            if text > 0 and all(lines(i, text) <= height for i in shown):
                return Plan(columns, height, pages)
    pages = tuple((i,) for i in range(count))
    return Plan(1, max(1, _height(1 + (count > 1), 1, rows)), pages, fits=False)


def page_of(plan: Plan, index: int) -> int:
    """The page answer ``index`` is on (0 if it is on none)."""
    return next((n for n, page in enumerate(plan.pages) if index in page), 0)
