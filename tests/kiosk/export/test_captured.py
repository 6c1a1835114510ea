"""What a session captures as it starts (its questionnaire definition, its identity) and what an
upgrade attaches to sessions stored before: real SQLite files, the real `kiosk results`."""

from __future__ import annotations

import json
import sqlite3

import pytest

from kiosk.commands.results import main as results_main
from kiosk.core.questionnaire import bundled_path, load_questionnaire
from kiosk.core.questionnaire.definition import (
    DefinitionError,
    canonical,
    canonical_json,
    digest,
    questionnaire_from,
)
from kiosk.export.captured import questionnaire_of, site_of
from kiosk.store import migrations as schema
from kiosk.store.database import DB_NAME, Store
from tests.kiosk.core.helpers import QUESTIONNAIRE, at_first_question
from tests.kiosk.store.test_schema import v1_database


@pytest.mark.parametrize("band_set", ["shah", "spanish"])
def test_a_definition_round_trips_to_an_equal_questionnaire(band_set):
    q = QUESTIONNAIRE.with_band_set(band_set)
    definition = canonical(q)
    rebuilt = questionnaire_from(json.loads(canonical_json(definition)))
    assert rebuilt == q and rebuilt.band_set == band_set
    assert canonical(rebuilt) == definition and digest(canonical(rebuilt)) == digest(definition)
    # every wording survives, in the order the kiosk had it
    for mine, theirs in zip(rebuilt.items, q.items):
        assert (list(mine.text.items()), list(mine.patient.items()), list(mine.spoken.items())) == (
            list(theirs.text.items()),
            list(theirs.patient.items()),
            list(theirs.spoken.items()),
        )
        assert [(o.label, o.patient, o.synonyms, o.points, o.code) for o in mine.options] == [
            (o.label, o.patient, o.synonyms, o.points, o.code) for o in theirs.options
        ]
    assert digest(canonical(q.with_band_set("shah"))) != digest(canonical(q.with_band_set("spanish")))


def test_a_definition_that_does_not_describe_a_questionnaire_is_one_message():
    definition = canonical(QUESTIONNAIRE)
    definition["items"][0]["options"][1]["number"] = 7
    with pytest.raises(DefinitionError, match="numbered"):
        questionnaire_from(definition)
    with pytest.raises(DefinitionError, match="format"):
        questionnaire_from({"format": 99})


def test_sessions_share_one_stored_definition_and_keep_their_identity(tmp_path):
    identity = {"site": "sitea", "kiosk_id": "kiosk-a", "patient_system": "https://sitea.example/sid/patient"}
    with Store.open(tmp_path, export=identity) as store:
        ids = [at_first_question(store, patient_id=f"P-SHARE{n}").session.id for n in range(2)]
        rows = store._db.execute("SELECT sha256, body FROM definitions").fetchall()
        sessions = [store.session(i) for i in ids]
    assert len(rows) == 1 and rows[0][0] == digest(canonical(QUESTIONNAIRE)) == sessions[0].definition_sha256
    for stored in sessions:
        assert stored.definition_sha256 == rows[0][0] and not stored.definition_attached_later
        assert questionnaire_of(stored) == QUESTIONNAIRE
        assert stored.identity == identity and not stored.identity_attached_later
        site = site_of(stored)
        assert (site.site, site.kiosk_id, site.patient_system) == ("sitea", "kiosk-a", identity["patient_system"])


def _v2_database(data) -> None:
    """A version-2 database (v1 upgraded as a v2 kiosk did) with a create_session waiting in its outbox."""
    path = v1_database(data)
    db = sqlite3.connect(path, isolation_level=None)
    for statement in schema._statements(schema.V2):  # the shipped v2 script
        db.execute(statement)
    db.execute("PRAGMA user_version = 2")
    db.execute(
        "INSERT INTO outbox (kind, session_id, payload, at) VALUES ('create_session', 'aaaa00000001', ?, ?)",
        (json.dumps({"session_id": "aaaa00000001", "patient_id": "P-FIRST1"}), "2026-11-20T09:00:00Z"),
    )
    db.close()


