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


class Live:
    """Renders bus messages into page events and fans them out to the open pages."""

    def __init__(self, bus: Bus, render_kiosk: Callable[[str], dict[str, Any]],
                 render_alerts: Callable[[], dict[str, Any]]) -> None:
        self._bus = bus
        self._render_kiosk = render_kiosk
        self._render_alerts = render_alerts
        self._pages: set[asyncio.Queue[str]] = set()
        self._task: asyncio.Task[None] | None = None
        #: a thread of its own: rendering an alert never queues behind the kiosks' requests
        self._executor = ThreadPoolExecutor(max_workers=1, thread_name_prefix="station-live")

    def start(self) -> None:
        self._task = asyncio.get_running_loop().create_task(self._run())

    async def stop(self) -> None:
        if self._task is not None:
            self._task.cancel()
        self._executor.shutdown(wait=False)

    async def _render(self, render: Callable[..., dict[str, Any]], *args: Any) -> dict[str, Any]:
        return await asyncio.get_running_loop().run_in_executor(self._executor, render, *args)

    async def _run(self) -> None:
        queue = self._bus.subscribe()
        while True:
            message = await queue.get()
            try:
                for text in await self._events(message, queue):
                    for page in list(self._pages):
                        page.put_nowait(text)
            except Exception:  # a page must keep its feed even if one render fails
                log.exception("station: could not render %s", message)

    async def _events(self, message: dict[str, Any], queue: asyncio.Queue[dict[str, Any]]) -> list[str]:
        """The page events for a message; messages already waiting are merged, so a burst of
        status reports from one kiosk is rendered once."""
        kiosks, alerts, resync = set(), False, False
        while True:
            kind = message.get("type")
            if kind in ("kiosk", "alert") and message.get("kiosk"):
                kiosks.add(message["kiosk"])
            alerts |= kind in ("alert", "ack")
            resync |= kind == "resync"
            if queue.empty():
                break
            message = queue.get_nowait()
        if not self._pages:
            return []
        if resync:
            return [sse("resync", {})]
        events = []
        if alerts:  # alerts first: they are what a nurse must see soonest
            events.append(sse("alerts", await self._render(self._render_alerts)))
        for name in sorted(kiosks):
            events.append(sse("kiosk", await self._render(self._render_kiosk, name)))
        return events

    async def stream(self) -> AsyncIterator[str]:
        """The event stream of one open page (ends when the page goes away)."""
        page: asyncio.Queue[str] = asyncio.Queue()
        self._pages.add(page)
        try:
            yield "retry: 1000\n\n"
            yield sse("alerts", await self._render(self._render_alerts))
            while True:
                try:
                    yield await asyncio.wait_for(page.get(), timeout=KEEPALIVE_S)
                except TimeoutError:
                    yield ": keepalive\n\n"
        finally:
            self._pages.discard(page)
