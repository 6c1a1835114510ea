"""`kiosk serve`: serve the kiosk to a browser on a touch display with textual-serve.

A touchscreen kiosk runs Chromium in kiosk mode on the same machine and opens
``http://127.0.0.1:8000/?fontsize=28``; every browser connection starts its own ``kiosk run``
process, so a closed tab never leaves a half-run session behind (the session core resumes it).

The server binds to localhost unless asked otherwise: patient data must not be reachable from the
network by default.
"""

from __future__ import annotations

import argparse
import shlex
import sys
from pathlib import Path

#: the address a kiosk's own browser uses; anything else exposes the kiosk to the network
LOCALHOST = "127.0.0.1"
#: the folder of the page the browser loads (``app_index.html``)
PAGE_DIR = Path(__file__).parent / "web"


def build_command(run_args: list[str]) -> str:
    """The shell command textual-serve starts for each browser connection: ``kiosk run ARGS``."""
    return shlex.join([sys.executable, "-m", "kiosk", "run", *run_args])


def run_args_problem(run_args: list[str]) -> str | None:
    """What is wrong with the options passed on to `kiosk run`, or None: checked before serving,
    because every browser connection would otherwise only show `kiosk run`'s usage error."""
    from kiosk.app import run_parser

    parser = run_parser()
    parser.exit_on_error = False  # report the problem as one line here, not argparse's usage text
    try:
        _, unknown = parser.parse_known_args(run_args)
    except argparse.ArgumentError as error:
        return str(error)
    if unknown:
        return f"unrecognised arguments: {' '.join(unknown)} (neither `kiosk serve` nor `kiosk run` takes them)"
    return None


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="kiosk serve",
        description="Serve the kiosk to a browser (a touch display running Chromium). "
        "Options not listed here are passed to `kiosk run` (for example --data-dir).",
    )
    parser.add_argument("--host", default=LOCALHOST,
                        help="address to listen on (default %(default)s: this machine only)")
    parser.add_argument("--port", type=int, default=8000, help="TCP port (default %(default)s)")
    return parser


def main(argv: list[str]) -> int:
    """Run the web server until interrupted; returns the process exit status."""
    args, run_args = _parser().parse_known_args(argv)
    if not 0 < args.port < 65536:
        print(f"kiosk serve: --port must be between 1 and 65535, got {args.port}", file=sys.stderr)
        return 2
    if (problem := run_args_problem(run_args)) is not None:
        print(f"kiosk serve: {problem}", file=sys.stderr)
        return 2
    if args.host not in (LOCALHOST, "localhost", "::1"):
        print(f"kiosk serve: warning: listening on {args.host}, so other machines can reach the "
              "kiosk and its patient data", file=sys.stderr)

    from textual_serve.server import Server

    # the kiosk's own page (offline font, large text that fits the display), textual-serve's statics
    server = Server(build_command(run_args), host=args.host, port=args.port, title="Barthel kiosk",
                    templates_path=PAGE_DIR)
    try:
        server.serve()
    except OSError as error:  # port in use, address not on this machine
        print(f"kiosk serve: cannot listen on {args.host}:{args.port}: {error.strerror or error}",
              file=sys.stderr)
        return 1
    return 0
