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
    site_dir: /etc/kiosk/site         # the site's instruments/, words/ (new languages), qos/: see README
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
    away_alert_after_s: 60            # a patient away this long (camera or "Patient away") alerts the ward
    unattended_after: 2               # this many questions in a row unanswered: the ward is alerted and
                                      # the kiosk waits for a touch instead of asking on
    show_score_to_patient: false      # the end screen shows the patient their total and band
    tug_threshold_s: 13.5             # Timed Up and Go: a time over it is "above the site's threshold"
    tug_keep_landmarks: false         # keep a TUG's pose landmarks (never pictures) with its result
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
from pathlib import Path
from typing import Any

import platformdirs

from fileio.bounded import BadFile, open_private, read_text
from kiosk.config.checks import PATH_SETTINGS, check_path, station_from
from kiosk.config.instruments import (
    configured_instruments,
    configured_questionnaire,
    configured_steps,
    offered_to_patients,
)
from kiosk.config.reading import read_file
from kiosk.config.settings import (
    FHIR_KEYS,
    KIOSK_ID,
    SERVE_MAX_SESSIONS,
    Config,
    ConfigError,
    InstrumentChoice,
    Station,
    site_from_config,
    tug_settings,
)
from kiosk.core.pin import DEFAULT_PIN
from kiosk.core.questionnaire import SCREEN_LANGUAGES
from kiosk.core.site import default_kiosk_id

__all__ = [
    "DEFAULT_PIN",
    "FHIR_KEYS",
    "KIOSK_ID",
    "SERVE_MAX_SESSIONS",
    "Config",
    "ConfigError",
    "InstrumentChoice",
    "Station",
    "configured_instruments",
    "configured_steps",
    "configured_questionnaire",
    "default_config_path",
    "load_config",
    "offered_to_patients",
    "site_from_config",
    "tug_settings",
    "write_settings",
]


def default_config_path() -> Path:
    """``<user config dir>/kiosk/config.yaml``."""
    return Path(platformdirs.user_config_dir("kiosk")) / "config.yaml"


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
    from kiosk.core.words import use_site_words

    use_site_words(None)  # a site's languages are those of the configuration read last
    if path is not None:
        values = read_file(Path(path))
    overrides = {"KIOSK_DATA_DIR": "data_dir", "KIOSK_LANGUAGE": "language", "KIOSK_VOSK_MODEL": "vosk_model"}
    for var, key in overrides.items():
        if env.get(var):
            values[key] = check_path(env[var], var) if key in PATH_SETTINGS else env[var]
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
    values["station"] = station_from(station, f"{path}: station" if path is not None else "KIOSK_STATION_URL")
    from kiosk.core.words import WordsError, load_words

    try:  # the screens' words, read now so a bad words file stops the kiosk before any screen
        load_words()
    except WordsError as exc:
        raise ConfigError(str(exc)) from None
    if values.get("language", "en") not in SCREEN_LANGUAGES:
        raise ConfigError(f"language {values['language']!r} is not one of {', '.join(SCREEN_LANGUAGES)}")
    return Config(**values, source=Path(path) if path is not None else None)


def _block_lines(text: str) -> list[str]:
    """The file's lines, with a mapping written in flow style (``{}``, ``{language: en}``) turned
    into block style first, so that a ``key: value`` line can be added after it (issue 32: after
    ``{}`` it was a YAML error at line 2). A file that is not YAML is left to :func:`load_config`."""
    import yaml

    try:
        root = yaml.compose(text, Loader=yaml.SafeLoader)
    except yaml.YAMLError:
        return text.splitlines()
    if not isinstance(root, yaml.MappingNode) or not root.flow_style:
        return text.splitlines()
    data = yaml.safe_load(text)
    comments = [line for line in text.splitlines() if line.lstrip().startswith("#")]
    block = yaml.safe_dump(data, default_flow_style=False, sort_keys=False, allow_unicode=True) if data else ""
    return comments + block.splitlines()


def write_settings(path: Path, changes: Mapping[str, str | None]) -> None:
    """Set (or, with None, remove) top-level settings of a configuration file, keeping its other
    lines and comments; the file is created if missing, and always left owner-only (0600).

    The new file is checked with :func:`load_config` before it replaces the old one, so a mistake
    leaves the old file as it was. Raises :class:`ConfigError`.
    """
    try:
        lines = _block_lines(read_text(path)) if path.exists() else []
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
