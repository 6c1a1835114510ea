"""`kiosk pin set [--config FILE]`: choose the clinician PIN; its scrypt hash goes into the config.

The PIN is asked twice on a terminal (never echoed), or read as one line from standard input
(``echo 482193 | kiosk pin set``) for provisioning scripts. The configuration file keeps its other
lines, loses any plain ``clinician_pin``, and is left owner-only (0600).
"""

from __future__ import annotations

import argparse
import getpass
import os
import sys
from pathlib import Path

from kiosk.config import ConfigError, default_config_path, write_settings
from kiosk.core.pin import MAX_DIGITS, MIN_DIGITS, hash_pin, pin_problem


def _config_path(given: Path | None) -> Path:
    if given is not None:
        return given
    if os.environ.get("KIOSK_CONFIG"):
        return Path(os.environ["KIOSK_CONFIG"])
    return default_config_path()


def _read_pin() -> str | None:
    """The new PIN, or None when the two entries differ."""
    if not sys.stdin.isatty():
        return sys.stdin.readline().strip()
    first = getpass.getpass(f"New clinician PIN ({MIN_DIGITS} to {MAX_DIGITS} digits): ")
    again = getpass.getpass("The same PIN again: ")
    return first if first == again else None


def main(argv: list[str]) -> int:
    """Set the PIN; exit 0, or 2 with one line when the PIN or the file is refused."""
    parser = argparse.ArgumentParser(prog="kiosk pin", description="Set the clinician PIN (stored hashed).")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    setter = commands.add_parser(
        "set",
        help="choose a new clinician PIN",
        description="Ask for a new PIN and store its hash in the configuration.",
    )
    setter.add_argument("--config", type=Path, help="configuration file (default: $KIOSK_CONFIG or the user's)")
    args = parser.parse_args(argv)
    path = _config_path(args.config)
    pin = _read_pin()
    if pin is None:
        print("kiosk pin set: the two PINs differ; nothing changed", file=sys.stderr)
        return 2
    if (problem := pin_problem(pin)) is not None:
        print(f"kiosk pin set: {problem}; nothing changed", file=sys.stderr)
        return 2
    try:
        write_settings(path, {"clinician_pin": None, "clinician_pin_hash": hash_pin(pin)})
    except ConfigError as error:
        print(f"kiosk pin set: {error}; nothing changed", file=sys.stderr)
        return 2
    print(f"The clinician PIN is set (stored hashed in {path}).")
    return 0
