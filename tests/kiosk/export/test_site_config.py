"""Site settings of the exports in the kiosk's config, and pseudonyms that do not clash."""

from __future__ import annotations

import re

import pytest

from kiosk.config import ConfigError, load_config
from kiosk.export import ExportSite, site_from_config
from kiosk.store.database import PATIENT_ID, new_patient_id


def config(tmp_path, text: str):
    path = tmp_path / "config.yaml"
    path.write_text(text, encoding="utf-8")
    return load_config(path, environ={})


def test_a_site_sets_its_identity_and_the_rest_keeps_documented_defaults(tmp_path):
    site = site_from_config(
        config(
            tmp_path,
            "site: hosp-north\nkiosk_id: ward3-bed2\n"
            "fhir: {patient_system: 'https://hosp-north.example/sid/kiosk-patient'}\n",
        )
    )
    assert site == ExportSite(
        site="hosp-north",
        kiosk_id="ward3-bed2",
        patient_system="https://hosp-north.example/sid/kiosk-patient",
        identifier_system="urn:barthel-kiosk:result",
        device_system="urn:barthel-kiosk:hosp-north:kiosk",
    )
    assert site.result_id("0a1b2c3d4e5f") == "hosp-north/ward3-bed2/0a1b2c3d4e5f"


def test_without_config_the_kiosk_id_is_the_host_name_fit_for_an_identifier(tmp_path):
    site = site_from_config(load_config(None, environ={"KIOSK_CONFIG": ""}))
    assert site.site == "local" and re.fullmatch(r"[A-Za-z0-9][A-Za-z0-9._-]{0,63}", site.kiosk_id)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("site: hosp north\n", "1:1: site must be 1-64 letters, digits"),
        ("kiosk_id: ward3/bed2\n", "1:1: kiosk_id must be 1-64 letters"),
        ("fhir: {patient_sytem: 'urn:x:y'}\n", "unknown fhir setting 'patient_sytem'"),
        ("fhir:\n  questionnaire_url: barthel\n", "2:3: fhir questionnaire_url must be an absolute URI"),
        ("fhir: [urn:x]\n", "fhir must be a mapping"),
    ],
)
def test_bad_site_settings_are_one_clear_error_with_their_position(tmp_path, text, message):
    with pytest.raises(ConfigError, match=re.escape(message)):
        config(tmp_path, text)


def test_new_pseudonyms_have_60_random_bits_and_old_ones_stay_valid():
    ids = {new_patient_id() for _ in range(2000)}
    assert len(ids) == 2000
    assert all(re.fullmatch(r"P-([A-HJ-NP-Z2-9]{4}-){2}[A-HJ-NP-Z2-9]{4}", i) and PATIENT_ID.match(i) for i in ids)
    assert PATIENT_ID.match("P-7K3QX9")  # the older six-character form


def test_one_kiosk_id_serves_exports_and_the_station(tmp_path):
    station = "station: {url: 'https://ward.example:8443', token: t0k3n"
    both = config(tmp_path, f"kiosk_id: ward3-bed2\n{station}}}\n")
    assert both.kiosk_id == both.station.kiosk_id == "ward3-bed2"
    older = config(tmp_path, f"{station}, kiosk_id: ward4-bed1}}\n")  # the station's own key still works
    assert older.kiosk_id == older.station.kiosk_id == "ward4-bed1"
    assert site_from_config(older).kiosk_id == "ward4-bed1"
    with pytest.raises(ConfigError, match="kiosk_id 'ward3-bed2' and station.kiosk_id 'ward4-bed1' differ"):
        config(tmp_path, f"kiosk_id: ward3-bed2\n{station}, kiosk_id: ward4-bed1}}\n")


def test_the_default_canonical_url_names_the_site_and_the_questionnaire_file_id():
    from dataclasses import replace

    from kiosk.export import questionnaire_canonical
    from tests.kiosk.core.helpers import QUESTIONNAIRE

    site = ExportSite(site="hosp-north", kiosk_id="k1")
    assert questionnaire_canonical(QUESTIONNAIRE, site, "es") == "urn:barthel-kiosk:hosp-north:questionnaire:barthel-es"
    other = replace(QUESTIONNAIRE, id="barthel_short")
    assert questionnaire_canonical(other, site, "fr") == "urn:barthel-kiosk:hosp-north:questionnaire:barthel_short-fr"
    configured = replace(site, questionnaire_url="https://hosp-north.example/fhir/Questionnaire/barthel")
    assert (
        questionnaire_canonical(other, configured, "en") == "https://hosp-north.example/fhir/Questionnaire/barthel-en"
    )


def test_the_kiosk_app_exports_with_the_configured_site(tmp_path):
    from kiosk.commands.run import build_app

    path = tmp_path / "config.yaml"
    path.write_text("data_dir: data\nsite: hosp-north\nkiosk_id: ward3-bed2\n", encoding="utf-8")
    app, close = build_app(config_path=path)
    try:
        # the clinician screen's FHIR/CSV exports name the same site and kiosk as `kiosk results`
        assert app.export_site == site_from_config(load_config(path, environ={}))
        assert app.export_site.result_id("abc") == "hosp-north/ward3-bed2/abc"
    finally:
        close()
