"""Device profiles for big-button remotes: which device to look for and what its buttons send.

The built-in profiles live in ``kiosk/remote/devices.yaml``. A site may add or change profiles
in its own file (the config's ``remote_profiles``) with the same layout: a profile whose ``name``
matches a built-in one overrides just the fields it gives (``enabled: false`` turns one off),
any other name adds a profile. Everything is validated before anything is used; the first
problem raises :class:`ProfileError`: one sentence naming the file, line and column, the profile
and the field.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import field
from pathlib import Path
from typing import Any

from basis import record
from basis.errors import KioskError
from fileio.positions import Positions, Problem, parse_file
from kiosk.remote.buttons import KIOSK_KEYS, Button, button_name, parse_button
from kiosk.remote.decoders import ReportMatch

#: the profiles shipped with the kiosk
BUILTIN_PROFILES = Path(__file__).with_name("devices.yaml")

KINDS = ("serial", "hid", "keyboard")

#: every field each kind of profile may have (a misspelt field is an error, not silently ignored)
_FIELDS = {
    "serial": {"name", "kind", "enabled", "description", "port", "baud", "max_line", "lines"},
    "hid": {"name", "kind", "enabled", "description", "vendor_id", "product_id", "report_id", "debounce_ms", "buttons"},
    "keyboard": {"name", "kind", "enabled", "description", "keys"},
}


class ProfileError(KioskError, ValueError):
    """A device profile file cannot be used; the message names the file, profile and field."""


@record
class SerialProfile:
    """A remote on a serial port that sends one text line per press, e.g. ``BTN 3``."""

    name: str
    #: a device path or a glob such as ``/dev/ttyUSB*``; the first port that opens is used
    port: str
    baud: int
    #: exact line text (without the newline) -> button
    lines: Mapping[str, Button]
    max_line: int = 64
    enabled: bool = True
    description: str = ""


@record
class HidProfile:
    """A USB HID remote, found by vendor and product id, whose input reports encode buttons."""

    name: str
    vendor_id: int
    product_id: int
    buttons: Mapping[Button, ReportMatch]
    #: first byte of every report this remote sends, if it numbers its reports
    report_id: int | None = None
    debounce_ms: float = 30.0
    enabled: bool = True
    description: str = ""

    @property
    def usb_id(self) -> str:
        """The ids the profile looks for, as :func:`usb_id` writes them."""
        return usb_id(self.vendor_id, self.product_id)


def usb_id(vendor_id: int, product_id: int) -> str:
    """``vvvv:pppp`` in hex, the way ``lsusb`` prints a USB device's ids."""
    return f"{vendor_id:04x}:{product_id:04x}"


@record
class KeyboardProfile:
    """A remote that presents itself as a keyboard; ``keys`` maps Textual key names to buttons."""

    name: str
    keys: Mapping[str, Button]
    enabled: bool = True
    description: str = ""


Profile = SerialProfile | HidProfile | KeyboardProfile


@record
class Profiles:
    """All known profiles, in file order (built-in first, then the site's additions)."""

    all: tuple[Profile, ...] = field(default_factory=tuple)

    @property
    def serial(self) -> list[SerialProfile]:
        """Enabled serial profiles."""
        return [p for p in self.all if isinstance(p, SerialProfile) and p.enabled]

    @property
    def hid(self) -> list[HidProfile]:
        """Enabled HID profiles."""
        return [p for p in self.all if isinstance(p, HidProfile) and p.enabled]

    @property
    def keyboard(self) -> list[KeyboardProfile]:
        """Enabled keyboard-emulating profiles."""
        return [p for p in self.all if isinstance(p, KeyboardProfile) and p.enabled]


def load_profiles(user_path: str | Path | None = None) -> Profiles:
    """Load the built-in profiles, apply the site's file ``user_path`` if given, and validate."""
    merged: dict[str, _Fields] = {}
    for path in [BUILTIN_PROFILES] + ([Path(user_path)] if user_path is not None else []):
        for entry in _read_file(path):
            name = entry.raw["name"]
            if name in merged:
                merged[name].override(entry)
            else:
                merged[name] = entry
    profiles = tuple(_build(fields) for fields in merged.values())
    _check_keyboard_clashes(profiles, merged)
    return Profiles(profiles)


class _Where:
    """Where one profile was written: the file, its positions, and the profile's list index."""

    def __init__(self, path: Path, positions: Positions, index: int) -> None:
        self.path, self.positions, self.index = path, positions, index

    def problem(self, keys: tuple[Any, ...], message: str) -> ProfileError:
        line, column = self.positions.of(("profiles", self.index) + keys, key=True)
        return ProfileError(str(Problem(str(self.path), line, column, message)))


