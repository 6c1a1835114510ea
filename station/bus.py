"""Fan-out of what changed (an alert, a kiosk's status, a queued command) to every open page and
waiting long poll, in this process and, on PostgreSQL, in every station process on the database.

Writers publish after their transaction commits. On SQLite (one station process) a message goes
straight to this process's subscribers. On PostgreSQL it goes through ``NOTIFY station`` and
comes back to every process, this one included, through its ``LISTEN`` connection: one path for
all, so a page served by another process sees the same alert as quickly. Messages are small
(what changed, never patient data); listeners read the details from the database.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
import logging
import threading
from collections.abc import Awaitable, Callable, Iterator
from typing import Any

import sqlalchemy as sa
from sqlalchemy.engine import Connection, Engine

from station.db import is_postgres
from station.write_gate import WriteGate

CHANNEL = "station"
log = logging.getLogger("station.bus")


class Bus:
    """Publish from any thread; subscribe from the event loop."""

    def __init__(self, engine: Engine) -> None:
        self._engine = engine
        self._loop: asyncio.AbstractEventLoop | None = None
        #: queues taking every message (the live pages), and the long polls' queues by kiosk with
        #: the kinds each one waits for
        self._subscribers: set[asyncio.Queue[dict[str, Any]]] = set()
        self._by_kiosk: dict[str, dict[asyncio.Queue[dict[str, Any]], frozenset[str]]] = {}
        self._kiosk_of: dict[asyncio.Queue[dict[str, Any]], str] = {}
        self._stopping = threading.Event()
        self._thread: threading.Thread | None = None
        self._listening = threading.Event()
        #: SQLite's one writer at a time, alerts first (none on PostgreSQL)
        self._gate = None if is_postgres(engine) else WriteGate()

    # -- lifecycle -------------------------------------------------------------------------------

    def start(self, loop: asyncio.AbstractEventLoop) -> None:
        """Begin delivering to subscribers on ``loop`` (and listening, on PostgreSQL)."""
        self._loop = loop
        if is_postgres(self._engine):
            self._thread = threading.Thread(target=self._listen, name="station-listen", daemon=True)
            self._thread.start()
            self._listening.wait(timeout=10)

    def stop(self) -> None:
        self._stopping.set()
        if self._thread is not None:
            self._thread.join(timeout=3)

    # -- publishing ------------------------------------------------------------------------------

    @contextlib.contextmanager
    def transaction(self, urgent: bool = False) -> Iterator[tuple[Connection, list[dict[str, Any]]]]:
        """A write transaction and the list of messages to publish if it commits: on PostgreSQL
        they are NOTIFYed in the transaction itself (sent by the commit, never without it), on
        SQLite delivered right after the commit. On SQLite an ``urgent`` one (alerts) is begun
        before every routine one waiting (:mod:`station.write_gate`)."""
        messages: list[dict[str, Any]] = []
        gate = self._gate.held(urgent) if self._gate is not None else contextlib.nullcontext()
        with gate, self._engine.begin() as connection:
            yield connection, messages
            if is_postgres(self._engine):
                for message in messages:
                    connection.execute(
                        sa.text("SELECT pg_notify(:channel, :payload)"),
                        {"channel": CHANNEL, "payload": json.dumps(message)},
                    )
        if not is_postgres(self._engine):
            for message in messages:
                self._deliver(message)

    def publish(self, *messages: dict[str, Any]) -> None:
        """Tell every station process what changed (call after the change committed)."""
        if not messages:
            return
        if is_postgres(self._engine):
            with self._engine.connect() as connection:
                for message in messages:
                    connection.execute(
                        sa.text("SELECT pg_notify(:channel, :payload)"),
                        {"channel": CHANNEL, "payload": json.dumps(message)},
                    )
                connection.commit()
        else:
            for message in messages:
                self._deliver(message)

    # -- subscribing -----------------------------------------------------------------------------

    def subscribe(self, kiosk: str | None = None, kinds: tuple[str, ...] = ()) -> asyncio.Queue[dict[str, Any]]:
        """A queue receiving every message from now on, or, given ``kiosk``, only the messages of
        ``kinds`` for that kiosk or for every kiosk (call :meth:`unsubscribe` when done). A long
        poll waits on one kiosk's few messages: fed every kiosk's status reports instead, each of
        50 waiting polls fell hundreds of ms behind (measured: bench/station.py)."""
        queue: asyncio.Queue[dict[str, Any]] = asyncio.Queue()
        if kiosk is None:
            self._subscribers.add(queue)
        else:
            self._by_kiosk.setdefault(kiosk, {})[queue] = frozenset(kinds)
            self._kiosk_of[queue] = kiosk
        return queue

    def unsubscribe(self, queue: asyncio.Queue[dict[str, Any]]) -> None:
        self._subscribers.discard(queue)
        kiosk = self._kiosk_of.pop(queue, None)
        if kiosk is not None:
            waiting = self._by_kiosk[kiosk]
            waiting.pop(queue, None)
            if not waiting:
                del self._by_kiosk[kiosk]

    def _deliver(self, message: dict[str, Any]) -> None:
        if self._loop is None or self._loop.is_closed():
            return
        self._loop.call_soon_threadsafe(self._fan_out, message)

    def _fan_out(self, message: dict[str, Any]) -> None:
        for queue in list(self._subscribers):
            queue.put_nowait(message)
        kiosk, kind = message.get("kiosk"), message.get("type")
        polls = [self._by_kiosk.get(kiosk, {})] if kiosk is not None else list(self._by_kiosk.values())
        for waiting in polls:
            for queue, kinds in list(waiting.items()):
                if kind in kinds:
                    queue.put_nowait(message)

    def _listen(self) -> None:
        """LISTEN on a connection of its own; after a lost connection, reconnect and tell the
        pages to reload what they show (a NOTIFY sent meanwhile is not replayed)."""
        import psycopg

        url = self._engine.url.set(drivername="postgresql").render_as_string(hide_password=False)
        first = True
        while not self._stopping.is_set():
            try:
                with psycopg.connect(url, autocommit=True) as connection:
                    connection.execute(f"LISTEN {CHANNEL}")
                    self._listening.set()
                    if not first:
                        self._deliver({"type": "resync"})
                    first = False
                    while not self._stopping.is_set():
                        for notice in connection.notifies(timeout=0.5):
                            self._deliver(json.loads(notice.payload))
            except psycopg.Error as exc:
                log.warning("station: lost the database notification connection (%s); reconnecting", exc)
                self._stopping.wait(1.0)


async def long_poll(
    queue: asyncio.Queue[dict[str, Any]],
    wait: float,
    current: Any,
    fetch: Callable[[], Awaitable[Any]],
    answered: Callable[[Any], bool],
) -> Any:
    """The long polls' wait: from ``current`` (read after subscribing ``queue`` to the kiosk's
    kinds of message, so nothing published in between is missed), read again with ``fetch`` once
    per wake (the messages queued by then taken together) until ``answered`` says so or ``wait``
    seconds pass; returns what was read last."""
    loop = asyncio.get_running_loop()
    deadline = loop.time() + wait
    while not answered(current):
        left = deadline - loop.time()
        if left <= 0:
            break
        try:
            await asyncio.wait_for(queue.get(), timeout=left)
        except TimeoutError:
            break
        while not queue.empty():  # one read answers every change queued so far
            queue.get_nowait()
        current = await fetch()
    return current
