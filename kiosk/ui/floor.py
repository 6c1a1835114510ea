"""The smallest display the kiosk runs a test on: below it, it takes no patient and says why.

At :data:`FLOOR` every shipped instrument's answers are shown whole (on pages where they need
them, :mod:`kiosk.ui.answer_pages`), with the question, the top bar and the controls: an 800x480
panel served at the page's smallest text (24 px, 57x15 cells in Chromium) and a 64x18 terminal
are above it. Plain code, so the controller and its tests use it without Textual.
"""

from __future__ import annotations

#: (columns, rows) the patient's screens need at the least (tests/kiosk/ui/test_every_display.py)
FLOOR = (56, 15)


def too_small(columns: int, rows: int) -> str | None:
    """Why a ``columns`` x ``rows`` display cannot take a patient, for staff (None: it can)."""
    least_columns, least_rows = FLOOR
    if columns >= least_columns and rows >= least_rows:
        return None
    return (
        f"the display is too small: {columns}x{rows} characters, and the patient's screens need at "
        f"least {least_columns}x{least_rows} (a larger window or screen, or a smaller text size)"
    )
