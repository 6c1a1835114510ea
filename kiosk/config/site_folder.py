"""A site's own folder (``site_dir:`` in the configuration): its instruments, words files (new
languages) and QoS models, kept outside the installed package so that an upgrade never deletes
them. The folder is checked whole when the configuration is read (and by `kiosk validate --site`),
every problem one ``file:line:col`` line, so a kiosk never starts on half of it.

- ``instruments/*.yaml``: instrument files, checked as `kiosk validate FILE` checks them; a bare id
  in ``instruments:`` names the site's instrument of that id before a shipped one. A site file may
  not take a shipped instrument's id (``id: barthel``) unless it says ``replaces: barthel``: a
  result must never silently come from other content than the shipped Barthel.
- ``words/<code>.yaml``: the site's languages, checked against the shipped ``en.yaml``.
- ``qos/*.roqme``: RoQME models, which may ``import "clarc.roqme"`` (the shipped models' folder is
  searched after the model's own); ``qos_model: NAME`` finds ``qos/NAME.roqme``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import field
from pathlib import Path

from basis import record
from fileio.positions import Problem, parse_file
from kiosk.core.questionnaire import check_questionnaire
from kiosk.core.questionnaire.loading import bundled_path

INSTRUMENTS, WORDS, QOS = "instruments", "words", "qos"


@record
class SiteFolder:
    """What a checked site folder holds."""

    path: Path
    #: the site's instruments: id -> file
    instruments: Mapping[str, Path] = field(default_factory=dict)
    #: the site's languages: code -> words file
    languages: Mapping[str, Path] = field(default_factory=dict)
    #: the site's QoS models: name -> file
    models: Mapping[str, Path] = field(default_factory=dict)


def shipped_instruments() -> tuple[str, ...]:
    """The ids of the instruments shipped in the package."""
    return tuple(sorted(path.stem for path in bundled_path().parent.glob("*.yaml")))


def check_site_folder(path: Path) -> tuple[SiteFolder, list[Problem], bool]:
    """(the folder's contents, every problem, whether every file could be read as YAML). The site's
    good words files are put in use (:func:`kiosk.core.words.use_site_words`) before its
    instruments are checked, which may be in those languages."""
    from kiosk.core.words import use_site_words

    languages, found, words_readable = _words(path / WORDS)
    use_site_words(path / WORDS if languages else None)
    instruments, problems, readable = _instruments(path / INSTRUMENTS)
    models, model_problems = _models(path / QOS)
    folder = SiteFolder(path, instruments, languages, models)
    return folder, [*found, *problems, *model_problems], readable and words_readable


def _instruments(folder: Path) -> tuple[dict[str, Path], list[Problem], bool]:
    shipped = shipped_instruments()
    found: dict[str, Path] = {}
    problems: list[Problem] = []
    readable = True
    for file in sorted(folder.glob("*.yaml")) if folder.is_dir() else ():
        ok, checked = check_questionnaire(file)
        readable = readable and ok
        problems += checked
        if checked:
            continue
        data, positions, _ = parse_file(file)
        assert positions is not None and isinstance(data, dict)  # it passed the checks above

        ident, replaces = data["id"], data.get("replaces")
        refused = _shadowing(ident, replaces, shipped, found)
        if refused is None:
            found[ident] = file
        else:
            line, column = positions.of((refused[0],))
            problems.append(Problem(str(file), line, column, refused[1]))
    return found, problems, readable


def _shadowing(
    ident: str, replaces: str | None, shipped: tuple[str, ...], found: dict[str, Path]
) -> tuple[str, str] | None:
    """(the key at fault, why) when a site file may not have its id, else None."""
    if replaces is not None and replaces != ident:
        return "replaces", f"replaces: {replaces!r} must be this file's own id ({ident!r})"
    if replaces is not None and ident not in shipped:
        return "replaces", f"replaces: no shipped instrument {ident!r} (shipped: {', '.join(shipped)})"
    if ident in shipped and replaces is None:
        return "id", (
            f"id {ident!r} is a shipped instrument's: give this file its own id, or add "
            f"`replaces: {ident}` to use it instead of the shipped {ident} on this site"
        )
    if ident in found:
        return "id", f"id {ident!r} is also the id of {found[ident]}: a site's instruments have one id each"
    return None


def _words(folder: Path) -> tuple[dict[str, Path], list[Problem], bool]:
    from kiosk.core.words import check_site_words

    if not folder.is_dir():
        return {}, [], True
    return check_site_words(folder)


def _models(folder: Path) -> tuple[dict[str, Path], list[Problem]]:
    from kiosk.core.qos_model import load_kiosk_model
    from qos import ModelError

    found: dict[str, Path] = {}
    problems: list[Problem] = []
    for file in sorted(folder.glob("*.roqme")) if folder.is_dir() else ():
        try:
            load_kiosk_model(file)
        except ModelError as exc:
            problems.append(_model_problem(str(exc), file))
        else:
            found[file.stem] = file
    return found, problems


def _model_problem(message: str, file: Path) -> Problem:
    """A model's error as a Problem naming the file by its whole path (the parser names it by its base name)."""
    name, _, rest = message.partition(":")
    parts = rest.split(":", 2)
    if name in (file.name, str(file)) and len(parts) == 3 and parts[0].isdigit() and parts[1].isdigit():
        return Problem(str(file), int(parts[0]), int(parts[1]), parts[2].strip())
    if name == str(file) or name == file.name:
        return Problem(str(file), 1, 1, rest.strip())
    return Problem(str(file), 1, 1, message)
