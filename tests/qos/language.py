"""Helpers for the RoQME language tests: build a small model, run a small timed trace through it."""

from __future__ import annotations

from qos import Engine, parse_model

HEAD = (
    "roqme M\nproperty P\ncontext B : boolean\ncontext C : boolean\ncontext N : number\n"
    "context E : eventtype\ncontext S : enum {ON, OFF}\n"
)


def engine_for(body: str, head: str = HEAD, **options) -> Engine:
    """An engine for the model ``head + body``."""
    return Engine(parse_model(head + body, "m.roqme"), **options)


def run(body: str, events: list[tuple], until: float | None = None, head: str = HEAD, **options) -> list[tuple]:
    """(t, fired observations) of every batch that fired something, timer batches included.

    ``events`` are ``(t, {context: value})`` or ``(t, {…}, [eventtypes])``; ``until`` lets time pass
    after the last one (``advance``).
    """
    engine = engine_for(body, head, **options)
    fired: list[tuple] = []
    engine.subscribe(lambda result: fired.append((result.t, result.fired)) if result.fired else None)
    for event in events:
        t, values, *emit = event
        engine.update(t, set=values, emit=emit[0] if emit else [])
    if until is not None:
        engine.advance(until)
    return fired


def times(fired: list[tuple], name: str = "O") -> list[float]:
    """The times at which observation ``name`` fired."""
    return [t for t, names in fired if name in names]
