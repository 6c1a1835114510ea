"""Reading a configuration file: every setting checked, a mistake named by file, line and column."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any
from urllib.parse import urlsplit

from fileio.positions import Problem, parse_file
from kiosk.config.settings import (
    _BOOLS,
    _KEYS,
    _PATHS,
    _SHA256,
    _STATION_URL,
    _TOKEN,
    _URI,
    FHIR_KEYS,
    KIOSK_ID,
    ConfigError,
    InstrumentChoice,
    Station,
)
from kiosk.core.pin import DEFAULT_PIN, MIN_DIGITS, hash_problem
from kiosk.core.questionnaire import SCREEN_LANGUAGES, Timing
from kiosk.core.questionnaire.loading import bundled_path
from kiosk.core.site import default_kiosk_id
from kiosk.core.visits import pattern_problem
from qos import bundled_models


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
        elif key == "patient_id_pattern" and (problem := pattern_problem(value)) is not None:
            raise fail((key,), problem)
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
        elif key == "away_alert_after_s":
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not 10 <= value <= 3600:
                raise fail((key,), "away_alert_after_s must be a number of seconds, 10 to 3600")
        elif key == "tug_threshold_s":
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not 5 <= value <= 60:
                raise fail((key,), "tug_threshold_s must be a number of seconds, 5 to 60")
        elif key == "unattended_after":
            if isinstance(value, bool) or not isinstance(value, int) or not 1 <= value <= 10:
                raise fail((key,), "unattended_after must be a whole number of questions, 1 to 10")
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
