"""A gentle sign that the kiosk is still waiting for an answer: words and a slow dot, no numbers.

Seconds left would hurry the patient; a still screen makes them wonder whether the kiosk still
listens. The dot moves once a second with the session's clock (the app's poll timer calls
:meth:`WaitingSign.tick`), so tests and snapshots on a simulated clock always draw the same frame.
"""

from __future__ import annotations

from kiosk.ui.widgets.literal import Static
from kiosk.ui.widgets.text import ui_text

#: positions of the moving dot
STEPS = 3


class WaitingSign(Static):
    """'Take your time. I am waiting for your answer.  ● ○ ○'; hidden when nothing is awaited."""

    def __init__(self, language: str) -> None:
        """A hidden sign with the words of ``language``."""
        super().__init__("", id="waiting")
        self.language = language
        self.display = False
        self._step: int | None = None

    def show(self, waiting: bool, now: float) -> None:
        """Show the sign (its dot where session time ``now`` puts it) while an answer is awaited."""
        self.display = waiting
        self._step = None
        self.tick(now)

    def tick(self, now: float) -> None:
        """Move the dot on (once a second of session time) while the sign is shown."""
        step = int(now) % STEPS
        if not self.display or step == self._step:
            return
        self._step = step
        dots = " ".join("●" if i == step else "○" for i in range(STEPS))
        self.update(f"{ui_text(self.language, 'waiting')}  {dots}")
