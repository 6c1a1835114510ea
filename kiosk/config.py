"""The kiosk's configuration: one frozen dataclass, from a YAML file plus environment overrides.

Where the file is: ``$KIOSK_CONFIG`` if set (it must exist), else
``<user config dir>/kiosk/config.yaml`` if present (``platformdirs.user_config_dir("kiosk")``),
else built-in defaults. Environment variables override the file: ``KIOSK_DATA_DIR``,
``KIOSK_LANGUAGE``, ``KIOSK_VOSK_MODEL``, ``KIOSK_STATION_URL``, ``KIOSK_STATION_TOKEN``.

Example ``config.yaml`` (every key optional)::

    data_dir: /var/lib/kiosk          # default: platformdirs.user_data_dir("kiosk")
    language: es                      # default language on the welcome screen
    clinician_pin_hash: "scrypt$…"    # written by `kiosk pin set` (6 to 12 digits); default PIN 1234
    serve_token_sha256: "…"           # written by `kiosk serve --new-token`: the served page's device key
    serve_max_sessions: 2             # browser connections `kiosk serve` runs at once
    adaptation: true                  # live adaptation on/off
    adaptation_policy: /etc/kiosk/adaptation.yaml
    qos_model: /etc/kiosk/ward.roqme  # the QoS model (default: the bundled clarc; also kiosk_pace)
    questionnaire: /etc/kiosk/barthel.yaml
    instruments: [barthel, lawton, gds15]   # or a battery, in order (instead of questionnaire:): shipped
                                      # ids or files; {id: gds15, qos_model: FILE} gives one its own model
    bands: spanish                    # a band set of the questionnaire (default: the file's default)
    accept_unvalidated_translations: [de]   # or true: unvalidated translations this site accepts
                                      # for clinical use (default none; see below)
    familiarisation: true             # practice questions before the questionnaire
    timing: {attempt_window_s: 30}    # overrides of the questionnaire's timing block
    vosk_model: /opt/vosk/vosk-model-small-es-0.42
    remote_profiles: /etc/kiosk/remotes.yaml
    site: hosp-north                  # short code of the site (default "local"); part of export ids
    kiosk_id: ward3-bed2              # this kiosk (default: the host name): exports and the station
    fhir:                             # FHIR identity of this site's exports (defaults: urn:barthel-kiosk:...)
      patient_system: https://hosp-north.example/sid/kiosk-patient
      questionnaire_url: https://hosp-north.example/fhir/Questionnaire/{id}   # {id}: each instrument's id
      identifier_system: https://hosp-north.example/sid/kiosk-result
      device_system: https://hosp-north.example/sid/kiosk
    interrupt_after_minutes: 120      # a test running longer is interrupted: staff may continue it
    next_patient_after_s: 90          # the end screen stays this long, then the welcome for the next patient
    show_score_to_patient: false      # the end screen shows the patient their total and band
    walk_up: true                     # anyone may start a test at the welcome (marked walk-up); false:
                                      # only ordered visits and visits staff start on the clinician screen
    station:                          # report to a ward station (docs/station-protocol.md)
      url: https://ward.example:8443  # without a url the kiosk talks to no station at all
      token: "…"                      # from `kiosk station add-kiosk NAME`
      kiosk_id: ward3-bed2            # the same as kiosk_id (older place; give one of the two)

Translations: an instrument's file marks each language's text validated (a published, validated
translation) or not (``translations:``). Without a configuration file the kiosk offers every
language, as it always did. A site's configuration offers patients only the validated languages
and those it names in ``accept_unvalidated_translations`` (``true``: all), and `kiosk run`
refuses a ``language:`` that is neither (:func:`offered_to_patients`), because an unvalidated
translation may not measure what the original does.

A legacy plain ``clinician_pin: "482193"`` still works (6 to 12 digits, or the default), with a
warning to run `kiosk pin set`. A bad file is one :class:`ConfigError` naming the file, line and
column and what is wrong.
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping
from dataclasses import field, fields, replace
from pathlib import Path
from typing import Any
from urllib.parse import urlsplit

import platformdirs

from basis import record
from fileio.bounded import BadFile, open_private, read_text
from fileio.positions import Problem, parse_file
from kiosk.core.pin import DEFAULT_PIN, MIN_DIGITS, hash_problem
from kiosk.core.questionnaire import SCREEN_LANGUAGES, Questionnaire, Timing, load_questionnaire
from kiosk.core.questionnaire.kept import load_questionnaire_kept
from kiosk.core.questionnaire.loading import bundled_path
from kiosk.core.site import ExportSite, default_kiosk_id
from qos import bundled_models

#: the FHIR settings a site may give (see kiosk.export.ExportSite for their defaults)
FHIR_KEYS = ("patient_system", "questionnaire_url", "identifier_system", "device_system")
#: an absolute URI of visible ASCII: no space, control character or '|' (matched whole: fullmatch)
_URI = re.compile(r"[A-Za-z][A-Za-z0-9+.-]*:[!-{}~]+")
#: a station address: http(s), a host of visible ASCII (IDN names in their xn-- form), an optional path
_STATION_URL = re.compile(r'https?://[!"$-.0->@-~]+(/[!"$->@-~]*)?')
#: a bearer token as RFC 6750 spells it (token68): it goes verbatim into an HTTP header
_TOKEN = re.compile(r"[A-Za-z0-9._~+/-]{1,512}=*")
#: browser connections `kiosk serve` runs at once unless configured: each is a kiosk process
#: of about 55 MB, and a ward kiosk has one screen
SERVE_MAX_SESSIONS = 2


class ConfigError(ValueError):
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
    #: the end screen shows the patient their total and band (default: only staff see them)
    show_score_to_patient: bool = False
    #: an unordered test may be started at the welcome (stored and shown as a walk-up); false: only
    #: a visit ordered from the station or started by staff on the clinician screen
    walk_up: bool = True
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


_PATHS = {"data_dir", "adaptation_policy", "questionnaire", "vosk_model", "remote_profiles"}
_BOOLS = {"adaptation", "familiarisation", "show_score_to_patient", "walk_up"}
_SHA256 = re.compile(r"[0-9a-f]{64}")
_KEYS = {f.name for f in fields(Config)} - {"source"}


def default_config_path() -> Path:
    """``<user config dir>/kiosk/config.yaml``."""
    return Path(platformdirs.user_config_dir("kiosk")) / "config.yaml"


def site_from_config(config: Config) -> ExportSite:
    """The export site of a configuration: its ``site``, ``kiosk_id`` and ``fhir:`` systems."""
    return ExportSite(site=config.site, kiosk_id=config.kiosk_id, **dict(config.fhir))


def load_config(path: str | Path | None = None, environ: Mapping[str, str] | None = None) -> Config:
    """Read the configuration (see the module docstring for where from); ConfigError if unusable."""
    env = os.environ if environ is None else environ
    if path is None and env.get("KIOSK_CONFIG"):
        path = Path(env["KIOSK_CONFIG"])
        if not path.is_file():
            raise ConfigError(f"KIOSK_CONFIG names {path}, which is not a file")
    if path is None and default_config_path().is_file():
        path = default_config_path()
    values: dict[str, Any] = {}
    if path is not None:
        values = _read(Path(path))
    overrides = {"KIOSK_DATA_DIR": "data_dir", "KIOSK_LANGUAGE": "language", "KIOSK_VOSK_MODEL": "vosk_model"}
    for var, key in overrides.items():
        if env.get(var):
            values[key] = _path(env[var], var) if key in _PATHS else env[var]
    station = values.get("station") or {}
    # one kiosk id for exports and the station: kiosk_id, or station.kiosk_id, never two different ones
    if station.get("kiosk_id") and values.get("kiosk_id", station["kiosk_id"]) != station["kiosk_id"]:
        raise ConfigError(
            f"{path}: kiosk_id {values['kiosk_id']!r} and station.kiosk_id {station['kiosk_id']!r} "
            "differ: one kiosk has one id (set kiosk_id only)"
        )
    values["kiosk_id"] = values.get("kiosk_id") or station.get("kiosk_id") or default_kiosk_id()
    station = {**station, "kiosk_id": values["kiosk_id"]} if station else station
    for var, key in (("KIOSK_STATION_URL", "url"), ("KIOSK_STATION_TOKEN", "token")):
        if env.get(var):
            station = {**station, key: env[var]}
    values["station"] = _station(station, f"{path}: station" if path is not None else "KIOSK_STATION_URL")
    from kiosk.core.words import WordsError, load_words

    try:  # the screens' words, read now so a bad words file stops the kiosk before any screen
        load_words()
    except WordsError as exc:
        raise ConfigError(str(exc)) from None
    if values.get("language", "en") not in SCREEN_LANGUAGES:
        raise ConfigError(f"language {values['language']!r} is not one of {', '.join(SCREEN_LANGUAGES)}")
    return Config(**values, source=Path(path) if path is not None else None)


def _no_secret(data: Any) -> bool:
    """Whether a configuration may be kept parsed in the user cache (:func:`fileio.positions.parse`):
    not with a station's bearer token or the served page's key digest in it."""
    return not (isinstance(data, dict) and {"station", "serve_token_sha256"} & set(data))


def _read(path: Path) -> dict[str, Any]:
    name = str(path)
    data, positions, problems = parse_file(path, keep=_no_secret)
    if problems and problems[0].message == "the file is empty":
        return {}  # a config file with every setting commented out means the defaults
    if problems:
        raise ConfigError(str(problems[0]))
    if data is None:
        return {}
    assert positions is not None

    def fail(key: tuple[Any, ...], message: str) -> ConfigError:
        line, col = positions.of(key, key=True)
        return ConfigError(str(Problem(name, line, col, message)))

    if not isinstance(data, dict):
        raise fail((), "the configuration is a mapping of settings (key: value)")
    values: dict[str, Any] = {}
    for key, value in data.items():
        if key not in _KEYS:
            raise fail((key,), f"unknown setting {key!r} (known: {', '.join(sorted(_KEYS))})")
        if key in _PATHS:
            try:
                value = _path(value, key)
            except ConfigError as exc:
                raise fail((key,), str(exc)) from None
            if not value.is_absolute():  # relative paths are relative to the config file
                value = path.parent / value
        elif key in _BOOLS:
            if not isinstance(value, bool):
                raise fail((key,), f"{key} must be true or false")
        elif key == "timing":
            if not isinstance(value, dict):
                raise fail((key,), "timing must be a mapping such as {attempt_window_s: 30}")
            try:
                Timing().with_overrides(value)
            except ValueError as exc:
                raise fail((key,), str(exc)) from None
            value = dict(value)
        elif key == "clinician_pin":
            if isinstance(value, int) and not isinstance(value, bool):
                raise fail((key,), 'write the PIN in quotes ("012345"), or leading zeros are lost')
            if (
                not isinstance(value, str)
                or not value.isascii()
                or not value.isdigit()
                or len(value) > 12
                or (len(value) < MIN_DIGITS and value != DEFAULT_PIN)
            ):
                raise fail(
                    (key,),
                    f"clinician_pin must be {MIN_DIGITS} to 12 digits, in quotes "
                    "(better: run `kiosk pin set`, which stores it hashed)",
                )
            if "clinician_pin_hash" in data:
                raise fail((key,), "clinician_pin and clinician_pin_hash are both set: remove clinician_pin")
        elif key == "clinician_pin_hash":
            problem = hash_problem(value) if isinstance(value, str) else "clinician_pin_hash must be text"
            if problem is not None:
                raise fail((key,), problem)
        elif key == "serve_token_sha256":
            if not isinstance(value, str) or not _SHA256.fullmatch(value):
                raise fail((key,), "serve_token_sha256 is not a key written by `kiosk serve --new-token`; run it again")
        elif key == "serve_max_sessions":
            if isinstance(value, bool) or not isinstance(value, int) or not 1 <= value <= 16:
                raise fail((key,), "serve_max_sessions must be a whole number from 1 to 16")
        elif key == "language" and (not isinstance(value, str) or value not in SCREEN_LANGUAGES):
            raise fail((key,), f"language must be one of {', '.join(SCREEN_LANGUAGES)}")
        elif key in ("site", "kiosk_id") and (not isinstance(value, str) or not KIOSK_ID.fullmatch(value)):
            raise fail((key,), f"{key} must be 1-64 letters, digits, '.', '-' or '_' (it goes into identifiers)")
        elif key == "fhir":
            if not isinstance(value, dict):
                raise fail((key,), "fhir must be a mapping such as {patient_system: https://example.org/sid/patient}")
            for setting, uri in value.items():  # not `name`: that is the file's, which fail() names
                if setting not in FHIR_KEYS:
                    raise fail((key, setting), f"unknown fhir setting {setting!r} (known: {', '.join(FHIR_KEYS)})")
                if not isinstance(uri, str) or not _URI.fullmatch(uri):
                    raise fail(
                        (key, setting),
                        f"fhir {setting} must be an absolute URI without spaces or '|', "
                        "in ASCII, such as https://example.org/sid/patient",
                    )
            value = dict(value)
        elif key == "station":
            if (
                not isinstance(value, dict)
                or set(value) - {"url", "token", "kiosk_id"}
                or not all(isinstance(v, str) for v in value.values())
            ):
                raise fail((key,), "station must be a mapping {url: ..., token: ..., kiosk_id: ...} of strings")
            try:
                _station(value, "station")
            except ConfigError as exc:
                line, col = positions.of((key, *exc.setting))
                raise ConfigError(str(Problem(name, line, col, str(exc)))) from None
        elif key == "interrupt_after_minutes":
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not 1 <= value <= 7 * 24 * 60:
                raise fail((key,), "interrupt_after_minutes must be a number of minutes, 1 to 10080")
        elif key == "qos_model":
            try:
                value = _model(value, path.parent)
            except ConfigError as exc:
                raise fail((key,), str(exc)) from None
        elif key == "instruments":
            if "questionnaire" in data:
                raise fail(
                    (key,),
                    "give either questionnaire: (one instrument) or instruments: (a battery), not both",
                )
            value = _instruments(value, path.parent, fail)
        elif key == "next_patient_after_s":
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not 5 <= value <= 3600:
                raise fail((key,), "next_patient_after_s must be a number of seconds, 5 to 3600")
        elif key == "accept_unvalidated_translations":
            value = _accepted_languages(value, lambda message, key=key: fail((key,), message))
        elif key == "bands" and (not isinstance(value, str) or not value):
            raise fail((key,), "bands must name a band set of the questionnaire, such as spanish")
        values[key] = value
    return values


def _accepted_languages(value: object, fail: Any) -> tuple[str, ...] | bool:
    """``accept_unvalidated_translations``: true, false, or a list of the kiosk's language codes."""
    if isinstance(value, bool):
        return value
    if not isinstance(value, list) or not all(isinstance(code, str) for code in value):
        raise fail("accept_unvalidated_translations must be true or a list of language codes such as [de, es]")
    unknown = [code for code in value if code not in SCREEN_LANGUAGES]
    if unknown:
        raise fail(
            f"accept_unvalidated_translations: {unknown[0]!r} is not a language of the kiosk "
            f"(it has {', '.join(SCREEN_LANGUAGES)})"
        )
    return tuple(dict.fromkeys(value))


