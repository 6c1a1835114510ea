"""The export's download name whatever session id a kiosk sent: one ``filename`` (and one
``filename*``) parameter, only safe characters, our own suffix last. Real station, real sync of
a real recorded session under each hostile id, real HTTP download."""

from __future__ import annotations

import re
from dataclasses import replace
from email.message import Message
from urllib.parse import quote

import pytest

from station.download import attachment, safe_stem
from tests.station.conftest import new_kiosk
from tests.station.helpers import PATIENTS, KioskClient, Staff, record_patient

HOSTILE = [
    'q"; filename=evil.exe.csv',
    "a\r\nSet-Cookie: taken=1",
    "..\\..\\Windows\\evil.bat",
    "...",
    "ü-naïve ☃ 'x'",
    '"',
    "x" * 64,
]
SAFE_NAME = re.compile(r"^[A-Za-z0-9._-]+$")
_TOKEN = r"[!#$%&'*+.^_`|~0-9A-Za-z-]+"
PARAMETER = re.compile(rf';\s*({_TOKEN})=(?:"(?:[^"\\\r\n]|\\.)*"|{_TOKEN})')
DISPOSITION = re.compile(rf"attachment(?:{PARAMETER.pattern})*")


def _parameters(header: str) -> tuple[list[str], str | None]:
    """The header's parameter names, read by RFC 6266's grammar (the whole value must parse), and
    the file name a browser takes from it (``filename*`` decoded, as Python's mail parser does)."""
    assert DISPOSITION.fullmatch(header), header
    names = [m.group(1) for m in PARAMETER.finditer(header)]
    message = Message()
    message["content-disposition"] = header
    return names, message.get_filename()


@pytest.mark.parametrize("session_id", [*HOSTILE, "..", "", "2026-11-26T08-00-00-ab12"])
def test_the_header_names_one_safe_file_whatever_the_id(session_id):
    header = attachment(session_id, ".csv")
    names, filename = _parameters(header)
    assert names == ["filename", "filename*"]
    assert filename is not None and SAFE_NAME.match(filename) and filename.endswith(".csv")
    assert not filename.startswith(".") and "\r" not in header and "\n" not in header
    assert safe_stem("2026-11-26T08-00-00-ab12") == "2026-11-26T08-00-00-ab12"  # ordinary ids kept as they are


@pytest.mark.slow  # a station process
def test_a_hostile_session_id_downloads_under_a_safe_name(shared_station):
    station, ward = shared_station
    name, token = new_kiosk(ward.db_url)
    kiosk = KioskClient(station.url, token, name)
    staff = Staff(station.url)
    recorded = record_patient(PATIENTS / "barthel1.yaml")
    try:
        for number, session_id in enumerate(HOSTILE):
            rows = [
                replace(
                    r,
                    seq=r.seq + 1000 * number,
                    session_id=session_id,
                    payload={k: session_id if k == "session_id" else v for k, v in r.payload.items()},
                )
                for r in recorded
            ]
            response = kiosk.sync(rows)
            assert response.status_code == 200, response.text
            for fmt, suffix in (("csv", ".csv"), ("json", ".fhir.json")):
                download = staff.http.get(f"/sessions/{quote(session_id, safe='')}/export.{fmt}")
                assert download.status_code == 200, (session_id, download.text)
                header = download.headers["content-disposition"]
                names, filename = _parameters(header)
                assert names == ["filename", "filename*"], header
                assert SAFE_NAME.match(filename) and filename.endswith(suffix), header
                assert "taken" not in " ".join(download.headers.get_list("set-cookie"))
    finally:
        kiosk.close()
        staff.http.close()
