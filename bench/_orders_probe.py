"""The clinician's loop under load, for ``bench/station.py``: each simulated kiosk long-polls its
orders as the kiosk's own watcher does (``kiosk/sync/orders.py``), a logged-in member of staff
orders one visit per kiosk while the kiosks replay their patients, and the page's event stream
notes when each finished result reaches it.

- order to kiosk: from the moment staff send the order form to the moment that kiosk's long poll
  lists the order (its welcome then shows it: drawing is local to the kiosk). Staff start ordering
  once every kiosk is waiting on its long poll, as on a ward where the kiosks were on before the
  round; the replays' rows keep flowing meanwhile;
- result stored to inbox: from the station storing a ``finish_session`` row (``inbox.received_at``,
  the station's clock) to the open page receiving the ``results`` event that rings for it (the
  same machine's clock).

Figures, 2026-11-26, ``uv run python bench/station.py --kiosks 50`` (PostgreSQL, 100x), three runs
on this shared 2-core machine with other work running (load average 3.7-4.2)::

    order sent -> kiosk p50/p99 ms    59 / 355     19 / 1452     45 / 469
    order stored -> kiosk p99 ms           304           451          287
    result stored -> inbox p50/p99 ms 121 / 406   205 / 731    131 / 431
    alert -> page p99 ms (same runs)       703          1433         1318

The second run's slow orders were slow before they were stored: the staff's POST waits for its
login check in the station's shared worker threads (``LoginRequired``), behind the kiosks' rows;
the order's own work (its write, the kiosk's long poll) runs on a lane of its own
(``station.api_orders.ORDER_LANE``). Before that lane, with the orders' reads in the shared
workers, order sent -> kiosk p99 was 1.9-5.0 s (load average 7.6-8.1). An earlier version rendered
each finished result's score for the ring, on the live feed's one thread that alerts share; the
ring now reads two small queries.
"""

from __future__ import annotations

import asyncio
import re
import time

import httpx

CSRF = re.compile(r'name="csrf" content="([^"]+)"')


async def poll_orders(
    http: httpx.AsyncClient, seen: dict[str, float], stop: asyncio.Event, listening: asyncio.Event
) -> None:
    """One kiosk's order watcher: the first time each order id is listed (monotonic seconds);
    ``listening`` is set once its first answer came (the kiosk is then waiting on a long poll)."""
    version = None
    while not stop.is_set():
        params = {"wait": 20} | ({"version": version} if version else {})
        try:
            response = await http.get("/api/v1/orders", params=params, timeout=40)
            response.raise_for_status()
        except httpx.HTTPError:
            await asyncio.sleep(0.5)
            continue
        now = time.monotonic()
        body = response.json()
        version = body["version"]
        listening.set()
        for order in body["orders"]:
            seen.setdefault(order["id"], now)


async def place_orders(
    url: str,
    user: str,
    password: str,
    kiosks: list[str],
    every_s: float,
    placed: dict[str, float],
    placed_wall: dict[str, float],
) -> None:
    """Staff order one visit per kiosk, ``every_s`` apart: order id -> when the form was sent
    (monotonic, and the wall clock in ``placed_wall``)."""
    async with httpx.AsyncClient(base_url=url, timeout=60) as http:
        token = CSRF.search((await http.get("/login")).text).group(1)
        await http.post("/login", data={"csrf": token, "name": user, "password": password, "next": "/orders"})
        token = CSRF.search((await http.get("/orders")).text).group(1)
        for index, kiosk in enumerate(kiosks):
            await asyncio.sleep(every_s)
            sent, wall = time.monotonic(), time.time()
            response = await http.post(
                "/orders",
                data={
                    "csrf": token,
                    "patient_id": f"NHC-B{index:04d}",
                    "kiosk": kiosk,
                    "instrument": "barthel",
                    "language": "en",
                },
            )
            location = response.headers.get("location", "")
            if response.status_code == 303 and location.startswith("/orders/order-"):
                placed[location.rsplit("/", 1)[1]] = sent
                placed_wall[location.rsplit("/", 1)[1]] = wall


def ward_round(
    url: str,
    kiosks: dict[str, str],
    users: tuple[str, ...],
    password: str,
    every_s: float,
    placed: dict[str, float],
    placed_wall: dict[str, float],
    seen: dict[str, float],
) -> None:
    """In a thread of its own (its own event loop, as each real kiosk and phone has its own
    process): every kiosk's order long poll, and staff ordering one visit per kiosk, ``every_s``
    apart overall, split between ``users``, once every kiosk is waiting. ``seen``: order id ->
    when its kiosk first listed it. Returns when every order was listed, or 15 s after the last."""

    async def run() -> None:
        stop = asyncio.Event()
        clients = {
            name: httpx.AsyncClient(base_url=url, headers={"Authorization": f"Bearer {token}"}, timeout=60)
            for name, token in kiosks.items()
        }
        listening = {name: asyncio.Event() for name in kiosks}
        polls = [asyncio.create_task(poll_orders(clients[name], seen, stop, listening[name])) for name in kiosks]
        await asyncio.gather(*(event.wait() for event in listening.values()))
        names = list(kiosks)
        await asyncio.gather(
            *(
                place_orders(url, user, password, names[index :: len(users)], every_s * len(users), placed, placed_wall)
                for index, user in enumerate(users)
            )
        )
        deadline = time.monotonic() + 15
        while time.monotonic() < deadline and not all(o in seen for o in placed):
            await asyncio.sleep(0.05)
        stop.set()
        for poll in polls:
            poll.cancel()
        await asyncio.gather(*polls, return_exceptions=True)
        for client in clients.values():
            await client.aclose()

    asyncio.run(run())
