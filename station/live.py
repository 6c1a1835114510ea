"""Server-sent events for the open station pages.

One :class:`Live` per process subscribes to the bus and renders each change once (the kiosk's
tile, the open alerts), then hands the same text to every open page; the page swaps the HTML in
and, for an alert it has not seen, plays a sound and shows a notification. SSE rather than
websockets: the pages only listen (staff actions are ordinary form posts with CSRF tokens), and
the browser's EventSource reconnects by itself.
"""

from __future__ import annotations

import asyncio
import json
import logging
from collections.abc import AsyncIterator, Callable
from concurrent.futures import ThreadPoolExecutor
from typing import Any

from station.bus import Bus

KEEPALIVE_S = 15.0
log = logging.getLogger("station.live")


def sse(event: str, data: dict[str, Any]) -> str:
    """One server-sent event (JSON data on one line)."""
    return f"event: {event}\ndata: {json.dumps(data)}\n\n"


class _Changed:
    """What the open pages have not been sent yet."""

    def __init__(self) -> None:
        self.kiosks: set[str] = set()
        self.alerts = False
        self.resync = False
        #: results: sessions that finished (they ring), and whether any result changed at all
        self.finished: list[str] = []
        self.results = False

    def __bool__(self) -> bool:
        return bool(self.kiosks) or self.alerts or self.resync or self.results

    def take(self, message: dict[str, Any]) -> None:
        kind = message.get("type")
        if kind in ("kiosk", "alert") and message.get("kiosk"):
            self.kiosks.add(message["kiosk"])
        self.alerts |= kind in ("alert", "ack")
        self.resync |= kind == "resync"
        if kind == "result" and message.get("finished") and message.get("session"):
            self.finished.append(message["session"])
        self.results |= kind in ("result", "sessions", "order")  # an order's page follows its state too


class Live:
    """Renders bus messages into page events and fans them out to the open pages.

    Alerts have a path of their own: a task and a thread that render only the open alerts (an
    index over the open ones, Alembic ``0006_history``), so a doctor call never waits behind a
    kiosk's tile, the results count, or whatever else the station is rendering."""

    def __init__(
        self,
        bus: Bus,
        render_kiosk: Callable[[str], dict[str, Any]],
        render_alerts: Callable[[], dict[str, Any]],
        render_results: Callable[[list[str]], dict[str, Any]] | None = None,
    ) -> None:
        self._bus = bus
        self._render_kiosk = render_kiosk
        self._render_alerts = render_alerts
        #: the results event: the count waiting and the results that just finished (they ring)
        self._render_results = render_results
        self._pages: set[asyncio.Queue[str]] = set()
        self._tasks: list[asyncio.Task[None]] = []
        #: a thread for alerts alone, and one for the rest (tiles, results)
        self._alert_thread = ThreadPoolExecutor(max_workers=1, thread_name_prefix="station-alerts-live")
        self._executor = ThreadPoolExecutor(max_workers=1, thread_name_prefix="station-live")

    def start(self) -> None:
        loop = asyncio.get_running_loop()
        self._tasks = [loop.create_task(self._run_alerts()), loop.create_task(self._run())]

    async def stop(self) -> None:
        for task in self._tasks:
            task.cancel()
        self._executor.shutdown(wait=False)
        self._alert_thread.shutdown(wait=False)

    async def _render(self, render: Callable[..., dict[str, Any]], *args: Any) -> dict[str, Any]:
        return await asyncio.get_running_loop().run_in_executor(self._executor, render, *args)

    async def _alerts_text(self) -> str:
        return sse("alerts", await asyncio.get_running_loop().run_in_executor(self._alert_thread, self._render_alerts))

    def _send(self, text: str) -> None:
        for page in list(self._pages):
            page.put_nowait(text)

    async def _run_alerts(self) -> None:
        """The alerts' own path: on any change of an alert, the open alerts, rendered once for
        every page (the messages queued meanwhile taken together)."""
        queue = self._bus.subscribe()
        while True:
            message = await queue.get()
            wanted = message.get("type") in ("alert", "ack")
            while not queue.empty():
                wanted |= queue.get_nowait().get("type") in ("alert", "ack")
            if not wanted or not self._pages:
                continue
            try:
                self._send(await self._alerts_text())
            except Exception:  # a page must keep its feed even if one render fails
                log.exception("station: could not render the alerts for the live feed")

    async def _run(self) -> None:
        """Render what else changed, one piece at a time: after each render the messages that
        arrived meanwhile are taken in."""
        queue = self._bus.subscribe()
        changed = _Changed()
        while True:
            if not changed:
                changed.take(await queue.get())
            while not queue.empty():
                changed.take(queue.get_nowait())
            changed.alerts = False  # the alerts' own path sends those
            if not self._pages or not changed:
                changed = _Changed()
                continue
            try:
                if changed.resync:
                    changed = _Changed()
                    text = sse("resync", {})
                elif changed.results:
                    finished, changed.finished, changed.results = changed.finished, [], False
                    if self._render_results is None:
                        continue
                    text = sse("results", await self._render(self._render_results, finished))
                else:
                    text = sse("kiosk", await self._render(self._render_kiosk, changed.kiosks.pop()))
            except Exception:  # a page must keep its feed even if one render fails
                log.exception("station: could not render a live update")
                continue
            self._send(text)

    async def stream(self) -> AsyncIterator[str]:
        """The event stream of one open page (ends when the page goes away)."""
        page: asyncio.Queue[str] = asyncio.Queue()
        self._pages.add(page)
        try:
            yield "retry: 1000\n\n"
            yield await self._alerts_text()
            while True:
                try:
                    yield await asyncio.wait_for(page.get(), timeout=KEEPALIVE_S)
                except TimeoutError:
                    yield ": keepalive\n\n"
        finally:
            self._pages.discard(page)
