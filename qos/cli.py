"""``python -m qos replay TRACE`` (also ``kiosk qos replay``): replay a context trace, print the figures;
``python -m qos check MODEL``: check a model and say what it holds."""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, cast

from fileio.bounded import open_private, write_error
from qos import load_model
from qos.errors import QosError
from qos.model import Model, type_name

if TYPE_CHECKING:  # the replay tools load on use: `kiosk` imports run_command from here at every start
    from qos.trace import ReplaySamples


def _positive_seconds(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not a number: {text!r}") from None
    if not math.isfinite(value) or value <= 0:
        raise argparse.ArgumentTypeError(f"must be a positive number of seconds, not {text}")
    return value


def build_parser(prog: str, epilog: str | None = None) -> argparse.ArgumentParser:
    """The argument parser of the replay tool (``prog`` names it in usage lines)."""
    parser = argparse.ArgumentParser(prog=prog, description="QoS engine tools.", epilog=epilog)
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    replay = commands.add_parser(
        "replay",
        help="replay a context trace and print the metrics",
        description="Replay a context trace (YAML or JSON) through its model and "
        "print min/max/avg/sd/last of every property and the "
        "observations fired over time.",
    )
    replay.add_argument("trace", type=Path, metavar="TRACE", help="the trace file (.yaml, .yml or .json)")
    replay.add_argument("--json", action="store_true", help="print one JSON object (trace-format.md)")
    replay.add_argument(
        "--sample-period",
        type=_positive_seconds,
        default=1.0,
        metavar="S",
        help="seconds between metric samples (default 1)",
    )
    replay.add_argument("--plot", type=Path, metavar="FILE.png", help="also draw the metrics over time")
    check = commands.add_parser(
        "check",
        help="check a RoQME model and say what it holds",
        description="Parse and check a model (a bundled name or a .roqme file): one "
        "file:line:col line and exit 2 when it is malformed, otherwise what a "
        "trace must provide and what the model computes and observes.",
    )
    check.add_argument("model", metavar="MODEL", help="a bundled model name (clarc) or a .roqme file")
    return parser


def describe_model(model: Model) -> str:
    """What a QoS engineer needs to know of a checked model, one section a kind."""

    def names(items) -> str:
        return ", ".join(items) or "none"

    primitive = [f"{c.name} ({type_name(c.type)})" for c in model.contexts.values() if not c.derived]
    lines = [
        f"model {model.name}: OK",
        *(model.description or "").splitlines()[:1],
        "",
        f"contexts a trace sets or emits: {names(primitive)}",
        f"derived contexts: {names(c.name for c in model.contexts.values() if c.derived)}",
        f"properties (published): {names(model.properties)}",
        f"belief variables: {names(model.beliefvars)}",
        f"variables and parameters: {names(model.variables)}",
        f"timers: {names(model.timers)}",
        f"observations: {names(model.observations)}",
    ]
    if model.imports:
        lines.append(f"imports: {names(Path(path).name for path in model.imports)}")
    return "\n".join(lines)


def format_table(result: dict) -> str:
    """The replay result for people: a statistics table, then the observations over time."""
    metrics = result["metrics"]
    beliefs = result.get("beliefs", {})
    width = max(len("property"), *(len(name) for name in [*metrics, *beliefs]))
    lines = [f"{'property':<{width}}  " + "  ".join(f"{column:>6}" for column in ("min", "max", "avg", "sd", "last"))]
    for heading, table in (("", metrics), ("belief variables (not published):", beliefs)):
        if table and heading:
            lines.append(heading)
        for name, stats in table.items():
            lines.append(
                f"{name:<{width}}  " + "  ".join(f"{stats[key]:6.4f}" for key in ("min", "max", "avg", "sd", "last"))
            )
    lines += ["", "fired observations:" if result["fired"] else "no observation fired"]
    for entry in result["fired"]:
        lines.append(f"  t={entry['t']:>8g} s  {' '.join(entry['observations'])}")
    return "\n".join(lines)


def plot(samples: ReplaySamples, path: Path, title: str) -> None:
    """Draw every property over time into a PNG (matplotlib, imported only when asked for)."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib import pyplot

    figure, axes = pyplot.subplots(figsize=(10, 5), dpi=100)
    for name, values in samples.series.items():
        axes.plot(samples.times, values, label=name, linewidth=1.8)
    for entry in samples.fired:
        axes.axvline(float(cast(float, entry["t"])), color="0.85", linewidth=0.8, zorder=0)
    axes.set_xlabel("time since the session started (s)")
    axes.set_ylabel("metric")
    axes.set_ylim(-0.02, 1.02)
    axes.set_title(title)
    axes.grid(True, axis="y", alpha=0.3)
    axes.legend(loc="best")
    figure.tight_layout()
    try:
        with open_private(path, binary=True) as handle:
            figure.savefig(handle, format="png")
    finally:
        pyplot.close(figure)


def main(argv: Sequence[str] | None = None, prog: str = "python -m qos", epilog: str | None = None) -> int:
    """Run the tool; returns 0, or 2 after one line on stderr for a bad trace, model or plot path."""
    args = build_parser(prog, epilog).parse_args(list(sys.argv[1:] if argv is None else argv))
    if args.command == "check":
        try:
            print(describe_model(load_model(args.model)))
        except QosError as exc:
            print(f"{prog} check: {exc}", file=sys.stderr)
            return 2
        return 0
    from qos.trace import load_trace, sample_trace, summarise

    try:
        trace = load_trace(args.trace)
        samples = sample_trace(trace, args.sample_period)
    except QosError as exc:
        print(f"{prog} replay: {exc}", file=sys.stderr)
        return 2
    result = summarise(samples)
    if args.plot is not None:
        try:
            plot(samples, args.plot, trace.description or args.trace.name)
        except OSError as exc:
            print(f"{prog} replay: {write_error(args.plot, exc)}", file=sys.stderr)
            return 2
    if args.json:
        print(json.dumps(result))
    else:
        print(f"{trace.description or args.trace.name}\nmodel: {trace.model}\n")
        print(format_table(result))
        if args.plot is not None:
            print(f"\nplot written to {args.plot}")
    return 0


def run_command(entry: Callable[[], int]) -> int:
    """Run a command-line entry point and return its exit status.

    A reader that stops early (``python -m qos replay T --json | head``) closes the pipe; that is
    the reader's choice, not an error, so it ends quietly instead of with a BrokenPipeError traceback.
    """
    try:
        status = entry()
        sys.stdout.flush()  # surface a closed pipe here, not in the interpreter's exit flush
        return status
    except BrokenPipeError:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
