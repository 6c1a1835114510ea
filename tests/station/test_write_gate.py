"""SQLite's one writer at a time, alerts first (station.write_gate): a doctor call's transaction
waits for at most the one in progress, never for the routine batches queued before it."""

from __future__ import annotations

import threading

from station.write_gate import WriteGate


def _waiter(gate: WriteGate, urgent: bool, order: list[str], name: str, waiting: threading.Event) -> threading.Thread:
    def run() -> None:
        waiting.set()
        with gate.held(urgent):
            order.append(name)

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    return thread


def _until_waiting(gate: WriteGate, routine: int, urgent: int) -> None:
    """Wait (bounded) until the gate's queues hold that many writers."""
    with gate._cond:
        assert gate._cond.wait_for(
            lambda: gate._waiting_routine == routine and gate._urgent_waiting == urgent, timeout=30
        ), "the writers never queued"


def test_an_urgent_writer_goes_before_the_routine_ones_queued_earlier():
    gate, order = WriteGate(), []
    release = threading.Event()
    held = threading.Event()

    def first() -> None:
        with gate.held():
            held.set()
            release.wait(30)
            order.append("in progress")

    threads = [threading.Thread(target=first, daemon=True)]
    threads[0].start()
    assert held.wait(30)
    threads += [_waiter(gate, False, order, f"routine {i}", threading.Event()) for i in range(3)]
    _until_waiting(gate, routine=3, urgent=0)
    threads.append(_waiter(gate, True, order, "alert", threading.Event()))
    _until_waiting(gate, routine=3, urgent=1)
    release.set()
    for thread in threads:
        thread.join(30)
    assert order[:2] == ["in progress", "alert"]
    assert sorted(order[2:]) == ["routine 0", "routine 1", "routine 2"]


def test_a_writer_inside_the_gate_may_open_another_gated_transaction():
    gate = WriteGate()
    with gate.held(), gate.held(urgent=True), gate.held():
        pass
    done = threading.Event()
    threading.Thread(target=lambda: (gate.held().__enter__(), done.set()), daemon=True).start()
    assert done.wait(30)  # released whole: another thread gets it
