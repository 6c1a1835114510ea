"""`kiosk validate [FILE...] [--words [DIR]] [--site DIR]`: list every problem of questionnaire files,
of the kiosk's words files and of a site's folder, one per line as ``file:line:col: problem``.

Exit status 0 when everything is valid, 1 when anything has a problem, 2 when a file cannot be read
as YAML at all (missing, not UTF-8, binary, too big or deep, a syntax error) or on bad usage. The
same checks run when the kiosk loads a questionnaire and its words, so what this command accepts
the kiosk starts with. Questionnaires are checked with the kiosk's own words files; ``--words DIR``
checks another directory of them (a translation in progress) and lists its languages.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from kiosk.core.questionnaire import check_questionnaire
from kiosk.core.words import WORDS_DIR, check_words


def main(argv: list[str]) -> int:
    """Validate questionnaire files and words files; returns the exit status."""
    parser = argparse.ArgumentParser(
        prog="kiosk validate",
        description="List every problem of questionnaire files and of the words files (one per language), "
        "one per line as file:line:col: problem; exit 1 if any, 2 if a file cannot be read as YAML.",
    )
    parser.add_argument("files", nargs="*", metavar="FILE", help="questionnaire YAML file(s)")
    parser.add_argument(
        "--words",
        nargs="?",
        const=str(WORDS_DIR),
        metavar="DIR",
        help=f"a directory of words files, <language>.yaml (default: the kiosk's own, {WORDS_DIR}); "
        "its languages are listed",
    )
    parser.add_argument(
        "--site",
        metavar="DIR",
        help="a site's folder (site_dir: in the configuration): its instruments/, words/ and qos/, "
        "checked as `kiosk run` checks them at start",
    )
    parser.add_argument(
        "--config",
        metavar="FILE",
        help="a configuration file: its settings, its site's folder, its instruments and QoS models, "
        "as `kiosk run` checks them at start (exit 2 on a problem, as every command)",
    )
    args = parser.parse_args(argv)
    if not args.files and args.words is None and args.site is None and args.config is None:
        parser.error("give questionnaire FILEs, --words [DIR], --site DIR, --config FILE, or several")
    if args.config is not None and (status := _config(Path(args.config))):
        return status
    status = _words(Path(args.words or WORDS_DIR), listed=args.words is not None)
    if args.site is not None:
        status = max(status, _site(Path(args.site)))
    for file in args.files:
        readable, problems = check_questionnaire(file)
        for problem in problems:
            print(problem)
        if not readable:
            status = 2
        elif problems:
            status = max(status, 1)
        else:
            print(f"{file}: ok", file=sys.stderr)
    return status


def _words(directory: Path, listed: bool) -> int:
    """Check a directory of words files; print its problems, and its languages when ``listed``."""
    if not directory.is_dir():
        print(f"{directory}: not a directory of words files")
        return 2
    words, problems, readable = check_words(directory)
    for problem in problems:
        print(problem)
    if listed and not problems:
        print(f"{directory}: ok, languages {', '.join(words)}", file=sys.stderr)
    return 2 if not readable else 1 if problems else 0


def _site(directory: Path) -> int:
    """Check a site's folder; print its problems, or what it holds."""
    from kiosk.config.site_folder import check_site_folder

    if not directory.is_dir():
        print(f"{directory}: not a folder (a site's folder holds instruments/, words/ and qos/)")
        return 2
    site, problems, readable = check_site_folder(directory)
    for problem in problems:
        print(problem)
    if not problems:
        held = {"instruments": site.instruments, "languages": site.languages, "QoS models": site.models}
        print(
            f"{directory}: ok, " + "; ".join(f"{what} {', '.join(names) or 'none'}" for what, names in held.items()),
            file=sys.stderr,
        )
    return 2 if not readable else 1 if problems else 0


def _config(path: Path) -> int:
    """Check a configuration as `kiosk run` does at start (its instruments and models loaded)."""
    from kiosk.config import ConfigError, configured_instruments, load_config
    from kiosk.core.qos_model import load_kiosk_model
    from kiosk.core.questionnaire import QuestionnaireError
    from qos import ModelError

    try:
        config = load_config(path, environ={})
        instruments = configured_instruments(config)
        for model in {config.qos_model, *(name for _, name in instruments if name is not None)}:
            load_kiosk_model(model)
    except QuestionnaireError as error:
        print("\n".join(map(str, error.problems)) or str(error))
        return 2
    except (ConfigError, ModelError) as error:
        print(error)
        return 2
    print(f"{path}: ok, instruments {', '.join(q.id for q, _ in instruments)}", file=sys.stderr)
    return 0
