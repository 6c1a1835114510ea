"""The welcome offers a site's patients only the translations it may use clinically: validated
ones and those its configuration accepts (``accept_unvalidated_translations``); a kiosk without a
configuration file offers every language, as it always did."""

from __future__ import annotations

import pytest
from textual.widgets import Button

from kiosk.commands.run import build_app
from kiosk.ui.app import KIOSK_SIZE

from .helpers import settle


@pytest.mark.parametrize(
    ("settings", "buttons"),
    [
        ("", ["1  English"]),
        ("accept_unvalidated_translations: [de]\n", ["1  English", "2  Deutsch"]),
        ("accept_unvalidated_translations: true\n", ["1  English", "2  Español", "3  Français", "4  Deutsch"]),
    ],
)
async def test_the_welcome_offers_validated_and_accepted_languages(tmp_path, settings, buttons):
    config = tmp_path / "config.yaml"
    config.write_text("data_dir: data\n" + settings)
    app, close = build_app(config_path=config, voice=False, remote=False)
    try:
        async with app.run_test(size=KIOSK_SIZE) as pilot:
            await settle(
                pilot, lambda: type(app.screen).__name__ == "WelcomeScreen" and app.screen.query("#languages Button")
            )
            labels = [str(b.label).strip() for b in app.screen.query("#languages Button").results(Button)]
            assert labels == buttons
            await pilot.press(str(len(buttons)))  # the last language offered, by its number
            await settle(pilot, lambda: type(app.screen).__name__ != "WelcomeScreen")
            assert app.session.language == ("de" if len(buttons) > 1 and "Deutsch" in buttons[-1] else "en")
    finally:
        close()
