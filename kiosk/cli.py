"""The `kiosk` command line: one sub-command per job, each owned by the module that does it.

The dispatcher only routes: every sub-command module exposes ``main(argv: list[str]) -> int`` and
parses its own arguments, so adding an option never touches this file. Modules are imported
lazily, so `kiosk validate` does not pay for Textual or the speech stack. Ctrl-C in any command is
one line ("kiosk replay: interrupted") and exit status 130; what each command stores is stored in
transactions, so an interruption leaves nothing half-written.
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Sequence

#: sub-command -> (module exposing main(argv), one-line description)
COMMANDS: dict[str, tuple[str, str]] = {
    "run": ("kiosk.commands.run", "start the kiosk (the default when no sub-command is given)"),
    "serve": ("kiosk.ui.serve.server", "serve the kiosk to a browser on a touch display (localhost by default)"),
    "replay": ("kiosk.commands.replay", "run a scripted patient through the real session on a simulated clock"),
    "validate": ("kiosk.commands.validate", "check questionnaire files and the words files; list every problem"),
    "results": ("kiosk.commands.results", "list stored sessions, show one, or export it (FHIR JSON, CSV)"),
    "devices": ("kiosk.commands.devices", "list remotes (HID, serial) and audio inputs, and what the kiosk would use"),
    "pin": ("kiosk.commands.pin", "set the clinician PIN (`kiosk pin set`; stored hashed in the configuration)"),
    "models": ("kiosk.speech.models", "install and list speech-recognition models"),
    "tug": ("kiosk.commands.tug", "Timed Up and Go from pose-landmarks files: analyse them, generate test ones"),
    "qos": ("kiosk.commands.qos", "QoS tools: replay a context trace, print a session's trace"),
    "station": ("station.cli", "the ward station web app (kiosks report to it; staff watch and validate)"),
}


#: the exit status of a command stopped by Ctrl-C (128 + SIGINT, as shells report it)
INTERRUPTED = 130


def _usage() -> str:
    width = max(len(name) for name in COMMANDS)
    lines = ["usage: kiosk [COMMAND] [ARGS...]", "", "commands:"]
    lines += [f"  {name:<{width}}  {text}" for name, (_, text) in COMMANDS.items()]
    lines += ["", "`kiosk COMMAND --help` describes a command's options."]
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the `kiosk` console script; returns the process exit status."""
    args = list(sys.argv[1:] if argv is None else argv)
    if args and args[0] in ("-h", "--help", "help"):
        print(_usage())
        return 0
    name = "run" if not args or args[0].startswith("-") else args.pop(0)
    if name not in COMMANDS:
        print(f"kiosk: unknown command {name!r}\n\n{_usage()}", file=sys.stderr)
        return 2
    try:
        module = importlib.import_module(COMMANDS[name][0])
        from qos.cli import run_command

        return run_command(lambda: int(module.main(args) or 0))
    except KeyboardInterrupt:  # Ctrl-C: the user's choice, not a failure to explain with a traceback
        print(f"kiosk {name}: interrupted", file=sys.stderr)
        return INTERRUPTED


if __name__ == "__main__":  # pragma: no cover - `python -m kiosk.cli`
    sys.exit(main())
