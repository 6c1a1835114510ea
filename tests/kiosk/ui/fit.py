"""What "fits the display" means, checked on a laid-out screen: nothing scrolls, every answer and
control lies wholly on screen with its whole text, answers do not overlap and are equally tall.
The Pilot fit test and the served-page test in Chromium both use it."""

from __future__ import annotations

from textual.screen import Screen
from textual.widget import Widget
from textual.widgets import Button, Label

from kiosk.ui.widgets.answer_button import AnswerButton


def problems(screen: Screen) -> list[str]:
    """Every way the screen on top fails to fit its display (empty: it fits)."""
    found: list[str] = []
    whole = screen.region
    for widget in screen.query("*"):
        if widget.display and widget.is_scrollable and widget.max_scroll_y > 0:
            found.append(f"{widget!r} scrolls ({widget.max_scroll_y} rows hidden)")
    for widget in [*screen.query(AnswerButton), *screen.query(Button)]:
        if _shown(widget) and not whole.contains_region(widget.region):
            found.append(f"{widget!r} at {widget.region} is not wholly on the {whole.size} screen")
    answers = [b for b in screen.query(AnswerButton) if _shown(b)]
    for button in answers:
        for label in button.query(".label").results(Label):
            # the label fills the button; its wrapped text must fit in it (and it in the button)
            box = label.content_region
            wanted = label.get_content_height(label.size, screen.size, box.width)
            if not button.region.contains_region(label.region) or wanted > box.height:
                found.append(f"answer {button.option}'s text ({wanted} lines) is cut by its button at {button.region}")
        for other in answers:
            if other.shows > button.shows and button.region.overlaps(other.region):
                found.append(f"answers {button.option} and {other.option} overlap")
    if len({b.region.height for b in answers}) > 1:
        found.append(f"answers of unequal heights {[b.region.height for b in answers]}")
    return found


def _shown(widget: Widget) -> bool:
    """Displayed, with all its ancestors displayed."""
    node: Widget | None = widget
    while node is not None and isinstance(node, Widget):
        if not node.display:
            return False
        node = node.parent if isinstance(node.parent, Widget) else None
    return True
