"""The clinician's plots tell what happened and only that: no label printed over another in the
PNG, no "slow speech" where the kiosk had no voice, the kiosk's colours (as on the station)."""

from __future__ import annotations

import dataclasses

from kiosk.export.qos_plot import METRIC_COLOURS, plot_marks
from kiosk.store.records import AdaptationRecord, LogEntry, MetricSample
from kiosk.ui.widgets.metrics_plot import metrics_figure, plot_data

from .helpers import start_in_english


def _crowded(stored):
    """``stored`` with many incidents and adaptations seconds apart (a restless patient)."""
    log = list(stored.log)
    for t in (10.0, 10.5, 11.0, 12.0, 12.2, 13.0, 40.0, 40.4):
        log.append(LogEntry(t, "pause" if t % 2 < 1 else "resume", ""))
    log += [LogEntry(11.5, "call_doctor", "touch"), LogEntry(12.5, "doctor_call_cancelled", "touch")]
    adaptations = (
        AdaptationRecord(10.8, "voice_off", True, ""),
        AdaptationRecord(11.2, "longer_attempts", True, ""),
        AdaptationRecord(40.2, "voice_off", False, ""),
    )
    metrics = (
        tuple(
            MetricSample(float(t), {"Performance": 0.5, "Interaction": 0.4, "VoiceInteractionQuality": 0.3}, ())
            for t in range(0, 60, 5)
        )
        if not stored.metrics
        else stored.metrics
    )
    return dataclasses.replace(
        stored, log=tuple(sorted(log, key=lambda e: e.t)), adaptations=adaptations, metrics=metrics
    )


async def test_the_png_prints_no_label_over_another(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)
    async with kiosk.app.run_test() as pilot:
        await start_in_english(kiosk, pilot)
    stored = _crowded(kiosk.store.session(kiosk.session.id))
    data = plot_data(stored)
    assert len(data.marks) >= 12
    from matplotlib import pyplot

    figure = metrics_figure(data, "crowded")
    try:
        figure.canvas.draw()
        renderer = figure.canvas.get_renderer()
        axes = figure.axes[0]
        labels = [t for t in axes.texts if t.get_text()]
        assert {t.get_text() for t in labels} >= {
            "doctor called",
            '"I\'m fine, carry on"',
            "voice answers off on",
            "longer attempts on",
        }
        boxes = [t.get_window_extent(renderer) for t in labels]
        for i, box in enumerate(boxes):
            for j, other in enumerate(boxes[i + 1 :], start=i + 1):
                assert not box.overlaps(other), (labels[i].get_text(), labels[j].get_text())
        colours = {
            line.get_label(): line.get_color() for line in axes.get_lines() if line.get_label() in METRIC_COLOURS
        }
        assert colours == METRIC_COLOURS
    finally:
        pyplot.close(figure)


async def test_no_slow_speech_mark_where_the_kiosk_had_no_voice(ui_kiosk):
    kiosk = ui_kiosk(familiarisation=False)  # no speaker: voice out is off from the start
    async with kiosk.app.run_test() as pilot:
        await start_in_english(kiosk, pilot)
    stored = kiosk.store.session(kiosk.session.id)
    assert ("voice_out", "unavailable") in [(e.kind, e.detail) for e in stored.log]
    slowed = dataclasses.replace(
        stored,
        adaptations=(
            AdaptationRecord(20.0, "slow_speech", True, ""),
            AdaptationRecord(21.0, "longer_attempts", True, ""),
        ),
    )
    assert [m.label for m in plot_marks(slowed)] == ["longer attempts on"]
    # with a voice the same change is marked
    voiced = dataclasses.replace(slowed, log=tuple(e for e in stored.log if e.kind != "voice_out"))
    assert [m.label for m in plot_marks(voiced)] == ["slow speech on", "longer attempts on"]
