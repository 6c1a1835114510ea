"""The site's batteries in the order form (issue 36): `kiosk station --battery NAME=ID,...` offers
each by name, lists the instruments in the site's order, and an order runs a battery in its
configured order (not the alphabet's, nor the boxes'); a malformed option is one line at start."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from urllib.parse import unquote

import pytest

from station import batteries
from tests.station.conftest import PATIENCE_S, ROOT, make_ward
from tests.station.helpers import KioskClient, Staff

CGA = batteries.Battery("CGA", ("sarc_f", "gds15", "barthel"))
MOOD = batteries.Battery("Mood", ("gds15",))


def test_a_battery_keeps_its_order_and_boxes_follow_the_sites():
    offered = ["barthel", "gds15", "lawton", "sarc_f"]
    assert batteries.site_order(offered, [CGA, MOOD]) == ["sarc_f", "gds15", "barthel", "lawton"]
    assert batteries.chosen("CGA", [], offered, [CGA]) == ["sarc_f", "gds15", "barthel"]
    # boxes ticked beside a battery come after it, in the site's order, whatever the form's order
    assert batteries.chosen("Mood", ["lawton", "barthel", "gds15"], offered, [CGA, MOOD]) == [
        "gds15",
        "barthel",
        "lawton",
    ]
    assert batteries.chosen("", ["lawton", "sarc_f"], offered, [CGA]) == ["sarc_f", "lawton"]
    with pytest.raises(ValueError, match="'Ward 9' is not one of this site's"):
        batteries.chosen("Ward 9", [], offered, [CGA])


@pytest.mark.parametrize(
    ("option", "problem"),
    [
        ("CGA", "give NAME=ID,ID,..."),
        ("CGA=barthel,,gds15", "'' is not an instrument id"),
        ("CGA=barthel,barthel", "an instrument is named twice"),
        ("<b>=barthel", "give NAME=ID,ID,..."),
    ],
)
def test_a_malformed_battery_is_one_line(option, problem):
    with pytest.raises(ValueError, match=problem):
        batteries.parse_all([option])
    with pytest.raises(ValueError, match="battery CGA is given twice"):
        batteries.parse_all(["CGA=barthel", "CGA=gds15"])


@pytest.mark.slow  # a station process
def test_the_order_form_offers_the_sites_battery_and_keeps_its_order(sqlite_url, station_factory, tmp_path):
    refused = subprocess.run(
        [sys.executable, "-m", "kiosk", "station", "--db", sqlite_url, "--battery", "CGA=barthel,,gds15"],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=PATIENCE_S,
    )
    assert refused.returncode != 0 and "--battery battery CGA: '' is not an instrument id" in refused.stderr
    assert "Traceback" not in refused.stderr

    ward = make_ward(sqlite_url)
    station = station_factory(
        sqlite_url, args=("--battery", "CGA=gds15,lawton,barthel", "--battery", "Mood=gds15,mood4")
    )
    nurse = Staff(station.url, "nurse.kim", "nurse")
    form = nurse.http.get("/orders").text
    cga = '<option value="CGA">CGA: Geriatric Depression Scale (GDS-15) → Lawton Instrumental Activities'
    assert cga in form and '<option value="Mood">Mood: Geriatric Depression Scale (GDS-15) → mood4</option>' in form
    boxes = re.findall(r'name="instrument" value="([^"]+)"', form)
    assert boxes == ["gds15", "lawton", "barthel", "sarc_f", "tug"]  # the site's order, then the others
    assert 'name="instrument" value="gds15" checked' not in form  # a battery or boxes: nothing ticked for staff

    # a battery's instrument the station has not seen a kiosk run is named and refused, never dropped
    mood = nurse.post("/orders", patient_id="NHC-0036301", kiosk=ward.kiosk_id, battery="Mood", language="en")
    assert "mood4 is not one this station knows" in unquote(mood.headers["location"])
    unknown = nurse.post("/orders", patient_id="NHC-0036301", kiosk=ward.kiosk_id, battery="Ward 9", language="en")
    assert "battery: battery 'Ward 9' is not one of this site's" in unquote(unknown.headers["location"])
    # the battery and a box it lacks, the box sent first: the battery's order, then the box
    placed = nurse.http.post(
        "/orders",
        data={
            "csrf": Staff.csrf(form),
            "patient_id": "NHC-0036301",
            "kiosk": ward.kiosk_id,
            "instrument": ["sarc_f"],
            "battery": "CGA",
            "language": "en",
        },
    )
    assert placed.status_code == 303 and placed.headers["location"].startswith("/orders/order-")
    kiosk = KioskClient(station.url, ward.token, ward.kiosk_id)
    (listed,) = kiosk.orders()["orders"]
    assert listed["instruments"] == ["gds15", "lawton", "barthel", "sarc_f"], json.dumps(listed)
    kiosk.close()
