"""Each setting of a configuration file, declared once: :data:`SETTINGS` maps its name to the
check that turns what the file says into the :class:`~kiosk.config.settings.Config` field's value
(the field declares its type and default). Reading (:mod:`kiosk.config.reading`), the known keys
and the environment overrides' paths all come from this table, so a new setting is one field and
one row.

A check raises :class:`Invalid` (message, and where below the setting the mistake is), which the
reader turns into a :class:`~kiosk.config.settings.ConfigError` naming the file, line and column.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any
from urllib.parse import urlsplit

from kiosk.config.settings import FHIR_KEYS, KIOSK_ID, Config, ConfigError, InstrumentChoice, Station
from kiosk.config.site_folder import SiteFolder, check_site_folder
from kiosk.core.pin import DEFAULT_PIN, MIN_DIGITS, hash_problem
from kiosk.core.questionnaire import SCREEN_LANGUAGES, Timing
from kiosk.core.questionnaire.loading import bundled_path
from kiosk.core.site import default_kiosk_id
from kiosk.core.visits import TUG, pattern_problem
from qos import bundled_models

#: an absolute URI of visible ASCII: no space, control character or '|' (matched whole: fullmatch)
URI = re.compile(r"[A-Za-z][A-Za-z0-9+.-]*:[!-{}~]+")
#: a station address: http(s), a host of visible ASCII (IDN names in their xn-- form), an optional path
STATION_URL = re.compile(r'https?://[!"$-.0->@-~]+(/[!"$->@-~]*)?')
#: a bearer token as RFC 6750 spells it (token68): it goes verbatim into an HTTP header
TOKEN = re.compile(r"[A-Za-z0-9._~+/-]{1,512}=*")
SHA256 = re.compile(r"[0-9a-f]{64}")


class Invalid(Exception):
    """A setting's value is unusable: ``message``, at ``where`` below the setting (its key when
    ``key``, else the value there)."""

    def __init__(self, message: str, where: tuple[Any, ...] = (), key: bool = True) -> None:
        super().__init__(message)
        self.message, self.where, self.key = message, where, key


@dataclass(frozen=True)
class Context:
    """What a check may look at besides its value: the whole file's settings and its folder."""

    data: Mapping[str, Any]
    folder: Path
    #: the site's own folder (``site_dir``), read before every other setting; None without one
    site: SiteFolder | None = None


Check = Callable[[Any, Context], Any]


def check_path(value: object, name: str) -> Path:
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


def station_from(values: Mapping[str, str], where: str) -> Station | None:
    """The station settings, checked; None without a url (a token alone is harmless)."""
    url = values.get("url", "")
    if not url:
        return None
    if not STATION_URL.fullmatch(url):
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
    if not TOKEN.fullmatch(token):
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


def load_site(folder: Path) -> SiteFolder:
    """The site's folder, checked whole; ConfigError with every problem, one line each."""
    site, problems, _ = check_site_folder(folder)
    if problems:
        raise ConfigError("\n".join(map(str, problems)))
    return site


def resolve_qos_model(value: object, folder: Path, site: SiteFolder | None = None) -> str:
    """A ``qos_model:`` value resolved (see kiosk.core.qos_model.resolve_model; a bare name may be
    one of the site's models); ConfigError if unusable, a file that is not there too."""
    from kiosk.core.qos_model import resolve_model

    if not isinstance(value, str) or not value.strip():
        raise ConfigError("qos_model must name a bundled model (clarc, kiosk_pace) or a .roqme file")
    if site is not None and value in site.models:
        return str(site.models[value])
    value = resolve_model(value, folder)
    if "/" in value and not Path(value).is_file():
        raise ConfigError(f"qos_model: no model file {value}")
    if "/" not in value and value not in bundled_models():
        raise ConfigError(
            f"no bundled model named {value!r} (bundled: {', '.join(bundled_models())}); "
            "give a path to a .roqme file instead"
        )
    return value


# -- the checks of the table's rows --------------------------------------------------------------


class PathCheck:
    """A path setting; a relative path is relative to the configuration file."""

    def __init__(self, name: str) -> None:
        self.name = name

    def __call__(self, value: object, context: Context) -> Path:
        try:
            path = check_path(value, self.name)
        except ConfigError as exc:
            raise Invalid(str(exc)) from None
        return path if path.is_absolute() else context.folder / path


def _flag(name: str) -> Check:
    def check(value: object, context: Context) -> bool:
        if not isinstance(value, bool):
            raise Invalid(f"{name} must be true or false")
        return value

    return check


def _number(low: float, high: float, message: str, whole: bool = False) -> Check:
    """A number from ``low`` to ``high`` (a whole one when ``whole``); never a bool."""

    def check(value: object, context: Context) -> object:
        if isinstance(value, bool) or not isinstance(value, (int, float)) or (whole and not isinstance(value, int)):
            raise Invalid(message)
        if not low <= value <= high:
            raise Invalid(message)
        return value

    return check


