"""What the patient and the clinician see of the familiarisation and of the gaps between questions:
no hearing check on a kiosk that cannot speak, practice outcomes on the clinician's session view,
a calm line on screen while the next question comes, and a metrics plot whose key hides no data.
Real session, QoS engine and SQLite store on a simulated clock, driven through Pilot."""

from __future__ import annotations

from textual.widgets import Label, Static

from kiosk.core.channels import Channel, ChannelState, ChannelStatus
from kiosk.core.session import Phase
from kiosk.ui.app import CLINICIAN_CHORD, KIOSK_SIZE
from kiosk.ui.widgets.metrics_plot import METRICS, MetricsPlot, metrics_figure, plot_data, save_png
from kiosk.ui.widgets.question_panel import QuestionPanel

from .conftest import UI_PIN
from .helpers import deliver_from_thread, screen_name, settle, text_of


def _progress(kiosk) -> str:
    return text_of(kiosk.app.screen.query_one("#progress", Label))


def _question_text(kiosk) -> str:
    return text_of(kiosk.app.screen.query_one("#question", Static))


def _interlude(kiosk) -> str | None:
    """The between-questions line, or None while it is hidden."""
    line = kiosk.app.screen.query_one("#interlude", Static)
    return text_of(line) if line.display else None


async def test_a_kiosk_without_voice_out_never_asks_which_word_was_heard(ui_kiosk):
    kiosk = ui_kiosk()  # no speaker: voice out is off
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        await pilot.press("1")
        await settle(pilot, lambda: kiosk.session.snapshot().practice is not None)
        assert screen_name(kiosk) == "FamiliarisationScreen"
        assert _question_text(kiosk) == "Please choose the answer that says yes."
        assert _progress(kiosk) == "Practice 1 of 2"
        await pilot.press("1")
        await settle(pilot, lambda: _interlude(kiosk) == "Well done.")  # a kind word first
        kiosk.to_next_deadline()
        await settle(pilot, lambda: _question_text(kiosk) == "Please choose answer number 3.")
        assert _progress(kiosk) == "Practice 2 of 2"
        assert not kiosk.app.screen.query(".-chosen")  # nothing marked before an answer
        await pilot.press("3")
        await settle(pilot, lambda: _interlude(kiosk) == "Well done.")
        # the practice answer is shown chosen, as a real one is, until the next screen
        await settle(pilot, lambda: kiosk.app.screen.query_one("#answer-3").has_class("-chosen"))
        assert [b.id for b in kiosk.app.screen.query(".-chosen")] == ["answer-3"]
        kiosk.to_next_deadline()
        await settle(pilot, lambda: screen_name(kiosk) == "ExplanationScreen")
    outcomes = [(p.question_id, p.outcome, p.detail) for p in kiosk.store.session(kiosk.session.id).practice]
    assert outcomes == [
        ("practice_hear", "skipped", "no voice out"),
        ("practice_read", "right", "key 1"),
        ("practice_select", "right", "key 3"),
    ]


async def test_voice_out_on_asks_the_hearing_check_and_losing_it_skips_that_check(ui_kiosk):
    kiosk = ui_kiosk()
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        deliver_from_thread(kiosk, ChannelStatus(Channel.VOICE, ChannelState.ON, "espeak-ng"))
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        await pilot.press("1")
        await settle(pilot, lambda: kiosk.session.snapshot().practice is not None)
        assert _question_text(kiosk) == "Which word did you hear?"
        assert _progress(kiosk) == "Practice 1 of 3"
        deliver_from_thread(kiosk, ChannelStatus(Channel.VOICE, ChannelState.LOST, "espeak-ng", "audio device gone"))
        await settle(pilot, lambda: kiosk.session.snapshot().practice.id == "practice_read")
        await settle(pilot, lambda: _question_text(kiosk) == "Please choose the answer that says yes.")
        assert _progress(kiosk) == "Practice 2 of 3"
    stored = kiosk.store.session(kiosk.session.id)
    assert [(p.question_id, p.outcome) for p in stored.practice] == [("practice_hear", "skipped")]
    assert [e.detail for e in stored.log if e.kind == "voice_out"] == ["unavailable"]


