"""The configuration's settings (:class:`Config`: each one's type and default), its errors and the
station it reports to; what they mean is the package's docstring (:mod:`kiosk.config`), how each is
checked its row in :data:`kiosk.config.checks.SETTINGS`."""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import field
from pathlib import Path
from typing import TYPE_CHECKING

import platformdirs

from basis import record
from basis.errors import KioskError
from kiosk.core.pin import DEFAULT_PIN
from kiosk.core.site import ExportSite, default_kiosk_id
from kiosk.core.visits import DEFAULT_ID_PATTERN

if TYPE_CHECKING:
    from kiosk.core.tug.step import TugSettings

#: the FHIR settings a site may give (see kiosk.export.ExportSite for their defaults)
FHIR_KEYS = ("patient_system", "questionnaire_url", "identifier_system", "device_system")
#: browser connections `kiosk serve` runs at once unless configured: each is a kiosk process
#: of about 55 MB, and a ward kiosk has one screen
SERVE_MAX_SESSIONS = 2


class ConfigError(KioskError, ValueError):
    """The configuration file (or an environment override) is unusable.

    ``setting`` is the path of the setting at fault inside its mapping (such as ``("token",)``),
    where the file's line and column can be found."""

    def __init__(self, message: str, setting: tuple[str, ...] = ()) -> None:
        super().__init__(message)
        self.setting = setting


#: a kiosk's name at the station, and a site's code: letters, digits, '.', '-' and '_' (both go
#: into exported identifiers, so no spaces, '/' or '|')
KIOSK_ID = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]{0,63}")  # fullmatch: '$' would let a final newline in


@record
class Station:
    """Where this kiosk reports (``station:`` in the configuration)."""

    #: the station's base URL, http:// or https://
    url: str
    #: this kiosk's bearer token, issued by the station
    token: str
    #: this kiosk's name at the station
    kiosk_id: str = field(default_factory=default_kiosk_id)


@record
class InstrumentChoice:
    """One instrument of the configured battery (``instruments:``): a shipped instrument's id or a
    file, and the RoQME model its QoS runs on (None: the kiosk's ``qos_model``)."""

    #: the shipped instrument's id, or the file's path as given
    name: str
    #: the file (None: the shipped instrument ``name``)
    path: Path | None = None
    #: a bundled model's name or a .roqme file's absolute path (see kiosk.core.qos_model)
    qos_model: str | None = None