def _read_file(path: Path) -> list[_Fields]:
    document, positions, problems = parse_file(path, keep=True)  # kept: no PyYAML at a second start
    if problems:
        raise ProfileError(str(problems[0]))
    assert positions is not None
    if not isinstance(document, dict) or set(document) != {"profiles"}:
        line, column = positions.of(())
        raise ProfileError(
            str(Problem(str(path), line, column, "expected a mapping with one key, 'profiles', holding a list"))
        )
    entries = document["profiles"] or []
    if not isinstance(entries, list):
        line, column = positions.of(("profiles",))
        raise ProfileError(str(Problem(str(path), line, column, "'profiles' must be a list of profiles")))
    read: list[_Fields] = []
    seen: set[str] = set()
    for index, entry in enumerate(entries):
        where = _Where(path, positions, index)
        if not isinstance(entry, dict):
            raise where.problem((), f"profile #{index + 1} must be a mapping of fields")
        name = entry.get("name")
        if not isinstance(name, str) or not name.strip():
            raise where.problem(("name",), f"profile #{index + 1}, field 'name': must be a non-empty text")
        if name in seen:
            raise where.problem(("name",), f"profile {name!r}, field 'name': appears twice in this file")
        seen.add(name)
        read.append(_Fields(entry, where))
    return read


class _Fields:
    """One profile's fields, merged over the files that set them; reading a field checks it, and
    a problem becomes a ProfileError naming the file, line, profile and field."""

    def __init__(self, raw: dict[str, Any], where: _Where) -> None:
        self.raw = dict(raw)
        self.name = raw["name"]
        # which file set each field, so an error points at the line that is wrong
        self.origin = {key: where for key in raw}

    def override(self, other: _Fields) -> None:
        self.raw.update(other.raw)
        self.origin.update(other.origin)

    def fail(self, key: str, problem: str, sub: tuple[Any, ...] = ()) -> ProfileError:
        where = self.origin.get(key, self.origin["name"])
        dotted = ".".join([key, *map(str, sub)])
        return where.problem((key, *map(str, sub)), f"profile {self.name!r}, field '{dotted}': {problem}")

    def get(self, key: str, default: Any = ...) -> Any:
        if key not in self.raw:
            if default is ...:
                raise self.fail(key, "is required")
            return default
        return self.raw[key]

    def integer(self, key: str, default: Any = ..., low: int = 0, high: int | None = None) -> Any:
        value = self.get(key, default)
        if value is None and default is None:
            return None
        return self.check_int(key, value, low, high)

    def check_int(self, key: str, value: Any, low: int, high: int | None, sub: tuple[Any, ...] = ()) -> int:
        if isinstance(value, str):
            try:
                value = int(value, 0)  # "0x1209" as well as 4617
            except ValueError:
                pass
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.fail(key, f"must be a whole number, got {value!r}", sub)
        if value < low or (high is not None and value > high):
            bounds = f"from {low} to {high}" if high is not None else f"at least {low}"
            raise self.fail(key, f"must be {bounds}, got {value}", sub)
        return value

    def text(self, key: str, default: Any = ...) -> str:
        value = self.get(key, default)
        if not isinstance(value, str) or not value.strip():
            raise self.fail(key, f"must be a non-empty text, got {value!r}")
        return value

    def flag(self, key: str, default: bool) -> bool:
        value = self.get(key, default)
        if not isinstance(value, bool):
            raise self.fail(key, f"must be true or false, got {value!r}")
        return value

    def mapping(self, key: str) -> dict[Any, Any]:
        value = self.get(key)
        if not isinstance(value, dict) or not value:
            raise self.fail(key, "must be a non-empty mapping")
        return value

    def button(self, key: str, value: Any, sub: tuple[Any, ...]) -> Button:
        try:
            return parse_button(value)
        except ValueError as error:
            raise self.fail(key, str(error), sub) from None


def _build(fields: _Fields) -> Profile:
    raw = fields.raw
    kind = fields.get("kind")
    if kind not in KINDS:
        raise fields.fail("kind", f"must be one of {', '.join(KINDS)}, got {kind!r}")
    unknown = sorted(set(raw) - _FIELDS[kind], key=str)
    if unknown:
        allowed = ", ".join(sorted(_FIELDS[kind]))
        raise fields.fail(str(unknown[0]), f"is not a field of a {kind} profile (fields: {allowed})")
    common = {
        "name": fields.name,
        "enabled": fields.flag("enabled", True),
        "description": fields.get("description", ""),
    }
    if not isinstance(common["description"], str):
        raise fields.fail("description", "must be text")
    if kind == "serial":
        return _build_serial(fields, common)
    if kind == "hid":
        return _build_hid(fields, common)
    return _build_keyboard(fields, common)


#: path components a serial port's pattern may have under /dev (/dev/serial/by-id/usb-* is three)
MAX_PORT_DEPTH = 4


