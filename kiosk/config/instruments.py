"""The instruments a configuration gives: the questionnaire or the battery, with the band set and
the languages the site offers patients."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from fileio.positions import parse_file
from kiosk.config.settings import (
    Config,
    ConfigError,
)
from kiosk.core.questionnaire import Questionnaire, load_questionnaire
from kiosk.core.questionnaire.kept import load_questionnaire_kept
from kiosk.core.questionnaire.loading import bundled_path
from kiosk.core.visits import TUG


def configured_instruments(config: Config) -> list[tuple[Questionnaire, str | None]]:
    """The battery this kiosk gives, in order: each instrument with its own QoS model (None: the
    kiosk's). ``questionnaire:`` (or nothing) is a battery of one. A ``bands`` set applies to the
    instruments that have it (ConfigError if none has). Raises QuestionnaireError or ConfigError."""
    if not config.instruments:
        return [(configured_questionnaire(config), None)]
    found: list[tuple[Questionnaire, str | None]] = []
    where = f"{config.source}: " if config.source else ""
    for choice in config.instruments:
        if choice.name == TUG and choice.path is None:
            continue  # a step of the visit, not a questionnaire (configured_steps)
        questionnaire = load_questionnaire(choice.path or bundled_path(f"{choice.name}.yaml"))
        if questionnaire.id in (q.id for q, _ in found):
            raise ConfigError(f"{where}instruments: {questionnaire.id!r} is given twice; a visit gives it once")
        found.append((_configured(config, questionnaire, needs_bands=False), choice.qos_model))
    if config.bands is not None and not any(config.bands in q.band_sets for q, _ in found):
        raise ConfigError(f"{where}bands: {config.bands!r} is not a band set of any of the instruments")
    return found


def configured_steps(config: Config, instruments: list[tuple[Questionnaire, str | None]]) -> tuple[str, ...]:
    """The visit's steps in order: the ids of ``instruments`` (:func:`configured_instruments`),
    with the Timed Up and Go's id where ``instruments:`` names it."""
    ids = iter(q.id for q, _ in instruments)
    if not config.instruments:
        return tuple(ids)
    return tuple(TUG if c.name == TUG and c.path is None else next(ids) for c in config.instruments)


def configured_questionnaire(config: Config) -> Questionnaire:
    """The questionnaire this kiosk uses, scoring with the configured band set (with a battery,
    its first instrument).

    Raises :class:`~kiosk.core.questionnaire.QuestionnaireError` for a bad questionnaire file and
    :class:`ConfigError` when ``bands`` names a set the questionnaire does not have.
    """
    if config.instruments:
        return configured_instruments(config)[0][0]
    return _configured(config, load_questionnaire_kept(config.questionnaire))  # read back when it loaded before


def _configured(config: Config, questionnaire: Questionnaire, *, needs_bands: bool = True) -> Questionnaire:
    where = f"{config.source}: " if config.source else ""
    if config.language not in questionnaire.languages:
        raise ConfigError(
            f"{where}language: {config.language!r} is not a language of {questionnaire.source} "
            f"(it has {', '.join(questionnaire.languages)}); set language: to one of them"
        )
    if config.bands is None or (not needs_bands and config.bands not in questionnaire.band_sets):
        return questionnaire
    try:
        return questionnaire.with_band_set(config.bands)
    except KeyError:
        raise ConfigError(
            f"{where}bands: {config.bands!r} is not a band set of {questionnaire.source} "
            f"(it has {', '.join(questionnaire.band_sets)})"
        ) from None


def offered_to_patients(config: Config, questionnaire: Questionnaire) -> Questionnaire:
    """The questionnaire with only the languages this site offers patients: every language
    without a configuration file (as the kiosk always ran); with one, the validated translations
    and those ``accept_unvalidated_translations`` accepts.

    Raises :class:`ConfigError` (naming the file, line and column of ``language:``) when the
    kiosk's own language is not offered: an unvalidated translation is not used clinically
    until the site says it accepts it.
    """
    if config.source is None:
        return questionnaire
    accepted = config.accept_unvalidated_translations
    offered = tuple(
        language
        for language in questionnaire.languages
        if questionnaire.validated(language) or accepted is True or (accepted and language in accepted)
    )
    if config.language not in offered:
        entry = questionnaire.translations.get(config.language)
        what = f"its source: {entry.source}" if entry is not None else "the file names no source for it"
        raise ConfigError(
            f"{_setting_at(config.source, 'language')}language: {config.language!r} is an unvalidated "
            f"translation of {questionnaire.id} ({what}); add it to accept_unvalidated_translations "
            f"to accept it for clinical use, or set language: to one of {', '.join(offered) or 'none'}"
        )
    return replace(questionnaire, languages=offered)


def _setting_at(path: Path, key: str) -> str:
    """ "FILE:LINE:COL: " of ``key`` in a configuration file, "FILE: " when the file does not set it
    (the default or an environment override)."""
    data, positions, _ = parse_file(path)
    if positions is None or not isinstance(data, dict) or key not in data:
        return f"{path}: "
    line, column = positions.of((key,), key=True)
    return f"{path}:{line}:{column}: "
