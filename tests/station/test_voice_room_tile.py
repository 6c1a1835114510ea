"""The ward tile says when a kiosk's room is failing voice (issue 33, part 5): the live status a
kiosk sends from a session with voice_room on, posted to a real `kiosk station` process."""

from __future__ import annotations

import pytest

from kiosk.core.adaptation import Adaptation, load_policy
from kiosk.core.room import STAFF_NOTICE, RoomHearing
from kiosk.sync.commands import live_status
from tests.kiosk.core.helpers import started
from tests.station.conftest import new_kiosk
from tests.station.helpers import KioskClient, Staff

pytestmark = pytest.mark.slow


@pytest.fixture
def kiosk_client(shared_station):
    station, ward = shared_station
    name, token = new_kiosk(ward.db_url)
    client = KioskClient(station.url, token, name)
    yield station, name, client
    client.close()


def _tile(station, name: str) -> str:
    page = Staff(station.url).http.get("/").text
    tile = page[page.index(f'id="kiosk-{name}"') :]
    return tile[: tile.index("</article>")]


def test_the_tile_says_voice_is_not_working_well_in_this_room(kiosk_client):
    station, name, client = kiosk_client
    rig = started(adaptation=Adaptation(load_policy()), room=RoomHearing())
    rig.run_until(25)
    assert client.status(**live_status(rig.session)).status_code == 200
    assert STAFF_NOTICE not in _tile(station, name)
    for _ in range(3):
        rig.session.voice_unheard("nothing recognisable was said")
    status = live_status(rig.session)
    assert status["voice_room"] == STAFF_NOTICE
    assert client.status(**status).status_code == 200
    assert STAFF_NOTICE in _tile(station, name)
    rig.session.request_voice()  # the patient tries voice again: the tile follows
    assert client.status(**live_status(rig.session)).status_code == 200
    assert STAFF_NOTICE not in _tile(station, name)