def port_problem(port: str) -> str | None:
    """Why ``port`` cannot be a serial port's path or glob, or None. A port is a device file:
    an absolute path under /dev, at most :data:`MAX_PORT_DEPTH` components deep, without '..',
    '**', spaces or control characters. Why: the kiosk globs it on every connection attempt, and
    ``/**/*`` walked the whole file system (11-15 s each time)."""
    parts = port.split("/")
    if not port.startswith("/dev/") or port == "/dev/":
        return f"must be a device path under /dev such as /dev/ttyUSB0 or /dev/ttyUSB*, got {port!r}"
    if any(c.isspace() or not c.isprintable() for c in port):
        return f"may not hold spaces or control characters, got {port!r}"
    if ".." in parts or "**" in port:
        return f"may not hold '..' or '**' (one '*' matches within a name), got {port!r}"
    if len(parts) - 2 > MAX_PORT_DEPTH or "" in parts[2:]:
        return f"must be at most {MAX_PORT_DEPTH} names below /dev, without '//' or a final '/', got {port!r}"
    return None


def _build_serial(fields: _Fields, common: dict[str, Any]) -> SerialProfile:
    max_line = fields.integer("max_line", 64, low=1, high=4096)
    lines: dict[str, Button] = {}
    for text, value in fields.mapping("lines").items():
        sub = (text,)
        if not isinstance(text, str) or not text.strip():
            raise fields.fail("lines", "each line must be a non-empty text", sub)
        if text != text.strip(" \t\r") or "\n" in text:
            raise fields.fail("lines", "a line may not start or end with spaces or hold a newline", sub)
        if len(text.encode("utf-8")) > max_line:
            raise fields.fail("lines", f"is longer than max_line ({max_line} bytes)", sub)
        lines[text] = fields.button("lines", value, sub)
    port = fields.text("port")
    if (problem := port_problem(port)) is not None:
        raise fields.fail("port", problem)
    return SerialProfile(
        port=port,
        baud=fields.integer("baud", 9600, low=1),
        lines=lines,
        max_line=max_line,
        **common,
    )


def _build_hid(fields: _Fields, common: dict[str, Any]) -> HidProfile:
    buttons: dict[Button, ReportMatch] = {}
    for key, spec in fields.mapping("buttons").items():
        sub = (key,)
        button = fields.button("buttons", key, sub)
        if button in buttons:
            raise fields.fail("buttons", "names the same button twice", sub)
        if not isinstance(spec, dict) or not {"byte"} <= set(spec) <= {"byte", "mask", "value"} or len(spec) != 2:
            raise fields.fail("buttons", "must be {byte: N, mask: M} or {byte: N, value: V}", sub)
        byte = fields.check_int("buttons", spec["byte"], 0, 63, (*sub, "byte"))
        kind = "mask" if "mask" in spec else "value"
        number = fields.check_int("buttons", spec[kind], 1 if kind == "mask" else 0, 255, (*sub, kind))
        buttons[button] = ReportMatch(byte=byte, **{kind: number})
    debounce = fields.get("debounce_ms", 30)
    if isinstance(debounce, bool) or not isinstance(debounce, int | float) or debounce < 0:
        raise fields.fail("debounce_ms", f"must be a number of milliseconds, 0 or more, got {debounce!r}")
    return HidProfile(
        vendor_id=fields.integer("vendor_id", high=0xFFFF),
        product_id=fields.integer("product_id", high=0xFFFF),
        report_id=fields.integer("report_id", None, high=255),
        debounce_ms=float(debounce),
        buttons=buttons,
        **common,
    )


def _build_keyboard(fields: _Fields, common: dict[str, Any]) -> KeyboardProfile:
    keys: dict[str, Button] = {}
    for key, value in fields.mapping("keys").items():
        sub = (key,)
        if not isinstance(key, str) or not key.strip():
            raise fields.fail("keys", "each key must be a Textual key name such as 'f13' or 'pageup'", sub)
        if key.lower() in KIOSK_KEYS:
            raise fields.fail(
                "keys",
                f"key {key!r} is one of the kiosk's own keys ({', '.join(sorted(KIOSK_KEYS))}); pick another",
                sub,
            )
        keys[key] = fields.button("keys", value, sub)
    return KeyboardProfile(keys=keys, **common)


def _check_keyboard_clashes(profiles: tuple[Profile, ...], fields: dict[str, _Fields]) -> None:
    """Two enabled keyboard remotes may not give one key two meanings."""
    owner: dict[str, tuple[KeyboardProfile, Button]] = {}
    for profile in profiles:
        if not (isinstance(profile, KeyboardProfile) and profile.enabled):
            continue
        for key, button in profile.keys.items():
            if key in owner and owner[key][1] != button:
                other, theirs = owner[key]
                raise fields[profile.name].fail(
                    "keys",
                    f"means {button_name(button)!r} here but {button_name(theirs)!r} in enabled profile {other.name!r}",
                    (key,),
                )
            owner[key] = (profile, button)
