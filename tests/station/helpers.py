"""Staff-side helpers for the station tests: log in over HTTP and post forms with the CSRF token."""

from __future__ import annotations

import re

import httpx

from bench._station_client import PATIENTS, KioskClient, Row, record_patient
from tests.station.conftest import PASSWORDS

__all__ = ["KioskClient", "Row", "record_patient", "Staff", "PATIENTS"]
_CSRF = re.compile(r'name="csrf" content="([^"]+)"')


class Staff:
    """A logged-in browser-less user of the station's pages."""

    def __init__(self, url: str, name: str = "dr.lopez", role: str = "doctor") -> None:
        self.http = httpx.Client(base_url=url, timeout=30)
        page = self.http.get("/login")
        response = self.http.post(
            "/login", data={"csrf": self.csrf(page.text), "name": name, "password": PASSWORDS[role], "next": "/"}
        )
        assert response.status_code == 303, response.text

    @staticmethod
    def csrf(html: str) -> str:
        return _CSRF.search(html).group(1)

    def post(self, path: str, **form: str) -> httpx.Response:
        token = self.csrf(self.http.get("/").text)
        return self.http.post(path, data={"csrf": token, **form})


def response_in(bundle: dict) -> dict:
    """The one QuestionnaireResponse of an exported transaction Bundle."""
    (response,) = [e["resource"] for e in bundle["entry"] if e["resource"]["resourceType"] == "QuestionnaireResponse"]
    return response
