"""``instruments:`` naming the Timed Up and Go (``tug``, issue 34): a step of the visit in its
place, refused alone or twice, and never in a walk-up's battery."""

from __future__ import annotations

import pytest

from kiosk.config import configured_instruments, configured_steps, load_config
from kiosk.core.clock import SimClock
from kiosk.ui.compose import KioskParts, SessionMaker
from tests.kiosk.battery_instruments import write_mini
from tests.kiosk.configs import refusal


def test_tug_holds_its_place_among_the_instruments(tmp_path):
    write_mini(tmp_path)
    path = tmp_path / "config.yaml"
    path.write_text("instruments: [barthel, tug, mini.yaml]\n")
    config = load_config(path, environ={})
    instruments = configured_instruments(config)
    assert [q.id for q, _ in instruments] == ["barthel", "mini"]
    assert configured_steps(config, instruments) == ("barthel", "tug", "mini")


@pytest.mark.parametrize(
    "text, message",
    [
        ("instruments: [tug]\n", "config.yaml:1:1: instruments: tug is given within a visit with at least one"),
        ("instruments: [barthel, tug, tug]\n", "config.yaml:1:1: instruments: 'tug' is given twice"),
    ],
)
def test_tug_alone_or_twice_is_refused(tmp_path, text, message):
    assert refusal(tmp_path / "config.yaml", text).startswith(f"{tmp_path}/{message}")


def test_a_staff_visit_counts_the_tug_and_a_walk_up_never_has_it(tmp_path):
    write_mini(tmp_path)
    path = tmp_path / "config.yaml"
    path.write_text(f"instruments: [barthel, tug, mini.yaml]\ndata_dir: {tmp_path / 'data'}\n")
    config = load_config(path, environ={})
    maker = SessionMaker(config, KioskParts.load(config), clock=SimClock(), store=None)
    staff = maker.fresh("P-1234", "en")
    assert staff.battery is not None and staff.battery.detail().split(" ")[1:] == ["1/3", "barthel,tug,mini"]
    assert maker.battery is not None and maker.battery.tug_after(staff) == 1
    walk_up = maker.fresh()
    assert walk_up.visit == "walk-up" and maker.battery.ids == ("barthel", "mini")
    assert maker.battery.tug_after(walk_up) is None
    # an order naming the TUG is one this kiosk can run, in the order's order
    assert KioskParts.load(config).ids == ["barthel", "mini", "tug"]
    assert KioskParts.load(config).visit_steps(["mini", "tug"]) == ("mini", "tug")


def test_a_station_order_may_name_the_tug_but_not_the_tug_alone():
    from kiosk.core.visits import parse_orders

    body = {
        "orders": [
            {"id": "o1", "patient_id": "P-1234", "instruments": ["barthel", "tug"], "language": "en"},
            {"id": "o2", "patient_id": "P-1235", "instruments": ["tug"], "language": "en"},
        ]
    }
    found, problems = parse_orders(body, ["barthel", "tug"], ["en"])
    assert [(o.id, o.instruments) for o in found] == [("o1", ("barthel", "tug"))]
    assert problems == ["orders[1] (o2): the Timed Up and Go alone: this kiosk gives it within a visit"]
