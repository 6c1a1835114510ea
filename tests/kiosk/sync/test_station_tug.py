"""End to end with real processes (issue 34, parts 3 and 5): staff order a Timed Up and Go at a
`kiosk station` process; a real `kiosk replay --order-code` kiosk process takes the order with its
code (the kiosk's order intake accepts the instrument id ``tug``), plays a landmark file through
the real TugStep, stores the result and delivers its outbox; the station files it under the order
(complete: staff decided at the kiosk) and shows it on the patient's page."""

from __future__ import annotations

import re

import httpx
import pytest

from tests.kiosk.sync.test_station_e2e import PATIENCE_S, free_port, replay, start_station

pytestmark = pytest.mark.slow
CODE = re.compile(r'id="order-code"[^>]*>(\d{4})<')


def test_an_ordered_tug_goes_from_a_kiosk_process_to_the_station(tmp_path):
    from station import auth, db, tugs

    db_url = db.sqlite_url(tmp_path / "station")
    engine = db.open_database(db_url)
    token = auth.add_kiosk(engine, "ward3-bed2")
    auth.add_user(engine, "nurse.kim", "nurse", "nurse-password-1")
    port = free_port()
    config = tmp_path / "config.yaml"
    config.write_text(f"station: {{url: 'http://127.0.0.1:{port}', token: '{token}', kiosk_id: ward3-bed2}}\n")
    station = start_station(db_url, port, tmp_path / "station.log")
    try:
        staff = httpx.Client(base_url=f"http://127.0.0.1:{port}", timeout=PATIENCE_S)
        csrf = re.compile(r'name="csrf" content="([^"]+)"')
        login = staff.get("/login").text
        staff.post(
            "/login",
            data={
                "csrf": csrf.search(login).group(1),
                "name": "nurse.kim",
                "password": "nurse-password-1",
                "next": "/",
            },
        )
        placed = staff.post(
            "/orders",
            data={
                "csrf": csrf.search(staff.get("/").text).group(1),
                "patient_id": "NHC-0034500",
                "kiosk": "ward3-bed2",
                "instrument": ["barthel", "tug"],  # a TUG is ordered within a visit
                "language": "en",
            },
        )
        assert placed.status_code == 303 and "error" not in placed.headers["location"], placed.headers["location"]
        order_page = placed.headers["location"]
        code = CODE.search(staff.get(order_page).text).group(1)

        done = replay("tug/normal.yaml", tmp_path / "data", config, "--order-code", code)
        assert done.returncode == 0 and done.stderr == "", done.stderr

        (found,) = tugs.patient_course(engine, "NHC-0034500")
        assert (found.decision, found.decided_by, found.method, found.simulated) == (
            "accepted",
            "dr-lee",
            "camera",
            True,
        )
        assert found.order_id == order_page.rsplit("/", 1)[1] and found.visit_kind == "order"
        # filed under its order, which waits for its questionnaire (not replayed here)
        assert 'id="order-state">in progress' in staff.get(order_page).text, staff.get(order_page).text[:3000]
        page = staff.get("/patients/NHC-0034500").text
        assert f'data-tug="{found.id}"' in page and "the site&#39;s threshold" in page
        staff.close()
    finally:
        station.terminate()
        station.wait(timeout=PATIENCE_S)
        engine.dispose()
