"""Reading a configuration file: every setting checked by its row of
:data:`kiosk.config.checks.SETTINGS`, a mistake named by file, line and column."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from fileio.positions import Positions, Problem, parse_file
from kiosk.config.checks import SETTINGS, Context, Invalid, load_site
from kiosk.config.settings import ConfigError


def _no_secret(data: Any) -> bool:
    """Whether a configuration may be kept parsed in the user cache (:func:`fileio.positions.parse`):
    not with a station's bearer token or the served page's key digest in it."""
    return not (isinstance(data, dict) and {"station", "serve_token_sha256"} & set(data))


def read_file(path: Path) -> dict[str, Any]:
    """The settings ``path`` gives, each checked (paths made absolute, battery resolved): the
    values :class:`~kiosk.config.settings.Config` takes. Raises ConfigError naming the place."""
    data, positions, problems = parse_file(path, keep=_no_secret)
    if problems and problems[0].message == "the file is empty":
        return {}  # a config file with every setting commented out means the defaults
    if problems:
        raise ConfigError(str(problems[0]))
    if data is None:
        return {}
    assert positions is not None
    if not isinstance(data, dict):
        raise _placed(path, positions, (), "the configuration is a mapping of settings (key: value)")
    context = Context(data, path.parent)
    values: dict[str, Any] = {}
    if "site_dir" in data:  # the site's folder first: its languages, instruments and models are in use from here on
        values["site_dir"] = _checked(path, positions, "site_dir", data["site_dir"], context)
        context = Context(data, path.parent, load_site(values["site_dir"]))
    values.update(
        (key, _checked(path, positions, key, value, context)) for key, value in data.items() if key != "site_dir"
    )
    site = context.site
    if site is not None and "barthel" in site.instruments and not {"questionnaire", "instruments"} & set(values):
        values["questionnaire"] = site.instruments["barthel"]  # the default instrument, as the site replaced it
    return values


def _checked(path: Path, positions: Positions, key: Any, value: Any, context: Context) -> Any:
    """One setting's value, checked by its row of the table."""
    check = SETTINGS.get(key)
    if check is None:
        raise _placed(path, positions, (key,), f"unknown setting {key!r} (known: {', '.join(sorted(SETTINGS))})")
    try:
        return check(value, context)
    except Invalid as bad:
        raise _placed(path, positions, (key, *bad.where), bad.message, key=bad.key) from None


def _placed(path: Path, positions: Positions, where: tuple[Any, ...], message: str, key: bool = True) -> ConfigError:
    """The error at ``where`` in the file: its key's position (``key``), else its value's."""
    line, col = positions.of(where, key=key)
    return ConfigError(str(Problem(str(path), line, col, message)))
