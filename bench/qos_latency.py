"""Latency of Engine.update with the CLARC model over 200 back-to-back sessions in one engine.

Prints JSON: p50/p99 over the whole run, and for the first and last tenth of the sessions
(the last tenth should be no slower than the first: the reasoner's cost must not grow).
Run: uv run python bench/qos_latency.py
"""

from __future__ import annotations

import json
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _qos_sessions import back_to_back

from qos import Engine, load_model

SESSIONS = 200


def percentiles(samples_ns: list[int]) -> dict[str, float]:
    """p50 and p99 in microseconds."""
    cuts = statistics.quantiles(samples_ns, n=100, method="inclusive")
    return {"p50_us": round(cuts[49] / 1000, 2), "p99_us": round(cuts[98] / 1000, 2), "updates": len(samples_ns)}


def main() -> int:
    engine = Engine(load_model("clarc"))
    per_session: list[list[int]] = [[] for _ in range(SESSIONS)]
    last_t = 0.0
    for number, t, values, emitted in back_to_back():
        if number == SESSIONS:
            break
        began = time.perf_counter_ns()
        engine.update(t, set=values, emit=emitted)
        per_session[number].append(time.perf_counter_ns() - began)
        last_t = t
    tenth = SESSIONS // 10
    everything = [ns for session in per_session for ns in session]
    first = [ns for session in per_session[:tenth] for ns in session]
    last = [ns for session in per_session[-tenth:] for ns in session]
    print(
        json.dumps(
            {
                "benchmark": "qos_latency",
                "model": "clarc",
                "sessions": SESSIONS,
                "simulated_hours": round(last_t / 3600, 1),
                "all": percentiles(everything),
                "first_tenth": percentiles(first),
                "last_tenth": percentiles(last),
                "last_over_first_p99": round(percentiles(last)["p99_us"] / percentiles(first)["p99_us"], 2),
                "goal": "p99 < 1000 us, last tenth no slower than the first",
            },
            indent=1,
        )
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