def _model(value: object, folder: Path) -> str:
    """A ``qos_model:`` value resolved (see kiosk.core.qos_model.resolve_model); ConfigError if unusable."""
    from kiosk.core.qos_model import resolve_model

    if not isinstance(value, str) or not value.strip():
        raise ConfigError("qos_model must name a bundled model (clarc, kiosk_pace) or a .roqme file")
    value = resolve_model(value, folder)
    if "/" not in value and value not in bundled_models():
        raise ConfigError(
            f"no bundled model named {value!r} (bundled: {', '.join(bundled_models())}); "
            "give a path to a .roqme file instead"
        )
    return value


def _instruments(value: object, folder: Path, fail: Any) -> tuple[InstrumentChoice, ...]:
    """``instruments:``: a non-empty list of shipped ids or files, each also as ``{id: ..., qos_model:
    ...}`` (``file:`` for a file); ``fail(key, message)`` makes the positioned ConfigError."""
    key = "instruments"
    if not isinstance(value, list) or not value:
        raise fail((key,), "instruments must be a list such as [barthel, lawton, gds15]")
    chosen: list[InstrumentChoice] = []
    for index, entry in enumerate(value):
        where = (key, index)
        model = None
        if isinstance(entry, dict):
            unknown = set(entry) - {"id", "file", "qos_model"}
            if unknown or len({"id", "file"} & set(entry)) != 1:
                raise fail(
                    where,
                    "an instrument is a shipped id, a file, or {id: ID (or file: PATH), qos_model: MODEL}",
                )
            if "qos_model" in entry:
                try:
                    model = _model(entry["qos_model"], folder)
                except ConfigError as exc:
                    raise fail((key, index, "qos_model"), str(exc)) from None
            entry = entry.get("id", entry.get("file"))
        if not isinstance(entry, str) or not entry.strip():
            raise fail(where, "an instrument is a shipped instrument's id or a file's path")
        if "/" in entry or entry.endswith((".yaml", ".yml")):
            file = _path(entry, key)
            chosen.append(InstrumentChoice(entry, file if file.is_absolute() else folder / file, model))
        elif not bundled_path(f"{entry}.yaml").is_file():
            shipped = sorted(p.stem for p in bundled_path().parent.glob("*.yaml"))
            raise fail(where, f"no shipped instrument {entry!r} (shipped: {', '.join(shipped)}); or give a file")
        else:
            chosen.append(InstrumentChoice(entry, None, model))
    return tuple(chosen)


