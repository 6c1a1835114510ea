"""Text is text: an instrument whose every text holds Textual markup (``[bold]``, a lone ``[/]``,
``[@click=app.quit]``, ``[link=...]``) runs to its end, and every screen shows those texts as
written: before, ``kiosk run`` stopped at question 1 with a ``MarkupError``, and "Walks 50 m
[with aid]" read "Walks 50 m " (issue 35, part 2)."""

from __future__ import annotations

from pathlib import Path

import yaml
from rich.text import Text
from textual.widgets import Button, DataTable, Label, Static

from kiosk.ui.app import CLINICIAN_CHORD, KIOSK_SIZE
from tests.instruments import MOOD4

from .conftest import UI_PIN
from .helpers import answer_every_question, screen_name, settle, start_in_english, text_of

#: what every text of the instrument ends with
MARKUP = " [bold]B[/] [/] [@click=app.quit]Q[/] [link=https://example.org]L[/link] [with aid]"


def marked(value, inside: str = ""):
    """The instrument with MARKUP after each English text (titles, questions, options, bands, messages)."""
    if isinstance(value, dict):
        return {
            k: (v + MARKUP if k == "en" and isinstance(v, str) and inside != "synonyms" else marked(v, k))
            for k, v in value.items()
        }
    if isinstance(value, list):
        return [marked(v, inside) for v in value]
    return value


def instrument(tmp_path: Path) -> Path:
    data = marked(yaml.safe_load(MOOD4.read_text(encoding="utf-8")))
    path = tmp_path / "marked.yaml"
    path.write_text(yaml.safe_dump(data, allow_unicode=True, sort_keys=False), encoding="utf-8")
    return path


def shown(screen) -> str:
    """Every text the screen's widgets draw, one per line."""
    return "\n".join(text_of(w) for w in screen.query("*") if isinstance(w, (Static, Label, Button)))


async def test_markup_in_every_text_of_an_instrument_is_shown_as_written(ui_kiosk, tmp_path):
    kiosk = ui_kiosk(familiarisation=False, show_score=True, questionnaire=instrument(tmp_path))
    q = kiosk.questionnaire
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await start_in_english(kiosk, pilot)
        seen: list[str] = []

        async def read_then_answer(number: int, option: int) -> None:
            await settle(pilot, lambda: screen_name(kiosk) == "QuestionScreen")
            item = kiosk.session.current_item
            text = shown(kiosk.app.screen)
            assert item.patient_text_in("en") in text
            for choice in item.options:
                assert choice.patient_label_in("en") in text
            seen.append(text)
            await pilot.press(str(option))

        await answer_every_question(kiosk, pilot, read_then_answer)
        assert len(seen) == len(q.items) and all(MARKUP in t for t in seen)
        summary = shown(kiosk.app.screen)
        assert q.bands_named().bands[-1].label["en"] in summary  # the band, brackets and all
        await pilot.press(CLINICIAN_CHORD, *UI_PIN, "enter")
        await settle(pilot, lambda: screen_name(kiosk) == "ClinicianHomeScreen")
        await pilot.press("enter")
        await settle(pilot, lambda: screen_name(kiosk) == "SessionDetailScreen")
        detail = shown(kiosk.app.screen)
        assert q.title["en"] in detail
        table = kiosk.app.screen.query_one("#answers-table", DataTable)
        last = q.items[0].options[-1].label["en"]
        # a DataTable reads a string cell as Rich markup: what it draws is the label as written
        assert Text.from_markup(table.get_row_at(0)[3]).plain == last
        assert kiosk.app.is_running  # the [@click=app.quit] never ran