def _text(allowed: Callable[[str], object], message: Callable[[], str]) -> Check:
    """Text that ``allowed`` accepts (truthy)."""

    def check(value: object, context: Context) -> object:
        if not isinstance(value, str) or not allowed(value):
            raise Invalid(message())
        return value

    return check


def _identifier(name: str) -> Check:
    return _text(
        KIOSK_ID.fullmatch, lambda: f"{name} must be 1-64 letters, digits, '.', '-' or '_' (it goes into identifiers)"
    )


def _timing(value: object, context: Context) -> dict[str, Any]:
    if not isinstance(value, dict):
        raise Invalid("timing must be a mapping such as {attempt_window_s: 30}")
    try:
        Timing().with_overrides(value)
    except ValueError as exc:
        raise Invalid(str(exc)) from None
    return dict(value)


def _clinician_pin(value: object, context: Context) -> object:
    if isinstance(value, int) and not isinstance(value, bool):
        raise Invalid('write the PIN in quotes ("012345"), or leading zeros are lost')
    if (
        not isinstance(value, str)
        or not value.isascii()
        or not value.isdigit()
        or len(value) > 12
        or (len(value) < MIN_DIGITS and value != DEFAULT_PIN)
    ):
        raise Invalid(
            f"clinician_pin must be {MIN_DIGITS} to 12 digits, in quotes "
            "(better: run `kiosk pin set`, which stores it hashed)"
        )
    if "clinician_pin_hash" in context.data:
        raise Invalid("clinician_pin and clinician_pin_hash are both set: remove clinician_pin")
    return value


def _clinician_pin_hash(value: object, context: Context) -> object:
    problem = hash_problem(value) if isinstance(value, str) else "clinician_pin_hash must be text"
    if problem is not None:
        raise Invalid(problem)
    return value


def _patient_id_pattern(value: Any, context: Context) -> object:
    if (problem := pattern_problem(value)) is not None:
        raise Invalid(problem)
    return value


def _fhir(value: object, context: Context) -> dict[str, Any]:
    if not isinstance(value, dict):
        raise Invalid("fhir must be a mapping such as {patient_system: https://example.org/sid/patient}")
    for setting, uri in value.items():
        if setting not in FHIR_KEYS:
            raise Invalid(f"unknown fhir setting {setting!r} (known: {', '.join(FHIR_KEYS)})", (setting,))
        if not isinstance(uri, str) or not URI.fullmatch(uri):
            raise Invalid(
                f"fhir {setting} must be an absolute URI without spaces or '|', "
                "in ASCII, such as https://example.org/sid/patient",
                (setting,),
            )
    return dict(value)


def _station(value: object, context: Context) -> object:
    """Checked here for its place in the file; the station itself is built when the environment's
    overrides are known (:func:`kiosk.config.load_config`)."""
    if (
        not isinstance(value, dict)
        or set(value) - {"url", "token", "kiosk_id"}
        or not all(isinstance(v, str) for v in value.values())
    ):
        raise Invalid("station must be a mapping {url: ..., token: ..., kiosk_id: ...} of strings")
    try:
        station_from(value, "station")
    except ConfigError as exc:
        raise Invalid(str(exc), exc.setting, key=False) from None
    return value


def _qos_model(value: object, context: Context) -> str:
    try:
        return resolve_qos_model(value, context.folder, context.site)
    except ConfigError as exc:
        raise Invalid(str(exc)) from None


def _instruments(value: object, context: Context) -> tuple[InstrumentChoice, ...]:
    """``instruments:``: a non-empty list of shipped ids or files, each also as ``{id: ..., qos_model:
    ...}`` (``file:`` for a file)."""
    if "questionnaire" in context.data:
        raise Invalid("give either questionnaire: (one instrument) or instruments: (a battery), not both")
    if not isinstance(value, list) or not value:
        raise Invalid("instruments must be a list such as [barthel, lawton, gds15]")
    if all(entry == TUG for entry in value):
        raise Invalid(f"instruments: {TUG} is given within a visit with at least one questionnaire")
    if value.count(TUG) > 1:
        raise Invalid(f"instruments: {TUG!r} is given twice; a visit gives it once")
    return tuple(_instrument(entry, index, context.folder, context.site) for index, entry in enumerate(value))