def _path(value: object, name: str) -> Path:
    """A path setting, ``~`` and ``~user`` expanded; ConfigError for one no command could use (not
    text, empty, a control character such as a line break or NUL, or an unknown user's ``~``)."""
    if not isinstance(value, str) or not value:
        raise ConfigError(f"{name} must be a path")
    if any(ord(c) < 32 or ord(c) == 127 for c in value) or any(0xD800 <= ord(c) <= 0xDFFF for c in value):
        raise ConfigError(
            f"{name} {value!r} holds a control character or bytes that are not UTF-8; "
            "write the path on one line, in UTF-8"
        )
    try:
        return Path(value).expanduser()
    except RuntimeError:  # no such user, or no home directory to expand ~ to
        user = value[1:].split("/", 1)[0]
        raise ConfigError(
            f"{name} {value!r}: "
            + (
                f"there is no user {user!r} to expand ~{user} for"
                if user
                else "there is no home directory to expand ~ to"
            )
        ) from None


def _station(values: Mapping[str, str], where: str) -> Station | None:
    """The station settings, checked; None without a url (a token alone is harmless)."""
    url = values.get("url", "")
    if not url:
        return None
    if not _STATION_URL.fullmatch(url):
        raise ConfigError(
            f"{where}: url {url!r} must be an http:// or https:// address of visible ASCII "
            "characters (no spaces, line breaks or query) such as https://ward.example:8443",
            ("url",),
        )
    try:
        port = urlsplit(url).port
    except ValueError:  # not digits, or past 65535
        port = 0
    if port == 0 or not urlsplit(url).hostname:
        raise ConfigError(f"{where}: url {url!r} needs a host and, if it names a port, one from 1 to 65535", ("url",))
    token = values.get("token")
    if not token:
        raise ConfigError(
            f"{where}: a token is needed with the url (KIOSK_STATION_TOKEN, or station.token; "
            "the station issues it with `kiosk station add-kiosk NAME`)",
            ("url",),
        )
    if not _TOKEN.fullmatch(token):
        raise ConfigError(
            f"{where}: the token is not one the station issues (letters, digits and -._~+/ only; "
            "no spaces or line breaks): copy it again from `kiosk station add-kiosk NAME`",
            ("token",),
        )
    kiosk_id = values.get("kiosk_id") or default_kiosk_id()
    if not KIOSK_ID.fullmatch(kiosk_id):
        raise ConfigError(
            f"{where}: kiosk_id {kiosk_id!r} must be 1-64 letters, digits, '.', '-' or '_'", ("kiosk_id",)
        )
    return Station(url.rstrip("/"), values["token"], kiosk_id)