async def test_every_gap_between_questions_shows_a_calm_line_over_the_last_content(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        await pilot.press("1")
        await settle(pilot, lambda: screen_name(kiosk) == "ExplanationScreen")
        await pilot.click("#understood")
        await settle(pilot, lambda: screen_name(kiosk) == "QuestionScreen")
        # between Start and question 1: not an empty screen
        assert _interlude(kiosk) == "Thank you. Here is the first question…"
        assert not kiosk.app.screen.query(QuestionPanel)
        assert text_of(kiosk.app.screen.query_one("#recap", Static)).startswith("I will ask you ten questions")

        kiosk.to_next_deadline()
        await settle(pilot, lambda: kiosk.session.current_attempt == 1)
        await settle(pilot, lambda: _interlude(kiosk) is None)
        assert not kiosk.app.screen.query("#recap")
        await pilot.press("2")
        await settle(pilot, lambda: "feeding" in kiosk.session.answers)
        # after an answer: the question stays with its answer marked, under "next question"
        await settle(pilot, lambda: _interlude(kiosk) == "Thank you. Next question…")
        assert _question_text(kiosk) == "How do you manage eating?"
        assert kiosk.app.screen.query_one("#answer-2").has_class("-chosen")

        kiosk.to_next_deadline()
        await settle(pilot, lambda: kiosk.session.current_item.id == "bathing")
        kiosk.to_next_deadline()
        kiosk.to_next_deadline()  # both attempts run out
        await settle(pilot, lambda: "bathing" in kiosk.session.snapshot().not_answered)
        # after a question without an answer: what the kiosk said, over the question left behind
        await settle(pilot, lambda: _interlude(kiosk) == "Let us go on to the next question.")
        assert _question_text(kiosk) == "Can you take a bath or a shower without help?"
        assert kiosk.session.phase is Phase.QUESTIONS


async def test_the_gap_line_is_in_the_patients_language(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False, language="es")
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        await pilot.press("2")  # Español
        await settle(pilot, lambda: screen_name(kiosk) == "ExplanationScreen")
        await pilot.press("1")
        await settle(pilot, lambda: screen_name(kiosk) == "QuestionScreen")
        assert _interlude(kiosk) == "Gracias. Ahora viene la primera pregunta…"


async def _session_detail(kiosk, pilot) -> None:
    await pilot.press(CLINICIAN_CHORD, *UI_PIN, "enter")
    await settle(pilot, lambda: screen_name(kiosk) == "ClinicianHomeScreen")
    await pilot.press("enter")
    await settle(pilot, lambda: screen_name(kiosk) == "SessionDetailScreen")


async def test_the_clinician_sees_how_the_practice_went(ui_kiosk):
    kiosk = ui_kiosk()  # no voice out: the hearing check is skipped
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        await pilot.press("1")
        await settle(pilot, lambda: kiosk.session.snapshot().practice is not None)
        await pilot.press("2")  # "No" where "Yes" was asked for
        kiosk.to_next_deadline()  # after the kind word
        await settle(pilot, lambda: kiosk.session.snapshot().practice.id == "practice_select")
        await pilot.press("3")
        kiosk.to_next_deadline()
        await settle(pilot, lambda: screen_name(kiosk) == "ExplanationScreen")
        await _session_detail(kiosk, pilot)
        line = text_of(kiosk.app.screen.query_one("#practice", Label))
        assert line == "Practice: hearing skipped (no voice out) / reading ✗ (chose No) / selecting ✓"


async def test_the_metrics_plot_keeps_its_key_off_the_data(ui_kiosk, tmp_path):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test(size=KIOSK_SIZE) as pilot:
        await settle(pilot, lambda: screen_name(kiosk) == "WelcomeScreen")
        await pilot.press("1")
        await settle(pilot, lambda: screen_name(kiosk) == "ExplanationScreen")
        await pilot.press("1")
        for _ in range(3):
            kiosk.to_next_deadline()
            await settle(pilot, lambda: kiosk.session.current_attempt == 1)
            item = kiosk.session.current_item
            await pilot.press("1")
            await settle(pilot, lambda: item.id in kiosk.session.answers)
        await _session_detail(kiosk, pilot)
        key = text_of(kiosk.app.screen.query_one("#metrics-key", Static))
        assert all(name in key for name in METRICS)
        plot = kiosk.app.screen.query_one(MetricsPlot)
        canvas = plot.render().plain.splitlines()
        assert not any(name in row for row in canvas for name in METRICS)  # no legend box inside
        # the first seconds of the curves are drawn, at the left where plotext's legend used to sit
        # (the plot is a fixed 16 rows in the scrolling detail: the curves start mid-height)
        top_left = "".join(row[8:30] for row in canvas[1:-3])
        assert any("\u2800" < ch <= "\u28ff" for ch in top_left)

    # the PNG export: its legend lies outside the axes, so it covers no curve either
    from matplotlib import pyplot

    figure = metrics_figure(plot_data(kiosk.store.session(kiosk.session.id)), "test")
    try:
        figure.canvas.draw()
        axes = figure.axes[0]
        legend = axes.get_legend()
        assert [t.get_text() for t in legend.get_texts()][:3] == list(METRICS)
        assert not legend.get_window_extent().overlaps(axes.get_window_extent())
    finally:
        pyplot.close(figure)

    # the exported PNG belongs to a patient's record: owner-only, even over an older 0644 file
    png = tmp_path / "plot.png"
    png.write_bytes(b"old")
    png.chmod(0o644)
    save_png(plot_data(kiosk.store.session(kiosk.session.id)), png, "test")
    assert png.read_bytes().startswith(b"\x89PNG") and png.stat().st_mode & 0o777 == 0o600
