"""Configuration: defaults, file, environment overrides, and one clear message for a bad file."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from kiosk.config import DEFAULT_PIN, Config, ConfigError, configured_questionnaire, load_config, offered_to_patients
from kiosk.core.clock import SimClock, SystemClock
from kiosk.core.visits import DEFAULT_ID_PATTERN
from tests.kiosk.configs import refusal


def test_defaults_without_a_file(tmp_path, monkeypatch):
    monkeypatch.setattr("kiosk.config.default_config_path", lambda: tmp_path / "none.yaml")
    config = load_config(environ={})
    assert config.source is None and config.language == "en" and config.adaptation and config.familiarisation
    assert config.clinician_pin == DEFAULT_PIN and config.default_pin


def test_file_and_environment(tmp_path):
    path = tmp_path / "config.yaml"
    path.write_text(
        'data_dir: data\nlanguage: es\nclinician_pin: "042042"\nadaptation: false\n'
        "timing: {attempt_window_s: 45}\nvosk_model: /opt/vosk\n"
    )
    config = load_config(environ={"KIOSK_CONFIG": str(path)})
    assert config.data_dir == tmp_path / "data"  # relative to the config file
    assert (config.language, config.clinician_pin, config.adaptation) == ("es", "042042", False)
    assert config.timing == {"attempt_window_s": 45} and config.vosk_model == Path("/opt/vosk")
    assert not config.default_pin
    env = {
        "KIOSK_CONFIG": str(path),
        "KIOSK_DATA_DIR": str(tmp_path / "elsewhere"),
        "KIOSK_VOSK_MODEL": "/m",
        "KIOSK_LANGUAGE": "fr",
    }
    config = load_config(environ=env)
    assert (config.data_dir, config.vosk_model, config.language) == (tmp_path / "elsewhere", Path("/m"), "fr")


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("colour: red\n", ":1:1: unknown setting 'colour'"),
        ("language: en\nclinician_pin: 1234\n", ':2:1: write the PIN in quotes ("012345")'),
        ('clinician_pin: "12"\n', ":1:1: clinician_pin must be 6 to 12 digits"),
        ("adaptation: maybe\n", ":1:1: adaptation must be true or false"),
        ("timing: {attempt_window_s: -3}\n", ":1:1: timing setting 'attempt_window_s' must be a number"),
        ("timing: {window: 3}\n", ":1:1: unknown timing setting 'window'"),
        ("data_dir: [1]\n", ":1:1: data_dir must be a path"),
        ("language: en\nlanguage: es\n", ":2:1: duplicate key 'language'"),
        ("language: [\n", ":2:1: YAML syntax"),
        ("language: en\npatient_id_pattern: '[A-Za-z0-9]+'\n", ":2:1: patient_id_pattern accepts the name"),
        ("patient_id_pattern: 'NHC-[0-9'\n", ":1:1: patient_id_pattern is not a regular expression"),
        ("patient_id_pattern: 7\n", ":1:1: patient_id_pattern must be a regular expression"),
    ],
)
def test_a_bad_config_is_one_message_naming_file_line_and_column(tmp_path, text, message):
    path = tmp_path / "config.yaml"
    assert refusal(path, text).startswith(f"{path}{message}")


def test_bad_environment(tmp_path, monkeypatch):
    monkeypatch.setattr("kiosk.config.default_config_path", lambda: tmp_path / "none.yaml")
    with pytest.raises(ConfigError, match="KIOSK_CONFIG names .* which is not a file"):
        load_config(environ={"KIOSK_CONFIG": str(tmp_path / "missing.yaml")})
    with pytest.raises(ConfigError, match="language 'pt' is not one of de, en, es, fr"):
        load_config(environ={"KIOSK_CONFIG": "", "KIOSK_LANGUAGE": "pt"})
    with pytest.raises(ConfigError, match="^KIOSK_DATA_DIR '~nosuchuser/x': there is no user 'nosuchuser'"):
        load_config(environ={"KIOSK_DATA_DIR": "~nosuchuser/x"})
    with pytest.raises(ConfigError, match="^" + re.escape("KIOSK_DATA_DIR '/tmp/a\\nb' holds a control character")):
        load_config(environ={"KIOSK_DATA_DIR": "/tmp/a\nb"})
    station = {"KIOSK_STATION_URL": "http://127.0.0.1:8443", "KIOSK_STATION_TOKEN": "abc"}
    with pytest.raises(ConfigError, match="^KIOSK_STATION_URL: the token is not one the station issues"):
        load_config(environ={**station, "KIOSK_STATION_TOKEN": "ab\ncd"})
    with pytest.raises(ConfigError, match="^KIOSK_STATION_URL: url 'http://127.0.0.1:65536' needs a host"):
        load_config(environ={**station, "KIOSK_STATION_URL": "http://127.0.0.1:65536"})


def test_clocks():
    clock = SimClock(5)
    clock.advance(2.5)
    assert clock.now() == 7.5 and clock.wall().isoformat() == "2026-01-01T00:00:07.500000+00:00"
    with pytest.raises(ValueError, match="back in time"):
        clock.set(7)
    with pytest.raises(ValueError, match="back in time"):
        clock.advance(-1)
    system = SystemClock()
    assert system.now() <= system.now() and system.wall().tzinfo is not None


def test_the_band_set_is_chosen_by_config_and_an_unknown_one_is_named(tmp_path):
    from kiosk.config import configured_questionnaire

    path = tmp_path / "config.yaml"
    path.write_text("bands: spanish\n")
    config = load_config(path, environ={})
    assert config.bands == "spanish"
    questionnaire = configured_questionnaire(config)
    assert questionnaire.band_set == "spanish" and questionnaire.band_for(60).id == "mild"
    assert configured_questionnaire(Config()).band_set == "shah"  # no choice: the file's default
    path.write_text("bands: castilian\n")
    with pytest.raises(ConfigError) as caught:
        configured_questionnaire(load_config(path, environ={}))
    assert str(caught.value).startswith(f"{path}: bands: 'castilian' is not a band set of ")
    assert str(caught.value).endswith("(it has shah, spanish)")
    path.write_text("bands: [spanish]\n")
    with pytest.raises(ConfigError, match=":1:1: bands must name a band set of the questionnaire"):
        load_config(path, environ={})


def test_the_station_settings_and_their_environment_overrides(tmp_path, monkeypatch):
    monkeypatch.setattr("kiosk.config.default_config_path", lambda: tmp_path / "none.yaml")
    assert load_config(environ={}).station is None  # no station: the kiosk works alone
    path = tmp_path / "config.yaml"
    path.write_text(
        "station: {url: 'https://ward.example:8443/', token: abc, kiosk_id: ward3-bed2}\ninterrupt_after_minutes: 45\n"
    )
    config = load_config(path, environ={})
    assert config.station is not None
    assert (config.station.url, config.station.token, config.station.kiosk_id) == (
        "https://ward.example:8443",
        "abc",
        "ward3-bed2",
    )
    assert config.interrupt_after_minutes == 45
    assert (config.away_alert_after_s, config.unattended_after) == (60.0, 2)  # the defaults
    env = {"KIOSK_STATION_URL": "http://127.0.0.1:9000", "KIOSK_STATION_TOKEN": "xyz"}
    config = load_config(path, environ=env)
    assert (config.station.url, config.station.token, config.station.kiosk_id) == (
        "http://127.0.0.1:9000",
        "xyz",
        "ward3-bed2",
    )
    only_env = load_config(environ=env).station
    assert only_env is not None and only_env.kiosk_id  # the host name by default


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("station: {url: 'ftp://x', token: a}\n", ":1:16: station: url 'ftp://x' must be an http:// or https://"),
        ("station: {url: 'http://x:1'}\n", ":1:16: station: a token is needed with the url"),
        ("station: {url: 'http://x:1', token: a, kiosk_id: 'bed 2'}\n", ":1:50: station: kiosk_id 'bed 2' must be"),
        ("station: {url: 'http://x:1', tokn: a}\n", ":1:1: station must be a mapping"),
        ("interrupt_after_minutes: 0\n", ":1:1: interrupt_after_minutes must be a number of minutes"),
        ("away_alert_after_s: 5\n", ":1:1: away_alert_after_s must be a number of seconds, 10 to 3600"),
        ("away_alert_after_s: soon\n", ":1:1: away_alert_after_s must be a number of seconds"),
        ("unattended_after: 0\n", ":1:1: unattended_after must be a whole number of questions, 1 to 10"),
        ("unattended_after: 2.5\n", ":1:1: unattended_after must be a whole number"),
        # ports out of range, no host, control characters in the url, the token or an id (real
        # processes: tests/kiosk/test_hostile_config.py)
        ("station: {url: 'http://127.0.0.1:99999', token: a}\n", ":1:16: station: url 'http://127.0.0.1:99999' needs"),
        ("station: {url: 'http://127.0.0.1:0', token: a}\n", ":1:16: station: url 'http://127.0.0.1:0' needs a host"),
        ("station: {url: 'http://127.0.0.1:-1', token: a}\n", ":1:16: station: url 'http://127.0.0.1:-1' needs"),
        ("station: {url: 'https://:8443', token: a}\n", ":1:16: station: url 'https://:8443' needs a host"),
        ("station: {url: 'http://x:8443x', token: a}\n", ":1:16: station: url 'http://x:8443x' needs a host"),
        (
            'station: {url: "http://x:1\\r\\nX-Evil: 1", token: a}\n',
            ":1:16: station: url 'http://x:1\\r\\nX-Evil: 1' must",
        ),
        ('station: {url: "http://x:1\\n", token: a}\n', ":1:16: station: url 'http://x:1\\n' must be an http://"),
        ('station: {url: "http://wärd:1", token: a}\n', ":1:16: station: url 'http://wärd:1' must be an http://"),
        ('station:\n  url: "http://x:1"\n  token: "ab\\ncd"\n', ":3:10: station: the token is not one the station"),
        ('station: {url: "http://x:1", token: "ab cd"}\n', ":1:37: station: the token is not one the station issues"),
        ('station: {url: "http://x:1", token: "ab\\u0085"}\n', ":1:37: station: the token is not one the station"),
        ('station: {url: "http://x:1", token: a, kiosk_id: "bed2\\n"}\n', ":1:50: station: kiosk_id 'bed2\\n' must be"),
        ('kiosk_id: "ward3\\n"\n', ":1:1: kiosk_id must be 1-64 letters"),
        ('site: "north\\n"\n', ":1:1: site must be 1-64 letters"),
        ('fhir: {patient_system: "https://h.example/p\\n"}\n', ":1:8: fhir patient_system must be an absolute URI"),
        ("data_dir: ~nosuchuser/x\n", ":1:1: data_dir '~nosuchuser/x': there is no user 'nosuchuser' to expand"),
        ("questionnaire: ~nosuchuser\n", ":1:1: questionnaire '~nosuchuser': there is no user 'nosuchuser'"),
        ('vosk_model: "/opt/vosk\\nmodel"\n', ":1:1: vosk_model '/opt/vosk\\nmodel' holds a control character"),
        ('data_dir: "/tmp/a\\0b"\n', ":1:11: the text holds U+0000, a control character"),
        ('language: "\\ud800"\n', ":1:11: the text holds U+D800, a lone surrogate"),
    ],
)
def test_bad_station_settings_say_where(tmp_path, text, message):
    path = tmp_path / "config.yaml"
    assert refusal(path, text).startswith(f"{path}{message}")


# --- accept_unvalidated_translations: which translations a site uses clinically -------------------


def _site(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "site.yaml"
    path.write_text("data_dir: data\n" + text)
    return path


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("accept_unvalidated_translations: de\n", ":2:1: accept_unvalidated_translations must be true or a list"),
        (
            "accept_unvalidated_translations: [de, xx]\n",
            ":2:1: accept_unvalidated_translations: 'xx' is not a language",
        ),
        ("accept_unvalidated_translations: [1]\n", ":2:1: accept_unvalidated_translations must be true or a list"),
    ],
)
def test_a_bad_accept_unvalidated_translations_says_where(tmp_path, text, message):
    path = _site(tmp_path, text)
    assert refusal(path).startswith(f"{path}{message}")


@pytest.mark.parametrize(
    ("text", "offered"),
    [
        ("", ("en",)),  # a site accepts no unvalidated translation unless it says so
        ("accept_unvalidated_translations: [de]\n", ("en", "de")),
        ("accept_unvalidated_translations: [fr, de, fr]\n", ("en", "fr", "de")),
        ("accept_unvalidated_translations: true\n", ("en", "es", "fr", "de")),
        ("accept_unvalidated_translations: false\n", ("en",)),
    ],
)
def test_a_site_offers_validated_and_accepted_translations_only(tmp_path, text, offered):
    config = load_config(_site(tmp_path, text), environ={})
    barthel = configured_questionnaire(config)
    assert barthel.languages == ("en", "es", "fr", "de")  # the file still has them all
    assert offered_to_patients(config, barthel).languages == offered


def test_without_a_config_file_every_language_is_offered_as_before(tmp_path, monkeypatch):
    monkeypatch.setattr("kiosk.config.default_config_path", lambda: tmp_path / "none.yaml")
    config = load_config(environ={"KIOSK_LANGUAGE": "de"})
    barthel = configured_questionnaire(config)
    assert offered_to_patients(config, barthel).languages == ("en", "es", "fr", "de")


def test_a_site_language_that_is_unvalidated_and_not_accepted_is_refused_where_it_is_set(tmp_path):
    path = _site(tmp_path, "language: de\naccept_unvalidated_translations: [es]\n")
    config = load_config(path, environ={})
    with pytest.raises(ConfigError) as caught:
        offered_to_patients(config, configured_questionnaire(config))
    message = str(caught.value)
    assert message.startswith(f"{path}:2:1: language: 'de' is an unvalidated translation of barthel (its source: ")
    assert "add it to accept_unvalidated_translations" in message and "\n" not in message
    # set by the environment instead: the file is named, without a line it does not have
    config = load_config(_site(tmp_path, ""), environ={"KIOSK_LANGUAGE": "fr"})
    with pytest.raises(ConfigError, match=rf"^{re.escape(str(tmp_path / 'site.yaml'))}: language: 'fr'"):
        offered_to_patients(config, configured_questionnaire(config))


def test_kiosk_run_refuses_an_unaccepted_translation_in_one_line_and_runs_an_accepted_one(tmp_path, capsys):
    from kiosk.commands import run as kiosk_app

    path = _site(tmp_path, "language: de\n")
    assert kiosk_app.main(["--config", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"kiosk run: {path}:2:1: language: 'de' is an unvalidated translation")
    path.write_text("data_dir: data\nlanguage: de\naccept_unvalidated_translations: [de]\n")
    app, close = kiosk_app.build_app(config_path=path, voice=False, remote=False)
    try:
        assert app.session.language == "de" and app.session.questionnaire.languages == ("en", "de")
    finally:
        close()


def test_a_configuration_with_a_station_token_is_never_kept_parsed_in_the_cache(tmp_path, monkeypatch):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    parsed = tmp_path / "cache" / "kiosk" / "parsed-yaml"
    plain = tmp_path / "plain.yaml"
    plain.write_text(f"data_dir: {tmp_path / 'data'}\n", encoding="utf-8")
    load_config(plain)
    assert len(list(parsed.glob("*.pickle"))) == 1  # a configuration without a secret is kept
    secret = tmp_path / "secret.yaml"
    secret.write_text(
        f"data_dir: {tmp_path / 'data'}\nstation:\n  url: http://127.0.0.1:9/\n  token: Zm9vYmFyYmF6cXV4\n",
        encoding="utf-8",
    )
    secret.chmod(0o600)
    assert load_config(secret).station is not None
    assert len(list(parsed.glob("*.pickle"))) == 1
    assert not any(b"Zm9vYmFyYmF6cXV4" in p.read_bytes() for p in parsed.glob("*.pickle"))


def test_a_sites_identifier_pattern_is_read_and_the_default_refuses_names(tmp_path):
    path = tmp_path / "config.yaml"
    path.write_text("patient_id_pattern: 'NHC-[0-9]{7}'\n")
    assert load_config(path, environ={}).patient_id_pattern == "NHC-[0-9]{7}"
    assert load_config(environ={}).patient_id_pattern == DEFAULT_ID_PATTERN