def configured_instruments(config: Config) -> list[tuple[Questionnaire, str | None]]:
    """The battery this kiosk gives, in order: each instrument with its own QoS model (None: the
    kiosk's). ``questionnaire:`` (or nothing) is a battery of one. A ``bands`` set applies to the
    instruments that have it (ConfigError if none has). Raises QuestionnaireError or ConfigError."""
    if not config.instruments:
        return [(configured_questionnaire(config), None)]
    found: list[tuple[Questionnaire, str | None]] = []
    where = f"{config.source}: " if config.source else ""
    for choice in config.instruments:
        questionnaire = load_questionnaire(choice.path or bundled_path(f"{choice.name}.yaml"))
        if questionnaire.id in (q.id for q, _ in found):
            raise ConfigError(f"{where}instruments: {questionnaire.id!r} is given twice; a visit gives it once")
        found.append((_configured(config, questionnaire, needs_bands=False), choice.qos_model))
    if config.bands is not None and not any(config.bands in q.band_sets for q, _ in found):
        raise ConfigError(f"{where}bands: {config.bands!r} is not a band set of any of the instruments")
    return found


def configured_questionnaire(config: Config) -> Questionnaire:
    """The questionnaire this kiosk uses, scoring with the configured band set (with a battery,
    its first instrument).

    Raises :class:`~kiosk.core.questionnaire.QuestionnaireError` for a bad questionnaire file and
    :class:`ConfigError` when ``bands`` names a set the questionnaire does not have.
    """
    if config.instruments:
        return configured_instruments(config)[0][0]
    return _configured(config, load_questionnaire_kept(config.questionnaire))  # read back when it loaded before


