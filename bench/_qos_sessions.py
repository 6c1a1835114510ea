"""Kiosk sessions for the QoS benchmarks: the six test-bench traces, replayed back to back."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

from qos import load_trace

TESTBENCH = Path(__file__).resolve().parents[1] / "recordings" / "testbench"


def session_batches() -> list[list[tuple[float, dict, list]]]:
    """The batches of Barthel #1 … #6 (times from the start of each session)."""
    return [load_trace(TESTBENCH / f"barthel{n}.yaml").batches() for n in range(1, 7)]


def back_to_back(gap: float = 60.0) -> Iterator[tuple[int, float, dict, list]]:
    """Endless (session number, absolute time, set, emit), sessions separated by ``gap`` seconds."""
    sessions = session_batches()
    start, number = 0.0, 0
    while True:
        batches = sessions[number % len(sessions)]
        for t, values, emitted in batches:
            yield number, start + float(t), values, emitted
        start += float(batches[-1][0]) + gap
        number += 1