@record
class Config:
    """Settings of one kiosk. Build with :func:`load_config`."""

    #: where the SQLite database (and nothing else of the patients') lives; created 0700
    data_dir: Path = field(default_factory=lambda: Path(platformdirs.user_data_dir("kiosk")))
    #: default language on the welcome screen
    language: str = "en"
    #: a legacy plain clinician PIN (use clinician_pin_hash); the default must be changed
    clinician_pin: str = DEFAULT_PIN
    #: the clinician PIN's scrypt hash, written by `kiosk pin set` (wins over clinician_pin)
    clinician_pin_hash: str | None = None
    #: SHA-256 (hex) of the served page's device key, written by `kiosk serve --new-token`
    serve_token_sha256: str | None = None
    #: browser connections (kiosk processes) `kiosk serve` runs at once
    serve_max_sessions: int = SERVE_MAX_SESSIONS
    #: live adaptation (the clinician can still switch it off per session)
    adaptation: bool = True
    #: an adaptation policy file (None: the bundled kiosk/core/adaptation.yaml)
    adaptation_policy: Path | None = None
    #: the QoS model: a bundled model's name, or a .roqme file's absolute path (see kiosk.core.qos_model)
    qos_model: str = "clarc"
    #: a questionnaire file (None: the bundled Barthel questionnaire)
    questionnaire: Path | None = None
    #: a battery: the instruments of one visit, in order (empty: the one ``questionnaire``)
    instruments: tuple[InstrumentChoice, ...] = ()
    #: the questionnaire's band set that interprets totals (None: the file's default, Shah 1989)
    bands: str | None = None
    #: languages whose unvalidated translations this site accepts for clinical use (True: all);
    #: only read with a configuration file (see :func:`offered_to_patients`)
    accept_unvalidated_translations: tuple[str, ...] | bool = ()
    #: practice questions before the questionnaire
    familiarisation: bool = True
    #: overrides of the questionnaire's timing (attempt_window_s, between_questions_s, ...)
    timing: Mapping[str, float] = field(default_factory=dict)
    #: a Vosk model directory (None: pocketsphinx fallback / voice in off)
    vosk_model: Path | None = None
    #: user overrides of the remote-control profiles
    remote_profiles: Path | None = None
    #: short code of the site: part of each exported result's identifier (site + kiosk + session)
    site: str = "local"
    #: this kiosk's id: in exported identifiers, the FHIR Device and the station protocol; set it
    #: once (a changed id makes re-exports look like new results)
    kiosk_id: str = field(default_factory=default_kiosk_id)
    #: FHIR identity of the site's exports: any of FHIR_KEYS (defaults in kiosk.export.ExportSite)
    fhir: Mapping[str, str] = field(default_factory=dict)
    #: a running test older than this is marked interrupted (staff may continue it; no patient is offered it)
    interrupt_after_minutes: float = 120.0
    #: seconds the end screen ("Thank you, you are done. Please call the nurse.") stays before the
    #: kiosk goes back to the welcome for the next patient; the result stays stored for staff (None,
    #: never from a file: the end screen stays until staff start over, as in the UI tests)
    next_patient_after_s: float | None = 90.0
    #: seconds a patient may be away (camera, or staff's "Patient away") before the ward is alerted
    #: (None, never from a file: no alert)
    away_alert_after_s: float | None = 60.0
    #: unanswered questions in a row after which the ward is alerted and the kiosk waits for a touch
    #: (None, never from a file: it asks on, as the UI tests written before it expect)
    unattended_after: int | None = 2
    #: the end screen shows the patient their total and band (default: only staff see them)
    show_score_to_patient: bool = False
    #: an unordered test may be started at the welcome (stored and shown as a walk-up); false: only
    #: a visit ordered from the station or started by staff on the clinician screen
    walk_up: bool = True
    #: the site's rule for the patient identifiers staff type (a regular expression matched whole;
    #: kiosk.core.visits.DEFAULT_ID_PATTERN: digits with at most four letters in front)
    patient_id_pattern: str = DEFAULT_ID_PATTERN
    #: the site's own folder of instruments/, words/ and qos/ (kiosk.config.site_folder), outside
    #: the package so that upgrades keep it (None: none)
    site_dir: Path | None = None
    #: the site's fall-risk threshold for the Timed Up and Go (s): a time over it is shown "above the
    #: site's threshold", never as a diagnosis (13.5 s: Barry et al. 2014, docs/tug.md)
    tug_threshold_s: float = 13.5
    #: keep a Timed Up and Go's pose landmarks (never pictures) with its result (default: not kept)
    tug_keep_landmarks: bool = False
    #: the ward station this kiosk reports to (None: none; the kiosk works alone, as it always did)
    station: Station | None = None
    #: the file this was read from (None: defaults only)
    source: Path | None = None

    @property
    def default_pin(self) -> bool:
        """The PIN is still the public default."""
        return self.clinician_pin_hash is None and self.clinician_pin == DEFAULT_PIN

    @property
    def pin_secret(self) -> str:
        """What the PIN pad checks against: the hash, else the legacy plain PIN."""
        return self.clinician_pin_hash or self.clinician_pin


def tug_settings(config: Config) -> TugSettings:
    """The site's Timed Up and Go settings: its threshold and whether landmarks are kept."""
    from kiosk.core.tug.step import TugSettings  # the analysis' numpy loads with a test, not at start

    return TugSettings(threshold_s=config.tug_threshold_s, keep_landmarks=config.tug_keep_landmarks)


def site_from_config(config: Config) -> ExportSite:
    """The export site of a configuration: its ``site``, ``kiosk_id`` and ``fhir:`` systems."""
    return ExportSite(site=config.site, kiosk_id=config.kiosk_id, **dict(config.fhir))
