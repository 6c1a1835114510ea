"""The QoS story of one session: Performance, Interaction and VoiceInteractionQuality over time,
with incidents (pause, call doctor, patient away...) and adaptations marked.

Drawn in the terminal with textual-plotext, and saved as a PNG with matplotlib for the record.
Both draw the same :func:`plot_data`, so the terminal and the PNG never tell different stories;
the colours and the marks' words come from :mod:`kiosk.export.qos_plot`, as on the ward station.
Neither puts its legend over the data: the first seconds of a session matter as much as the rest,
so the terminal shows a coloured key line (:func:`metrics_key`) above the plot and the PNG puts
its legend below the axes.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from rich.text import Text
from textual_plotext import PlotextPlot

from basis import record
from fileio.bounded import open_private
from kiosk.export.qos_plot import MARK_COLOURS, METRICS, Mark, metric_colour, plot_marks
from kiosk.store.database import StoredSession

#: log entries worth a mark on the plot (the rest -- ignored inputs, time-outs -- would crowd it)
INCIDENTS = (
    "pause",
    "resume",
    "call_doctor",
    "doctor_call_cancelled",
    "clinician_continue",
    "person_lost",
    "person_back",
    "repeat",
)
#: label lanes the PNG may stack its marks' labels in, from the top of the axes down
LABEL_LANES = 14


def _rgb(colour: str) -> tuple[int, int, int]:
    """``"#1b6ac9"`` as (27, 106, 201): plotext takes RGB tuples."""
    return int(colour[1:3], 16), int(colour[3:5], 16), int(colour[5:7], 16)


@record
class PlotData:
    """What a metrics plot draws: one time series per metric, and the marks."""

    series: dict[str, tuple[list[float], list[float]]]
    marks: tuple[Mark, ...]


def plot_data(stored: StoredSession) -> PlotData:
    """The metric samples and marks of a stored session."""
    series: dict[str, tuple[list[float], list[float]]] = {}
    for name in METRICS:
        samples = [(s.t, s.metrics[name]) for s in stored.metrics if name in s.metrics]
        series[name] = ([t for t, _ in samples], [v for _, v in samples])
    return PlotData(series, plot_marks(stored, INCIDENTS))


def metrics_key() -> Text:
    """The terminal plot's key, one line in the plot's colours (it replaces plotext's legend,
    which is drawn inside the plot and hides the first seconds of the curves)."""
    key = Text("QoS: ", style="bold")
    for name in METRICS:
        key.append("━ ", style=f"bold {metric_colour(name)}")
        key.append(f"{name}  ")
    for kind, colour in MARK_COLOURS.items():
        key.append("│ ", style=f"bold {colour}")
        key.append(f"{kind}s  ")
    key.rstrip()
    return key


def steps(times: list[float], values: list[float]) -> tuple[list[float], list[float]]:
    """The corners of a step function through the samples: a metric keeps its value until the
    next event changes it, so each value is held flat up to the next sample's time (the PNG draws
    the same with matplotlib's ``step(where="post")``)."""
    xs, ys = [], []
    for index, (t, value) in enumerate(zip(times, values)):
        if index:
            xs.append(t)
            ys.append(values[index - 1])
        xs.append(t)
        ys.append(value)
    return xs, ys


class MetricsPlot(PlotextPlot):
    """The three metrics in the terminal; incidents as grey lines, adaptations as red lines.

    It has no legend of its own: show :func:`metrics_key` beside it.
    """

    def __init__(self, data: PlotData, *, id: str | None = None) -> None:
        """Draw ``data`` (from :func:`plot_data`)."""
        super().__init__(id=id)
        self.data = data

    def on_mount(self) -> None:
        """Draw once: a stored session does not change while it is shown."""
        plt = self.plt
        plt.xlabel("session time (s)")
        plt.ylim(0, 1)
        for name, (times, values) in self.data.series.items():
            if times:  # no label: plotext would draw its legend box over the first seconds
                plt.plot(*steps(times, values), color=_rgb(metric_colour(name)), marker="braille")
        for mark in self.data.marks:
            plt.vline(mark.t, _rgb(MARK_COLOURS[mark.kind]))


def metrics_figure(data: PlotData, title: str) -> Any:
    """The plot as a matplotlib Figure (the caller closes it): the metrics as steps, the marks as
    dashed lines, each mark's label in the highest lane where it overlaps no other label (measured
    as drawn), and the legend below the axes, where it cannot cover a curve."""
    import matplotlib

    matplotlib.use("Agg")  # no display on a kiosk's service shell
    from matplotlib import pyplot
    from matplotlib.lines import Line2D

    figure, axes = pyplot.subplots(figsize=(10, 5), dpi=100)
    for name, (times, values) in data.series.items():
        if times:
            axes.step(times, values, where="post", label=name, color=metric_colour(name), linewidth=2)
    axes.set_ylim(0, 1.05)
    for mark in data.marks:
        axes.axvline(mark.t, color=MARK_COLOURS[mark.kind], linestyle="--", linewidth=1)
    axes.set_xlabel("session time (s)")
    axes.set_ylabel("metric")
    axes.set_title(title.replace("$", r"\$"))  # a '$' pair would be read as mathtext
    handles, _ = axes.get_legend_handles_labels()
    kinds = {m.kind for m in data.marks}
    handles += [
        Line2D([], [], color=MARK_COLOURS[k], linestyle="--", linewidth=1, label=f"{k}s")
        for k in MARK_COLOURS
        if k in kinds
    ]
    if handles:
        axes.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=len(handles), frameon=False)
    axes.grid(alpha=0.3)
    _label_marks(figure, axes, data.marks)
    return figure


def _label_marks(figure: Any, axes: Any, marks: tuple[Mark, ...]) -> None:
    """Write each mark's label beside its line, in the first lane (from the top) where its drawn
    box meets no label already placed; marks too crowded for every lane keep only their line."""
    renderer = figure.canvas.get_renderer()
    placed: list[Any] = []
    for mark in marks:
        for lane in range(LABEL_LANES):
            text = axes.annotate(
                mark.label,
                (mark.t, 1.0 - 0.065 * lane),
                xycoords=("data", "axes fraction"),
                fontsize=8,
                color=MARK_COLOURS[mark.kind],
                xytext=(3, -10),
                textcoords="offset points",
            )
            box = text.get_window_extent(renderer).expanded(1.0, 1.1)
            if not any(box.overlaps(other) for other in placed):
                placed.append(box)
                break
            text.remove()


def save_png(data: PlotData, path: str | Path, title: str) -> Path:
    """Write the plot as a PNG (owner-only, it belongs to a patient's record); returns the path."""
    from matplotlib import pyplot

    figure = metrics_figure(data, title)
    try:
        path = Path(path)
        with open_private(path, binary=True) as handle:
            figure.savefig(handle, format="png", bbox_inches="tight")
    finally:
        pyplot.close(figure)
    return path