def _config(path, site: str, kiosk: str, questionnaire=None):
    path.write_text(
        f"site: {site}\nkiosk_id: {kiosk}\n" + (f"questionnaire: {questionnaire}\n" if questionnaire else ""),
        encoding="utf-8",
    )
    return path


def test_an_upgrade_attaches_the_definition_and_identity_in_force_marked_attached_later(tmp_path, monkeypatch, capsys):
    data = tmp_path / "data"
    _v2_database(data)
    monkeypatch.setenv("KIOSK_CONFIG", str(_config(tmp_path / "a.yaml", "sitea", "kiosk-a")))
    assert results_main(["--data-dir", str(data), "--csv", str(tmp_path / "a.csv")]) == 0  # upgrades
    with Store.open(data, create=False) as store:
        assert schema.version(store._db) == schema.LATEST
        stored = [store.session(s.id) for s in store.sessions()]
        (payload,) = [json.loads(p) for (p,) in store._db.execute("SELECT payload FROM outbox")]
        assert store._db.execute("SELECT COUNT(*) FROM definitions").fetchone() == (1,)
    assert len(stored) == 4
    for session in stored:
        assert session.definition_attached_later and session.identity_attached_later
        assert session.definition == canonical(load_questionnaire())
        assert (session.identity["site"], session.identity["kiosk_id"]) == ("sitea", "kiosk-a")
    # the row waiting for the station carries them too, marked alike
    assert payload["definition"] == stored[0].definition and payload["definition_attached_later"] is True
    assert payload["export"]["site"] == "sitea" and payload["export_attached_later"] is True
    # later, another site and an edited file: the sessions keep what was attached
    edited = tmp_path / "edited.yaml"
    edited.write_text(
        bundled_path().read_text(encoding="utf-8").replace("Feeding: how do you manage eating?", "Feeding, edited"),
        encoding="utf-8",
    )
    monkeypatch.setenv("KIOSK_CONFIG", str(_config(tmp_path / "b.yaml", "siteb", "laptop-7", edited)))
    assert results_main(["--data-dir", str(data), "--csv", str(tmp_path / "b.csv")]) == 0
    assert (tmp_path / "b.csv").read_bytes() == (tmp_path / "a.csv").read_bytes()
    assert "K:kiosk-a" in (tmp_path / "b.csv").read_text(encoding="utf-8")
    capsys.readouterr()
    assert results_main(["aaaa00000001", "--data-dir", str(data)]) == 0
    assert "questionnaire and site and kiosk attached later" in capsys.readouterr().out


def test_an_upgrade_without_anything_in_force_is_refused_and_changes_nothing(tmp_path):
    data = tmp_path / "data"
    _v2_database(data)
    db = sqlite3.connect(data / DB_NAME, isolation_level=None)
    with pytest.raises(schema.SchemaError, match="nothing was changed"):
        schema.migrate(db, "kiosk.sqlite3")
    assert schema.version(db) == 2
    assert db.execute("SELECT COUNT(*) FROM sqlite_master WHERE name = 'definitions'").fetchone() == (0,)
    db.close()


def test_an_upgrade_with_an_unusable_questionnaire_in_force_is_one_message_and_changes_nothing(
    tmp_path, monkeypatch, capsys
):
    data = tmp_path / "data"
    _v2_database(data)
    broken = tmp_path / "broken.yaml"
    broken.write_text("id: barthel\nitems: [\n", encoding="utf-8")
    monkeypatch.setenv("KIOSK_CONFIG", str(_config(tmp_path / "a.yaml", "sitea", "kiosk-a", broken)))
    from kiosk.export.opening import trace_main

    assert trace_main(["aaaa00000001", "--data-dir", str(data), "--model", "clarc"]) == 2
    error = capsys.readouterr().err
    assert "broken.yaml" in error and "nothing was changed" in error and "Traceback" not in error
    db = sqlite3.connect(data / DB_NAME)
    assert schema.version(db) == 2
    db.close()