def _configured(config: Config, questionnaire: Questionnaire, *, needs_bands: bool = True) -> Questionnaire:
    where = f"{config.source}: " if config.source else ""
    if config.language not in questionnaire.languages:
        raise ConfigError(
            f"{where}language: {config.language!r} is not a language of {questionnaire.source} "
            f"(it has {', '.join(questionnaire.languages)}); set language: to one of them"
        )
    if config.bands is None or (not needs_bands and config.bands not in questionnaire.band_sets):
        return questionnaire
    try:
        return questionnaire.with_band_set(config.bands)
    except KeyError:
        raise ConfigError(
            f"{where}bands: {config.bands!r} is not a band set of {questionnaire.source} "
            f"(it has {', '.join(questionnaire.band_sets)})"
        ) from None


def offered_to_patients(config: Config, questionnaire: Questionnaire) -> Questionnaire:
    """The questionnaire with only the languages this site offers patients: every language
    without a configuration file (as the kiosk always ran); with one, the validated translations
    and those ``accept_unvalidated_translations`` accepts.

    Raises :class:`ConfigError` (naming the file, line and column of ``language:``) when the
    kiosk's own language is not offered: an unvalidated translation is not used clinically
    until the site says it accepts it.
    """
    if config.source is None:
        return questionnaire
    accepted = config.accept_unvalidated_translations
    offered = tuple(
        language
        for language in questionnaire.languages
        if questionnaire.validated(language) or accepted is True or (accepted and language in accepted)
    )
    if config.language not in offered:
        entry = questionnaire.translations.get(config.language)
        what = f"its source: {entry.source}" if entry is not None else "the file names no source for it"
        raise ConfigError(
            f"{_setting_at(config.source, 'language')}language: {config.language!r} is an unvalidated "
            f"translation of {questionnaire.id} ({what}); add it to accept_unvalidated_translations "
            f"to accept it for clinical use, or set language: to one of {', '.join(offered) or 'none'}"
        )
    return replace(questionnaire, languages=offered)


