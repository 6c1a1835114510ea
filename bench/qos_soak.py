"""A simulated 10-hour kiosk day through one CLARC engine: per-event cost and memory, start vs end.

Sessions (the six test-bench sessions in turn) follow each other with a 5-minute pause; the engine
also answers a metrics() read after every update, as the kiosk's adaptation does. Prints JSON with
the mean and p99 cost of an update in the first and the last simulated hour, and the memory traced
(tracemalloc) after the first hour and at the end of the day.
Run: uv run python bench/qos_soak.py
"""

from __future__ import annotations

import json
import statistics
import sys
import time
import tracemalloc
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _qos_sessions import back_to_back  # noqa: E402

from qos import Engine, load_model  # noqa: E402

DAY = 10 * 3600.0
HOUR = 3600.0


def cost(samples_ns: list[int]) -> dict[str, float]:
    """Mean and p99 of an update (+ read) in microseconds."""
    return {"mean_us": round(statistics.fmean(samples_ns) / 1000, 2),
            "p99_us": round(statistics.quantiles(samples_ns, n=100, method="inclusive")[98] / 1000, 2),
            "events": len(samples_ns)}


def simulate_day(engine: Engine, day, on_event) -> tuple[int, int]:
    """Feed one simulated day to the engine; ``on_event(t, ns)`` gets each event's cost."""
    sessions = events = 0
    for number, t, values, emitted in day:
        if t > DAY:
            break
        began = time.perf_counter_ns()
        engine.update(t, set=values, emit=emitted)
        engine.metrics(t)
        on_event(t, time.perf_counter_ns() - began)
        sessions, events = number + 1, events + 1
    return sessions, events


def main() -> int:
    model = load_model("clarc")
    # timing pass (tracemalloc would slow every allocation down)
    first_hour: list[int] = []
    last_hour: list[int] = []

    def timed(t: float, spent: int) -> None:
        if t <= HOUR:
            first_hour.append(spent)
        elif t > DAY - HOUR:
            last_hour.append(spent)

    sessions, events = simulate_day(Engine(model), back_to_back(gap=300.0), timed)
    # memory pass: what the engine holds after the first hour and at the end of the day
    day = back_to_back(gap=300.0)
    first = next(day)  # loads the session data before tracing starts
    tracemalloc.start()
    engine = Engine(model)
    engine.update(first[1], set=first[2], emit=first[3])
    after_first_hour: list[int] = []

    def traced(t: float, spent: int) -> None:
        if t > HOUR and not after_first_hour:
            after_first_hour.append(tracemalloc.get_traced_memory()[0])

    simulate_day(engine, day, traced)
    memory_end, memory_peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    print(json.dumps({
        "benchmark": "qos_soak",
        "model": "clarc",
        "simulated_hours": DAY / 3600,
        "sessions": sessions,
        "events": events,
        "first_hour": cost(first_hour),
        "last_hour": cost(last_hour),
        "traced_memory_after_first_hour_kib": round(after_first_hour[0] / 1024, 1),
        "traced_memory_end_kib": round(memory_end / 1024, 1),
        "traced_memory_peak_kib": round(memory_peak / 1024, 1),
        "live_firings_end": engine.live_firings,
    }, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
