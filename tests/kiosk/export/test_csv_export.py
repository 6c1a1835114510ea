"""CSV for researchers, read back by real pandas: ids stay text, long and wide layouts, BOM."""

from __future__ import annotations

import io
from dataclasses import replace

import pandas as pd

from kiosk.commands.results import main as results_main
from kiosk.core.review import Correction, Review, ReviewState
from kiosk.export import ExportSite, csv_text, questionnaire_version, wide_csv_text
from tests.kiosk.core.helpers import QUESTIONNAIRE

SITE = ExportSite(site="hosp-north", kiosk_id="0042")
#: ids that a CSV reader would take for numbers, a missing value or a boolean
TRICKY = [("001234567890", "00123"), ("8e1234567890", "NA"), ("123456789012", "True")]


def tricky_sessions(replayed):
    base = [replayed["TB-0001"], replayed["TB-0004"], replayed["P-ES-0001"]]
    return [replace(stored, id=session, patient_id=patient) for stored, (session, patient) in zip(base, TRICKY)]


def test_ids_stay_text_in_pandas_in_both_layouts(replayed, tmp_path):
    sessions = tricky_sessions(replayed)
    for name, text in (
        ("long", csv_text(QUESTIONNAIRE, sessions, site=SITE)),
        ("wide", wide_csv_text(QUESTIONNAIRE, sessions, site=SITE)),
    ):
        path = tmp_path / f"{name}.csv"
        path.write_text(text, encoding="utf-8")
        frame = pd.read_csv(path)
        for column in ("session", "patient", "kiosk_id"):
            assert frame[column].map(type).eq(str).all(), (name, column, frame[column].tolist())
        sessions_read = frame["session"].str.removeprefix("S:").unique().tolist()
        patients_read = frame["patient"].str.removeprefix("P:").unique().tolist()
        assert sessions_read == [s for s, _ in TRICKY] and patients_read == [p for _, p in TRICKY]
        assert set(frame["kiosk_id"].str.removeprefix("K:")) == {"0042"}


def test_the_wide_csv_has_one_row_per_session_and_no_total_when_incomplete(replayed, tmp_path):
    sessions = [replayed["TB-0001"], replayed["TB-0004"], replayed["P-FR-0003"]]
    path = tmp_path / "wide.csv"
    path.write_text(wide_csv_text(QUESTIONNAIRE, sessions, site=SITE), encoding="utf-8")
    frame = pd.read_csv(path, keep_default_na=False)
    assert len(frame) == 3
    complete, partial, french = (frame.iloc[i] for i in range(3))
    assert (complete["total"], complete["complete"], complete["band"], complete["band_set"]) == (
        "100",
        True,
        "independent",
        "shah",
    )  # a real boolean
    assert (partial["total"], partial["answered_points"], partial["complete"]) == ("", 65, False)
    assert partial["missing"] == "grooming bladder" and partial["grooming_option"] == ""
    assert partial["feeding_option"] == 3 and partial["feeding_points"] == 10
    assert french["language"] == "fr" and french["answered_by"] == "relative" and french["missing"] == "mobility"
    assert all(row["questionnaire_version"] == questionnaire_version(QUESTIONNAIRE) for _, row in frame.iterrows())
    assert set(frame["review_state"]) == {"unreviewed"} and all(frame["finished_at"].str.len() > 0)


def test_the_long_csv_shows_the_review_and_what_the_kiosk_recorded(replayed):
    stored = replayed["TB-0004"]
    review = Review(
        ReviewState.AMENDED,
        (
            Correction("grooming", 2, None, "asked again", "dr.lopez", "2026-11-23T15:00:00Z"),
            Correction("feeding", 2, 3, "patient overstated", "dr.lopez", "2026-11-23T15:01:00Z"),
            Correction("bladder", 3, None, "chart", "dr.lopez", "2026-11-23T15:01:00Z"),
        ),
        "dr.lopez",
        "2026-11-23T15:02:00Z",
    )
    frame = pd.read_csv(io.StringIO(csv_text(QUESTIONNAIRE, [stored], [review], SITE)), keep_default_na=False)
    items = frame[frame["kind"] == "item"].set_index("item")
    assert (items.loc["feeding", "option"], items.loc["feeding", "recorded_option"]) == ("2", "3")
    assert items.loc["feeding", "corrected_by"] == "dr.lopez" and items.loc["feeding", "points"] == 5
    assert (items.loc["grooming", "option"], items.loc["grooming", "recorded_option"]) == ("2", "")
    assert items.loc["dressing", "channel"] == "touch" and items.loc["dressing", "corrected_by"] == ""
    total = frame[frame["kind"] == "total"].iloc[0]
    assert (total["points"], total["complete"], total["review_state"]) == (75, True, "amended")


def test_kiosk_results_writes_both_layouts_with_a_bom_and_accepts_tagged_ids(replayed, tmp_path, monkeypatch):
    from kiosk.commands.replay import load_script, run_script
    from kiosk.store.database import Store

    from .conftest import RECORDED_AT, ROOT

    store = Store.open(tmp_path / "data", export=RECORDED_AT)  # recorded on ward3-bed2
    run_script(load_script(ROOT / "recordings/patients/spanish_voice.yaml"), store=store)
    session_id = store.sessions()[0].id
    store.close()
    config = tmp_path / "config.yaml"
    config.write_text("site: hosp-north\nkiosk_id: ward3-bed2\n", encoding="utf-8")
    monkeypatch.setenv("KIOSK_CONFIG", str(config))
    long, wide = tmp_path / "long.csv", tmp_path / "wide.csv"
    assert (
        results_main(
            [
                f"S:{session_id}",
                "--data-dir",
                str(tmp_path / "data"),
                "--csv",
                str(long),
                "--csv-wide",
                str(wide),
                "--bom",
            ]
        )
        == 0
    )
    for path in (long, wide):
        assert path.read_bytes().startswith(b"\xef\xbb\xbfsession,")
        assert path.stat().st_mode & 0o777 == 0o600
        frame = pd.read_csv(path, encoding="utf-8-sig")
        assert frame["kiosk_id"].iloc[0] == "K:ward3-bed2" and frame["session"].iloc[0] == f"S:{session_id}"
    assert "Independiente" in long.read_text(encoding="utf-8-sig")  # labels in the session's language