def _setting_at(path: Path, key: str) -> str:
    """ "FILE:LINE:COL: " of ``key`` in a configuration file, "FILE: " when the file does not set it
    (the default or an environment override)."""
    data, positions, _ = parse_file(path)
    if positions is None or not isinstance(data, dict) or key not in data:
        return f"{path}: "
    line, column = positions.of((key,), key=True)
    return f"{path}:{line}:{column}: "


def write_settings(path: Path, changes: Mapping[str, str | None]) -> None:
    """Set (or, with None, remove) top-level settings of a configuration file, keeping its other
    lines and comments; the file is created if missing, and always left owner-only (0600).

    The new file is checked with :func:`load_config` before it replaces the old one, so a mistake
    leaves the old file as it was. Raises :class:`ConfigError`.
    """
    try:
        lines = read_text(path).splitlines() if path.exists() else []
    except BadFile as exc:
        raise ConfigError(str(exc)) from None
    for key, value in changes.items():
        lines = [line for line in lines if not re.match(rf"{re.escape(key)}\s*:", line)]
        if value is not None:
            lines.append(f'{key}: "{value}"')  # the values written here never hold quotes or backslashes
    path.parent.mkdir(parents=True, exist_ok=True)
    temporary = path.with_name(f".{path.name}.new")
    try:
        with open_private(temporary) as handle:
            handle.write("\n".join(lines) + "\n")
        load_config(temporary, environ={})
        os.replace(temporary, path)
    except ConfigError as exc:  # name the file staff know, not the one checked in its place
        raise ConfigError(str(exc).replace(str(temporary), str(path))) from None
    except OSError as exc:
        raise ConfigError(f"cannot write {path}: {exc.strerror or exc}") from None
    finally:
        temporary.unlink(missing_ok=True)
    os.chmod(path, 0o600)
