"""The staff pages of orders: order a visit (phone or desk), see its code and state, cancel it.

Thin handlers as in :mod:`station.pages`: check the form (CSRF), call :mod:`station.orders`,
publish what changed (the kiosk's long poll wakes), redirect (post/redirect/get).
"""

from __future__ import annotations

import asyncio
from typing import Any
from urllib.parse import quote

from starlette.concurrency import run_in_threadpool
from starlette.requests import Request
from starlette.responses import PlainTextResponse, RedirectResponse, Response
from starlette.routing import Route

from kiosk.core.answerers import RELATIONSHIPS, TEXT_MAX
from station import batteries, orders, tugs, validation, ward
from station.api_orders import ORDER_LANE
from station.redirects import see_other
from station.rendering import checked_form, render


def _in_site_order(offered: list[orders.Instrument], site: Any) -> list[orders.Instrument]:
    """The instruments staff may order, listed in the site's order (:func:`batteries.site_order`)."""
    by_id = {i.id: i for i in offered}
    return [by_id[i] for i in batteries.site_order(list(by_id), site)]


def _kiosk_names(engine: Any) -> list[str]:
    return [k.name for k in ward.kiosk_views(engine) if not k.revoked]


async def orders_page(request: Request) -> Response:
    """The order form and the orders, open ones first (filter: ``state``, ``kiosk``)."""
    engine, q = request.app.state.engine, request.app.state.questionnaire
    state = request.query_params.get("state") or ""
    kiosk = request.query_params.get("kiosk") or ""
    states = [state] if state in orders.STATES else (list(orders.OPEN) if state == "" else None)
    found = await run_in_threadpool(lambda: orders.listing(engine, kiosk_id=kiosk or None, states=states))
    offered = _in_site_order(await run_in_threadpool(orders.instruments, engine, q), request.app.state.batteries)
    languages = list(dict.fromkeys(lang for i in offered for lang in i.languages))
    titles = {i.id: i.title for i in offered}
    return render(
        request,
        "orders.html",
        orders=found,
        kiosks=await run_in_threadpool(_kiosk_names, engine),
        instruments=[(i.id, i.title) for i in offered],
        # the site's batteries by name, each with its instruments' titles in its order
        batteries=[(b.name, " → ".join(titles.get(i, i) for i in b.instruments)) for b in request.app.state.batteries],
        languages=languages,
        state=state,
        kiosk=kiosk,
        words=orders.WORDS,
        relationships=list(RELATIONSHIPS),
        text_max=TEXT_MAX,
        form=dict(request.query_params),
        # a double booking's form again: what was chosen (never the default) and what to confirm
        chosen=request.query_params.get("instruments", "").split(",") if "warn" in request.query_params else None,
        warn=request.query_params.get("warn"),
        error=request.query_params.get("error"),
        message=request.query_params.get("message"),
    )


async def create_order(request: Request) -> Response:
    form = await checked_form(request)
    engine, q = request.app.state.engine, request.app.state.questionnaire
    multi = await request.form()

    def place() -> orders.Order:
        offered = {i.id: i for i in orders.instruments(engine, q)}
        try:  # the site's battery in its order, then the boxes ticked, in the site's order
            ticked = [str(v) for v in multi.getlist("instrument")]
            chosen = batteries.chosen(str(form.get("battery", "")), ticked, list(offered), request.app.state.batteries)
        except ValueError as exc:
            raise orders.OrderError(f"battery: {exc}") from None
        # a language every chosen instrument has (all of them when none is known yet: create says why)
        spoken = [set(offered[i].languages) for i in chosen if i in offered and offered[i].languages]
        languages = (
            sorted(set.intersection(*spoken)) if spoken else sorted({x for i in offered.values() for x in i.languages})
        )
        order = orders.create(
            engine,
            kiosk_id=form.get("kiosk", ""),
            patient_id=form.get("patient_id", ""),
            id_pattern=request.app.state.id_pattern,
            instruments=chosen,
            language=form.get("language", ""),
            relative=form.get("relative") == "yes",
            relationship=str(form.get("relationship", "")),
            relationship_text=str(form.get("relationship_text", "")),
            by=request.state.user,
            known_instruments=list(offered),
            languages=languages,
            anyway=form.get("anyway") == "yes",
        )
        request.app.state.bus.publish({"type": "order", "kiosk": order.kiosk_id})
        return order

    try:
        # on the orders' own lane: the kiosk's welcome must not wait behind routine rows
        order = await asyncio.get_running_loop().run_in_executor(ORDER_LANE, place)
    except orders.OrderError as exc:
        kept = ("kiosk", "patient_id", "language", "relationship", "relationship_text", "relative", "battery")
        keep = {k: str(form.get(k, "")) for k in kept}
        if isinstance(exc, orders.DoubleBooking):  # the same form again, to confirm: "Order anyway"
            keep["instruments"] = ",".join(str(v) for v in multi.getlist("instrument"))
            return see_other("/orders", warn=str(exc), fields=keep)
        return see_other("/orders", error=str(exc), fields=keep)
    return RedirectResponse(f"/orders/{order.id}", status_code=303)


async def order_page(request: Request) -> Response:
    engine = request.app.state.engine
    order = await run_in_threadpool(orders.get, engine, request.path_params["order_id"])
    if order is None:
        return PlainTextResponse(f"no order {request.path_params['order_id']}", status_code=404)
    trail = await run_in_threadpool(validation.trail, engine, order.id)
    found = await run_in_threadpool(tugs.of_order, engine, order.id)
    offered = await run_in_threadpool(orders.instruments, engine, request.app.state.questionnaire)
    titles = {i.id: i.title for i in offered}  # staff read the instruments' titles, never their ids
    return render(
        request,
        "order.html",
        order=order,
        trail=trail,
        tugs=found,
        titles=titles,
        message=request.query_params.get("message"),
    )


async def cancel_order(request: Request) -> Response:
    form = await checked_form(request)
    engine, order_id = request.app.state.engine, request.path_params["order_id"]
    try:
        order = await run_in_threadpool(orders.cancel, engine, order_id, request.state.user, form.get("reason", ""))
    except orders.OrderError as exc:
        return see_other(f"/orders/{quote(order_id)}", message=str(exc))
    # the kiosk's orders poll (it ends a running visit) and the ward's tile of it (it says "cancelled")
    kiosk = {"kiosk": order.kiosk_id}
    await run_in_threadpool(request.app.state.bus.publish, {"type": "order", **kiosk}, {"type": "kiosk", **kiosk})
    return RedirectResponse(f"/orders/{quote(order_id)}?message={quote('Cancelled.')}", status_code=303)


routes = [
    Route("/orders", orders_page, methods=["GET"]),
    Route("/orders", create_order, methods=["POST"]),
    Route("/orders/{order_id}", order_page, methods=["GET"]),
    Route("/orders/{order_id}/cancel", cancel_order, methods=["POST"]),
]
