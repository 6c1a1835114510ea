"""`kiosk results [SESSION...] [--fhir FILE] [--fhir-questionnaire FILE] [--csv FILE] [--csv-wide FILE]`.

Without SESSION: list stored sessions; exports then cover every stored session. With SESSION (an
id, a unique prefix, or the CSV's tagged ``S:id``), exports cover those sessions: ``--fhir`` one
FHIR R4 transaction Bundle (Questionnaires, kiosk Device, responses, totals; see
:mod:`kiosk.export.fhir`), ``--csv`` the long CSV and ``--csv-wide`` one row per session (see
:mod:`kiosk.export.tables`), one table per instrument: sessions of several instruments (a battery)
give ``FILE-<id>.csv`` each, since a wide table's columns are one instrument's items.
Each session is described with what it captured as it started (its
questionnaire definition and its site, kiosk and FHIR systems, :mod:`kiosk.export.captured`), whatever
the questionnaire file and configuration say today; ``--fhir-questionnaire`` writes today's
questionnaire. The listing ends with the outbox: changes waiting for the ward station and those
it refused (parked). For each SESSION it shows how the
practice questions went (hearing, reading, selecting: right, wrong, not answered or skipped and
why), its answers, the total recomputed from them, band (from the band set it was scored with) and
completeness, adaptations and QoS metrics at the end.
Without SESSION, the stored Timed Up and Go results with a time go out too (issue 34): Observations
LOINC 89423-8 in the ``--fhir`` Bundle, and with ``--csv FILE`` their rows in ``FILE-tug.csv``
(:mod:`kiosk.export.tug`). Exports are written readable by their owner only. Exit 2 on an unknown
session or unusable store.
"""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

from kiosk.config import ConfigError, configured_instruments, configured_questionnaire, load_config
from kiosk.core.questionnaire import QuestionnaireError, result_words
from kiosk.core.words import languages
from kiosk.export import (
    ID_TAGS,
    ExportError,
    export_identity,
    fhir_questionnaire,
    practice_outcomes,
    questionnaire_bundle,
    rescore,
    site_from_config,
    write_export,
    write_json,
)
from kiosk.export.captured import bundle_of, csv_of, questionnaire_of, result_line, wide_csv_tables
from kiosk.export.opening import in_force_of, open_store
from kiosk.export.tug import tug_csv, tug_entries, tug_times
from kiosk.store.database import StorageError, Store, StoredSession


def _listed_result(store: Store, session_id: str) -> str:
    """A session's result line in the list; a session whose stored rows this kiosk cannot read is
    listed as such (the list goes on: ``kiosk results ID`` names the damage)."""
    try:
        return result_line(store.session(session_id))
    except StorageError:
        return f"cannot be read (kiosk results {session_id} says why)"


def _show(stored: StoredSession) -> None:
    q = questionnaire_of(stored)
    score = rescore(q, stored)
    status = (
        stored.status
        + (f" ({stored.interrupted_reason})" if stored.interrupted_reason else "")
        + (", simulated (a scripted patient, kiosk replay)" if stored.simulated else "")
    )
    print(
        f"session {stored.id}  patient {stored.patient_id}  {status}  language {stored.language}  "
        f"answered by {stored.answered_by.value}"
    )
    print(f"started {stored.started_at}" + (f"  finished {stored.finished_at}" if stored.finished_at else ""))
    later = [
        what
        for what, flag in (
            ("questionnaire", stored.definition_attached_later),
            ("site and kiosk", stored.identity_attached_later),
        )
        if flag
    ]
    print(
        f"questionnaire {q.id} {q.version} ({stored.definition_sha256[:12]}), recorded at "
        f"{stored.identity.get('site', '?')}/{stored.identity.get('kiosk_id', '?')}"
        + (f"; {' and '.join(later)} attached later (stored before kiosks captured them)" if later else "")
    )
    outcomes = practice_outcomes(q, stored)
    print(
        "practice: "
        + ("; ".join(str(o) for o in outcomes) if outcomes else "none (no practice questions in this session)")
    )
    answers = {a.item_id: a for a in stored.answers}
    for item in q.items:
        a = answers.get(item.id)
        if a is None:
            outcome = "not answered" if item.id in stored.not_answered else "-"
            print(f"  {item.number:>2} {item.id:<10} {outcome}")
        else:
            label = item.option(a.option).label_in(stored.language)
            print(
                f"  {item.number:>2} {item.id:<10} option {a.option} {a.points:>3} points  attempt {a.attempt}  "
                f"{a.channel.value:<8} {label}"
            )
    source = q.bands_named(score.band_set).source
    if score.complete:
        band = f"{score.band.label['en']} (bands: {score.band_set}, {source})" if score.band else "no band"
        print(f"total {score.total}/{score.max_total} (complete); {band}")
    else:  # a partial sum is no total: say what the result waits for, by the items' words
        partial = set(score.missing) - set(score.awaiting_staff) and not score.problem
        print(result_words(q, score) + (f" (the answered ones add up to {score.total})" if partial else ""))
    for record in stored.adaptations:
        print(f"  adaptation {record.name} {'on' if record.active else 'off'} at t={record.t:g}: {record.reason}")
    if stored.metrics:
        last = stored.metrics[-1]
        print("QoS at the end: " + ", ".join(f"{k} {v:.3f}" for k, v in last.metrics.items()))


def wide_paths(file: str, instruments: list[str]) -> dict[Path, str]:
    """Where ``--csv-wide FILE`` writes each instrument's table: FILE itself for one instrument;
    for several, ``STEM-<id>SUFFIX`` beside it (``wide.csv`` -> ``wide-barthel.csv``,
    ``wide-gds15.csv``): a wide table has one instrument's item columns."""
    path = Path(file)
    if len(instruments) == 1:
        return {path: instruments[0]}
    return {
        path.with_name(f"{path.stem}-{re.sub(r'[^A-Za-z0-9_.-]', '_', qid)}{path.suffix}"): qid for qid in instruments
    }


