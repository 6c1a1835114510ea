"""A simulated 10-hour kiosk day through one engine: per-event cost and memory, start vs end.

Sessions (the six test-bench sessions in turn) follow each other with a 5-minute pause; the engine
also answers a metrics() read after every update, as the kiosk's adaptation does. Two models run the
day: CLARC, and SOAK_MODEL, which adds timers and windows to it (kiosk_pace's period, length and
five-minute aggregates and its inactivity timer, plus a 30-second periodic timer and a one-minute
window); for it a QuestionAsked is emitted 8 s before each answer. An update's cost includes the
timer and window batches the engine runs before it. Prints JSON with the mean and p99 cost of an
update in the first and the last simulated hour, and the memory traced (tracemalloc) after the first
hour and at the end of the day, per model.
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

from _qos_sessions import back_to_back

from qos import Engine, Model, load_model, parse_model

DAY = 10 * 3600.0
HOUR = 3600.0
MODELS = Path(__file__).resolve().parents[1] / "qos" / "models"
SOAK_MODEL = """roqme Soak
import "kiosk_pace.roqme"
timer Tick := 30 seconds
context MinuteAnswers : number := count(Answered, 1 minutes)
observation Quiet : Tick while(AnswerTime'avg(5) > 10) undermines Interaction verylow survival 5 minutes
observation Busy : update(MinuteAnswers) while(MinuteAnswers > 2) reinforces Fatigue low
"""
ANSWERS = ("FirstAttemptAnswered", "SecondAttemptAnswered")


def with_questions(day):
    """The day's events with a QuestionAsked 8 s before each answer (what kiosk_pace measures), or
    just after the event before it when that is closer."""
    previous = 0.0
    for number, t, values, emitted in day:
        if any(values.get(name) is True for name in ANSWERS):
            yield number, max(t - 8.0, previous), {}, ["QuestionAsked"]
        yield number, t, values, emitted
        previous = t


def cost(samples: list[tuple[int, int]]) -> dict[str, float]:
    """Mean and p99 of an update (+ read) in microseconds: elapsed, and CPU time of the thread (which
    leaves out the time other processes held the CPU: on a shared machine elapsed p99 is mostly that)."""

    def summary(values: list[int]) -> tuple[float, float]:
        return (
            round(statistics.fmean(values) / 1000, 2),
            round(statistics.quantiles(values, n=100, method="inclusive")[98] / 1000, 2),
        )

    mean, p99 = summary([wall for wall, _ in samples])
    cpu_mean, cpu_p99 = summary([cpu for _, cpu in samples])
    return {"mean_us": mean, "p99_us": p99, "cpu_mean_us": cpu_mean, "cpu_p99_us": cpu_p99, "events": len(samples)}


def simulate_day(engine: Engine, day, on_event) -> tuple[int, int]:
    """Feed one simulated day to the engine; ``on_event(t, (elapsed_ns, cpu_ns))`` gets each event's cost."""
    sessions = events = 0
    for number, t, values, emitted in day:
        if t > DAY:
            break
        began, began_cpu = time.perf_counter_ns(), time.thread_time_ns()
        engine.update(t, set=values, emit=emitted)
        engine.metrics(t)
        on_event(t, (time.perf_counter_ns() - began, time.thread_time_ns() - began_cpu))
        sessions, events = number + 1, events + 1
    return sessions, events


def soak(model: Model, day) -> dict:
    """Run one simulated day through ``model`` (``day()`` makes a fresh event stream)."""
    # timing pass (tracemalloc would slow every allocation down)
    first_hour: list[tuple[int, int]] = []
    last_hour: list[tuple[int, int]] = []

    def timed(t: float, spent: tuple[int, int]) -> None:
        if t <= HOUR:
            first_hour.append(spent)
        elif t > DAY - HOUR:
            last_hour.append(spent)

    sessions, events = simulate_day(Engine(model), day(), timed)
    # memory pass: what the engine holds after the first hour and at the end of the day
    events_of_day = day()
    first = next(events_of_day)  # loads the session data before tracing starts
    tracemalloc.start()
    engine = Engine(model)
    engine.update(first[1], set=first[2], emit=first[3])
    after_first_hour: list[int] = []

    def traced(t: float, spent: tuple[int, int]) -> None:
        if t > HOUR and not after_first_hour:
            after_first_hour.append(tracemalloc.get_traced_memory()[0])

    simulate_day(engine, events_of_day, traced)
    memory_end, memory_peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return {
        "model": model.name,
        "timers": sorted(model.timers),
        "streams": len(model.streams),
        "sessions": sessions,
        "events": events,
        "first_hour": cost(first_hour),
        "last_hour": cost(last_hour),
        "traced_memory_after_first_hour_kib": round(after_first_hour[0] / 1024, 1),
        "traced_memory_end_kib": round(memory_end / 1024, 1),
        "traced_memory_peak_kib": round(memory_peak / 1024, 1),
        "live_firings_end": engine.live_firings,
    }


def main() -> int:
    clarc = soak(load_model("clarc"), lambda: back_to_back(gap=300.0))
    timed = soak(parse_model(SOAK_MODEL, "soak.roqme", MODELS), lambda: with_questions(back_to_back(gap=300.0)))
    print(
        json.dumps(
            {"benchmark": "qos_soak", "simulated_hours": DAY / 3600, "clarc": clarc, "timers_and_windows": timed},
            indent=1,
        )
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
