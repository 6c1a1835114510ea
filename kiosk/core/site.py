"""Who exports and reports: the site and this kiosk, and the FHIR systems and URLs the site owns
(:class:`ExportSite`). Every export and every session the kiosk sends the station names them; the
kiosk needs them before its welcome (its store is opened with them), its exports only later."""

from __future__ import annotations

import re
import socket
from collections.abc import Mapping
from dataclasses import field, fields
from typing import Any

from basis import record


def default_kiosk_id() -> str:
    """The host name made fit for an identifier (set ``kiosk_id`` so it never changes)."""
    name = re.sub(r"[^A-Za-z0-9._-]", "-", socket.gethostname()).strip("-._")[:64]
    return name or "kiosk"


@record
class ExportSite:
    """Who exports: the site and the kiosk, and the FHIR systems and URLs the site owns.

    The defaults are URNs under ``urn:barthel-kiosk:`` with the site code in them; a hospital
    sets its own (``site``, ``kiosk_id`` and ``fhir:`` in the kiosk's config,
    :func:`kiosk.config.site_from_config`).
    """

    site: str = "local"
    kiosk_id: str = field(default_factory=default_kiosk_id)
    #: the system of the patients' pseudonymous ids
    patient_system: str = ""
    #: the canonical URL of the questionnaire; one Questionnaire per language is ``URL-LANG``
    #: (empty: ``urn:barthel-kiosk:SITE:questionnaire:ID``, ID the questionnaire file's id)
    questionnaire_url: str = ""
    #: the system of result identifiers: ``SITE/KIOSK/SESSION`` (+ ``/total`` for the Observation)
    identifier_system: str = ""
    #: the system of kiosk ids (the FHIR Device's identifier)
    device_system: str = ""

    def __post_init__(self) -> None:
        defaults = {
            "patient_system": f"urn:barthel-kiosk:{self.site}:patient",
            "identifier_system": "urn:barthel-kiosk:result",
            "device_system": f"urn:barthel-kiosk:{self.site}:kiosk",
        }
        for name, value in defaults.items():
            if not getattr(self, name):
                object.__setattr__(self, name, value)

    def result_id(self, session_id: str) -> str:
        """The stable business identifier of a session's result: site + kiosk + session."""
        return f"{self.site}/{self.kiosk_id}/{session_id}"


def export_identity(site: ExportSite) -> dict[str, str]:
    """``site`` as plain strings (what the kiosk sends the station with each session)."""
    return {f.name: str(getattr(site, f.name)) for f in fields(site)}


def site_from_identity(identity: Mapping[str, Any], kiosk_id: str) -> ExportSite:
    """The :class:`ExportSite` a kiosk sent (:func:`export_identity`); its unknown or non-text
    fields are ignored, and without one the station's default site for ``kiosk_id``."""
    known = {f.name for f in fields(ExportSite)}
    chosen = {k: v for k, v in identity.items() if k in known and isinstance(v, str) and v}
    return ExportSite(**{"kiosk_id": kiosk_id, **chosen})