def _instrument(entry: object, index: int, folder: Path, site: SiteFolder | None) -> InstrumentChoice:
    """One entry of ``instruments:``; an id is the site's instrument of that id before a shipped one."""
    model = None
    if isinstance(entry, dict):
        unknown = set(entry) - {"id", "file", "qos_model"}
        if unknown or len({"id", "file"} & set(entry)) != 1:
            raise Invalid(
                "an instrument is a shipped id, a file, or {id: ID (or file: PATH), qos_model: MODEL}", (index,)
            )
        if "qos_model" in entry:
            try:
                model = resolve_qos_model(entry["qos_model"], folder, site)
            except ConfigError as exc:
                raise Invalid(str(exc), (index, "qos_model")) from None
        entry = entry.get("id", entry.get("file"))
    if not isinstance(entry, str) or not entry.strip():
        raise Invalid("an instrument is a shipped instrument's id or a file's path", (index,))
    if "/" in entry or entry.endswith((".yaml", ".yml")):
        file = check_path(entry, "instruments")  # its ConfigError names no position, as it always did
        return InstrumentChoice(entry, file if file.is_absolute() else folder / file, model)
    if site is not None and entry in site.instruments:
        return InstrumentChoice(entry, site.instruments[entry], model)
    if entry == TUG:  # the Timed Up and Go: a step of the visit, not a questionnaire (issue 34)
        return InstrumentChoice(entry, None, model)
    if not bundled_path(f"{entry}.yaml").is_file():
        shipped = sorted(p.stem for p in bundled_path().parent.glob("*.yaml"))
        raise Invalid(f"no shipped instrument {entry!r} (shipped: {', '.join(shipped)}); or give a file", (index,))
    return InstrumentChoice(entry, None, model)


def _site_dir(value: object, context: Context) -> Path:
    """``site_dir``: the site's folder of instruments/, words/ and qos/ (checked whole by :func:`load_site`)."""
    folder = PathCheck("site_dir")(value, context)
    if not folder.is_dir():
        raise Invalid(f"site_dir: {folder} is not a folder (of instruments/, words/ and qos/)")
    return folder


def _accepted_languages(value: object, context: Context) -> tuple[str, ...] | bool:
    """``accept_unvalidated_translations``: true, false, or a list of the kiosk's language codes."""
    if isinstance(value, bool):
        return value
    if not isinstance(value, list) or not all(isinstance(code, str) for code in value):
        raise Invalid("accept_unvalidated_translations must be true or a list of language codes such as [de, es]")
    unknown = [code for code in value if code not in SCREEN_LANGUAGES]
    if unknown:
        raise Invalid(
            f"accept_unvalidated_translations: {unknown[0]!r} is not a language of the kiosk "
            f"(it has {', '.join(SCREEN_LANGUAGES)})"
        )
    return tuple(dict.fromkeys(value))


#: every setting a file may give, and its check (the Config field of the same name has its type
#: and default)
SETTINGS: dict[str, Check] = {
    "data_dir": PathCheck("data_dir"),
    "language": _text(
        lambda value: value in SCREEN_LANGUAGES, lambda: f"language must be one of {', '.join(SCREEN_LANGUAGES)}"
    ),
    "clinician_pin": _clinician_pin,
    "clinician_pin_hash": _clinician_pin_hash,
    "serve_token_sha256": _text(
        SHA256.fullmatch,
        lambda: "serve_token_sha256 is not a key written by `kiosk serve --new-token`; run it again",
    ),
    "serve_max_sessions": _number(1, 16, "serve_max_sessions must be a whole number from 1 to 16", whole=True),
    "adaptation": _flag("adaptation"),
    "adaptation_policy": PathCheck("adaptation_policy"),
    "qos_model": _qos_model,
    "questionnaire": PathCheck("questionnaire"),
    "instruments": _instruments,
    "bands": _text(bool, lambda: "bands must name a band set of the questionnaire, such as spanish"),
    "accept_unvalidated_translations": _accepted_languages,
    "familiarisation": _flag("familiarisation"),
    "timing": _timing,
    "vosk_model": PathCheck("vosk_model"),
    "remote_profiles": PathCheck("remote_profiles"),
    "site": _identifier("site"),
    "kiosk_id": _identifier("kiosk_id"),
    "fhir": _fhir,
    "interrupt_after_minutes": _number(
        1, 7 * 24 * 60, "interrupt_after_minutes must be a number of minutes, 1 to 10080"
    ),
    "next_patient_after_s": _number(5, 3600, "next_patient_after_s must be a number of seconds, 5 to 3600"),
    "away_alert_after_s": _number(10, 3600, "away_alert_after_s must be a number of seconds, 10 to 3600"),
    "unattended_after": _number(1, 10, "unattended_after must be a whole number of questions, 1 to 10", whole=True),
    "show_score_to_patient": _flag("show_score_to_patient"),
    "walk_up": _flag("walk_up"),
    "patient_id_pattern": _patient_id_pattern,
    "station": _station,
    "site_dir": _site_dir,
    "tug_threshold_s": _number(5, 60, "tug_threshold_s must be a number of seconds, 5 to 60"),
    "tug_keep_landmarks": _flag("tug_keep_landmarks"),
}
#: the settings that are paths (the environment's overrides of them are checked as paths too)
PATH_SETTINGS = frozenset(name for name, check in SETTINGS.items() if isinstance(check, PathCheck))

_FIELDS = {f.name for f in fields(Config)} - {"source"}
if set(SETTINGS) != _FIELDS:  # a developer's slip: a field without its row, or a row without its field
    raise AssertionError(f"kiosk.config.checks.SETTINGS and Config differ: {sorted(set(SETTINGS) ^ _FIELDS)}")
