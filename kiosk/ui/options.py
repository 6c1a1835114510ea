"""The options of `kiosk run`, here rather than in :mod:`kiosk.commands.run` because `kiosk serve`
(:mod:`kiosk.ui.serve.server`) checks the ones it passes on to each browser's kiosk with them."""

from __future__ import annotations

import argparse
from pathlib import Path


def run_parser() -> argparse.ArgumentParser:
    """The options of `kiosk run` (`kiosk serve` checks what it passes on with it)."""
    parser = argparse.ArgumentParser(prog="kiosk run", description="Start the kiosk (a patient session).")
    parser.add_argument("--data-dir", type=Path, help="where sessions are stored (default: from the configuration)")
    parser.add_argument("--config", type=Path, help="configuration file (default: $KIOSK_CONFIG or the user's)")
    parser.add_argument("--patient", help="the patient's pseudonymous id (default: a new random one)")
    parser.add_argument("--no-voice", action="store_true", help="no spoken prompts and no voice answers")
    parser.add_argument("--no-remote", action="store_true", help="do not look for remote controls")
    return parser