def tug_csv_path(file: str) -> Path:
    """Where ``--csv FILE`` writes the Timed Up and Go times (their own columns): ``STEM-tug.csv``."""
    path = Path(file)
    return path.with_name(f"{path.stem}-tug{path.suffix or '.csv'}")


def main(argv: list[str]) -> int:
    """List, show or export stored sessions; returns the exit status."""
    parser = argparse.ArgumentParser(
        prog="kiosk results",
        description="List stored sessions, show some, or export them as FHIR R4 JSON or CSV "
        "(totals recomputed from the answers).",
    )
    parser.add_argument(
        "sessions",
        nargs="*",
        metavar="SESSION",
        help="session id or unique prefix (default: list sessions; exports cover all)",
    )
    parser.add_argument("--fhir", metavar="FILE", help="write the sessions as one FHIR R4 transaction Bundle")
    parser.add_argument(
        "--fhir-questionnaire",
        metavar="FILE",
        help="write the FHIR R4 Questionnaire (with --language: that language's; else a Bundle of all); "
        "a battery (instruments: in the config): a Bundle of every instrument",
    )
    parser.add_argument("--language", choices=languages(), help="language of --fhir-questionnaire")
    parser.add_argument("--csv", metavar="FILE", help="write the sessions as CSV, rows per item")
    parser.add_argument(
        "--csv-wide",
        metavar="FILE",
        help="write the sessions as CSV, one row per session; sessions of several instruments: "
        "one file per instrument, FILE's name with -ID before its suffix",
    )
    parser.add_argument("--bom", action="store_true", help="start CSV files with a UTF-8 byte-order mark")
    parser.add_argument("--data-dir", help="data directory (default: from the kiosk configuration)")
    args = parser.parse_args(argv)
    if args.language and not args.fhir_questionnaire:
        parser.error("--language says which language --fhir-questionnaire writes; give --fhir-questionnaire FILE")
    try:
        config = load_config()
        site = site_from_config(config)
        # today's questionnaire file is read only for what it describes: itself (--fhir-questionnaire)
        # and an export of no session; stored sessions are described by what they captured
        if args.fhir_questionnaire:
            battery = [q for q, _ in configured_instruments(config)]
            if len(battery) == 1 and args.language:
                written: dict = fhir_questionnaire(battery[0], args.language, site)
            else:  # several instruments (instruments: in the config) are a Bundle, one per language
                missing = [q.id for q in battery if args.language and args.language not in q.languages]
                if missing:
                    raise ConfigError(f"--language {args.language}: {', '.join(missing)} has no such translation")
                written = questionnaire_bundle(battery, site, args.language)
            write_json(args.fhir_questionnaire, written)
        with open_store(args.data_dir, in_force=lambda: in_force_of(config), export=export_identity(site)) as store:
            refs = [ref.removeprefix(ID_TAGS["session"]) for ref in args.sessions]
            exporting = args.fhir or args.csv or args.csv_wide
            chosen = (
                [store.session(ref) for ref in refs]
                if refs
                else [store.session(s.id) for s in store.sessions()]
                if exporting
                else []
            )
            empty = None if chosen or not exporting else (configured_questionnaire(config), site)
            tugs = tug_times(store.tug.all()) if exporting and not refs else []  # a visit's TUG, not a session's
            if args.fhir:
                bundle = bundle_of(chosen, empty=empty)
                if tugs:
                    bundle["entry"] = [*bundle.get("entry", []), *tug_entries(tugs, site)]
                write_json(args.fhir, bundle)
            if args.csv:
                write_export(args.csv, csv_of(chosen, bom=args.bom, empty=empty))
                if tugs:
                    write_export(tug_csv_path(args.csv), tug_csv(tugs, bom=args.bom))
                    print(f"Timed Up and Go times: {tug_csv_path(args.csv)}", file=sys.stderr)
            if args.csv_wide:
                tables = wide_csv_tables(chosen, bom=args.bom, empty=empty)
                for path, qid in wide_paths(args.csv_wide, list(tables)).items():
                    write_export(path, tables[qid])
                if len(tables) > 1:
                    print(
                        "wide CSV: one table per instrument: "
                        + ", ".join(str(p) for p in wide_paths(args.csv_wide, list(tables))),
                        file=sys.stderr,
                    )
            if not refs:
                summaries = store.sessions()
                if not summaries:
                    print("no sessions stored", file=sys.stderr)
                for tug in store.tug.all():
                    r = tug.result
                    print(f"{tug.id}  {tug.patient_id:<10} {tug.at}  tug      {r.decision:<9} {r.wording()}")
                for s in summaries:
                    print(
                        f"{s.id}  {s.patient_id:<10} {s.started_at}  {s.questionnaire_id:<8} {s.label:<9} "
                        f"{s.language}  {_listed_result(store, s.id)}"
                    )
                waiting, parked = store.outbox_waiting()
                if waiting or parked:
                    print(
                        f"outbox: {waiting} stored changes waiting for the ward station, {parked} refused by it "
                        "(parked, kept for an engineer)",
                        file=sys.stderr,
                    )
            for stored in chosen if refs else ():
                _show(stored)
    except (ConfigError, StorageError, QuestionnaireError, ExportError) as exc:
        print(f"kiosk results: {exc}", file=sys.stderr)
        return 2
    except KeyError as exc:
        print(f"kiosk results: {exc.args[0]}", file=sys.stderr)
        return 2
    return 0
