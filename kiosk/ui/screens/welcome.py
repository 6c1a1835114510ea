"""Welcome: the patient chooses a language, which starts the test."""

from __future__ import annotations

from collections.abc import Hashable

from textual import events, on
from textual.app import ComposeResult
from textual.containers import Vertical
from textual.message import Message

from kiosk.ui.screens.base import PatientScreen, PatientView, Ways
from kiosk.ui.widgets.literal import Button, Static
from kiosk.ui.widgets.text import language_name, ui_text, ways_sentence


def welcome_line(view: PatientView, language: str) -> str:
    """The welcome in ``language`` itself, and how to choose with the channels on now: "Welcome.
    Please choose your language." alone when touching is the only way (the buttons say the rest)."""
    ways = language_ways(view.ways)
    how = (
        ways_sentence(language, "choose_by", ways, "_language")
        if len(ways) > 1
        else ui_text(language, "choose_language")
    )
    return f"{view.questionnaire.message('welcome', language)} {how}".strip()


def language_ways(ways: Ways) -> tuple[str, ...]:
    """How a language can be chosen now: touch; a remote's number; "start" while the kiosk listens."""
    return ("touch",) + (("remote",) if ways.remote else ()) + (("voice",) if ways.listening else ())


class LanguageList(Vertical):
    """The language buttons, all equally tall (an odd number of rows, so each label sits in the
    middle) and equally labelled: names padded to the longest, so the labels line up centred."""

    def on_resize(self, event: events.Resize) -> None:
        """The display changed: share the rows out again."""
        self.lay_out()

    def lay_out(self) -> None:
        """Give every button the same height, a row of margin above each so no two run together;
        spare rows stay below the last. Where three rows each do not fit (four languages on a
        short panel) they shrink to two, then one, so no language is ever cut off."""
        buttons = list(self.query(Button))
        rows = self.content_region.height
        if not buttons or rows <= 0:
            return
        height = max(1, (rows - len(buttons)) // len(buttons))
        if height % 2 == 0 and height > 2:  # an odd height centres the label; two rows beat one
            height -= 1
        for button in buttons:
            button.styles.height = height
            button.styles.min_height = min(3, height)


def language_labels(languages: list[str] | tuple[str, ...]) -> list[str]:
    """ "1  English ", "2  Español ", "3  Français": numbered like the remote, padded to one width."""
    labels = [f"{number}  {language_name(language)}" for number, language in enumerate(languages, start=1)]
    width = max(map(len, labels))
    return [label.ljust(width) for label in labels]


class WelcomeScreen(PatientScreen):
    """The welcome and "choose your language", each line in its own language, and one big button
    per language (numbered like the remote)."""

    class LanguageChosen(Message):
        """The patient touched a language: start in it."""

        def __init__(self, language: str) -> None:
            self.language = language
            """One of the questionnaire's languages."""
            super().__init__()

    @classmethod
    def key(cls, view: PatientView) -> Hashable:
        """Rebuilt when the language changes."""
        return view.snapshot.language

    def compose(self) -> ComposeResult:
        """Bars, the welcome lines, the language buttons."""
        yield from self.compose_bars()
        q = self.view.questionnaire
        with Vertical(id="welcome"):
            for language in q.languages:
                yield Static(welcome_line(self.view, language), classes="welcome-line", id=f"welcome-{language}")
        with LanguageList(id="languages"):
            for language, label in zip(q.languages, language_labels(q.languages)):
                yield Button(label, id=f"language-{language}")

    def show(self, view: PatientView) -> None:
        """Also keep the welcome lines true to the channels on now."""
        super().show(view)
        said = view.snapshot.prompt  # a walk-up's start of a caregiver's instrument: who it is for instead
        said = said if said is not None and said.key == "caregiver_only" else None
        for language in view.questionnaire.languages:
            for line in self.query(f"#welcome-{language}").results(Static):
                line.update(welcome_line(view, language) if said is None else said.text * (language == said.language))

    def progress_text(self, view: PatientView) -> str:
        """The title in every language (the patient has not chosen one yet), as many as fit the
        top bar's one row: four languages' titles are longer than a narrow screen."""
        q = view.questionnaire
        titles = list(dict.fromkeys(q.title_for_patient(lang) for lang in q.languages))
        room = self.size.width - 2  # the bar's padding; 0 or less before the screen is laid out
        shown = titles[:1]
        for title in titles[1:]:
            if room > 0 and len(" · ".join([*shown, title])) > room:
                break
            shown.append(title)
        return " · ".join(shown)

    @on(Button.Pressed, "#languages Button")
    def _language(self, event: Button.Pressed) -> None:
        event.stop()
        self.post_message(self.LanguageChosen((event.button.id or "").removeprefix("language-")))
