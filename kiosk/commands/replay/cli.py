"""`kiosk replay FILE...`: load the configuration, run each script, print or store the results."""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import replace
from typing import Any

from fileio.bounded import BadFile
from kiosk.commands.replay.driver import ReplayResult, run_battery, run_script
from kiosk.commands.replay.script import ScriptError, is_battery_script, load_battery_script, load_script
from kiosk.commands.replay.tug import TugReplay, is_tug_script, load_tug_script, run_tug_script
from kiosk.core.questionnaire import Questionnaire, QuestionnaireError
from kiosk.store.lease import SessionTaken
from qos.errors import QosError


def _print_human(result: ReplayResult) -> None:
    data = result.to_dict()
    score = data["score"]
    band = f", {score['band']}" if score["band"] else ""
    status = "complete" if score["complete"] else f"incomplete ({len(data['not_answered'])} not answered)"
    print(f"{data['script']}: patient {data['patient']} ({data['language']}, answered by {data['answered_by']})")
    print(
        f"{data['instrument']} total {score['total']}/{score['max_total']} {status}{band}; "
        f"simulated {data['simulated_s']} s"
    )
    for answer in data["answers"]:
        print(
            f"  {answer['item']:<10} option {answer['option']}  {answer['points']:>2} points  "
            f"attempt {answer['attempt']}  {answer['channel']:<8} t={answer['t']}"
        )
    for item in data["not_answered"]:
        print(f"  {item:<10} not answered")
    for adaptation in data["adaptations"]:
        state = "on" if adaptation["active"] else "off"
        print(f"  adaptation {adaptation['name']} {state} at t={adaptation['t']}: {adaptation['reason']}")
    print("QoS        min     max     avg     sd      last")
    for name, stats in data["qos"]["metrics"].items():
        print(f"  {name:<24} " + " ".join(f"{stats[k]:.4f}" for k in ("min", "max", "avg", "sd", "last")))


class _NoOrder(Exception):
    """The station did not give the ordered visit (message says why)."""


def _take_order(code: str, config: Any, battery: list[tuple[Questionnaire, Any]]) -> Any:
    """The ordered visit whose code staff gave, started at the configured station."""
    if config.station is None:
        raise _NoOrder("--order-code needs a station in the configuration (station: {url, token, kiosk_id})")
    from kiosk.sync.http import Station, Unreachable
    from kiosk.sync.orders import OrderRefused, start_order

    try:
        return start_order(
            Station(config.station.url, config.station.token),
            code,
            instruments=[q.id for q, _ in battery],
            languages=[lang for lang in battery[0][0].languages if all(lang in q.languages for q, _ in battery)],
        )
    except (OrderRefused, Unreachable) as exc:
        raise _NoOrder(f"the visit with code {code} was not started: {exc}") from None


def main(argv: list[str]) -> int:
    """`kiosk replay FILE... [--json] [--trace OUT] [--data-dir DIR]`; exit 0, or 2 on a bad script."""
    parser = argparse.ArgumentParser(
        prog="kiosk replay",
        description="Run scripted patients through the real session core and QoS engine on a simulated clock.",
    )
    parser.add_argument("files", nargs="+", metavar="FILE", help="scripted patient YAML file(s)")
    parser.add_argument("--json", action="store_true", help="print one JSON object per script")
    parser.add_argument("--trace", metavar="OUT", help="write the context trace (one script only)")
    parser.add_argument(
        "--data-dir",
        metavar="DIR",
        help="also store the replayed sessions in this data directory (see `kiosk results`)",
    )
    parser.add_argument(
        "--config",
        metavar="FILE",
        help="configuration file (default: $KIOSK_CONFIG or the user's): its questionnaire, "
        "band set, adaptation policy and QoS model are the ones replayed, as at the kiosk",
    )
    parser.add_argument(
        "--station-wait",
        metavar="S",
        type=float,
        default=30.0,
        help="with a station configured, how long to try delivering the stored sessions to it "
        "before exiting (default 30; what is left goes with the next kiosk run)",
    )
    parser.add_argument(
        "--order-code",
        metavar="CODE",
        help="run the script as the visit ordered for this kiosk whose code the station shows "
        "(one script; needs --data-dir and a station): its patient and language are the order's",
    )
    args = parser.parse_args(argv)
    if args.trace and len(args.files) != 1:
        parser.error("--trace takes one script")
    if args.order_code and (len(args.files) != 1 or not args.data_dir):
        parser.error("--order-code takes one script and --data-dir")
    from kiosk.config import ConfigError, configured_instruments, load_config, tug_settings
    from kiosk.core.adaptation import PolicyError, load_policy
    from kiosk.core.qos_model import load_kiosk_model

    try:
        config = load_config(args.config)
        battery = configured_instruments(config)
        questionnaire = battery[0][0]
        policy = load_policy(config.adaptation_policy, model=load_kiosk_model(config.qos_model))
    except QuestionnaireError as exc:
        print(f"kiosk replay: the questionnaire is invalid: {exc}", file=sys.stderr)
        return 2
    except (ConfigError, PolicyError, QosError, BadFile) as exc:
        print(f"kiosk replay: {exc}", file=sys.stderr)
        return 2
    store = None
    if args.data_dir:
        from kiosk.store.database import StorageError, Store

        try:
            # scripted patients: never offered to anyone; queued for the station when there is one
            from kiosk.export import export_identity, site_from_config
            from kiosk.export.opening import in_force_of

            store = Store.open(
                args.data_dir,
                simulated=True,
                outbox=config.station is not None,
                export=export_identity(site_from_config(config)),
                in_force=lambda: in_force_of(config),
            )
        except StorageError as exc:
            print(f"kiosk replay: {exc}", file=sys.stderr)
            return 2
    results: list[ReplayResult | TugReplay] = []
    try:
        order = _take_order(args.order_code, config, battery) if args.order_code else None
        for file in args.files:
            if is_tug_script(file):  # a visit's Timed Up and Go from a landmark file
                tug = load_tug_script(file, tug_settings(config))
                tug = replace(tug, patient=order.patient_id) if order is not None else tug
                visit = order.visit if order is not None else None
                results.append(run_tug_script(tug, store=store, model=config.qos_model, visit=visit))
                continue
            if is_battery_script(file):  # a visit of several instruments: one result each
                battery_script = load_battery_script(file, {q.id: q for q, _ in battery})
                if order is not None:
                    battery_script = replace(
                        battery_script,
                        scripts=tuple(
                            replace(s, patient=order.patient_id, language=order.language, answered_by=order.answered_by)
                            for s in battery_script.scripts
                        ),
                    )
                results += run_battery(
                    battery_script,
                    models={q.id: m for q, m in battery},
                    store=store,
                    model=config.qos_model,
                    policy=policy,
                    visit=order.visit if order is not None else None,
                )
                continue
            script = load_script(file, questionnaire)
            if order is not None:  # the ordered patient, language and answerer, never the script's own
                script = replace(
                    script, patient=order.patient_id, language=order.language, answered_by=order.answered_by
                )
            results.append(
                run_script(
                    script,
                    questionnaire,
                    store=store,
                    model=config.qos_model,
                    policy=policy,
                    visit=order.visit if order is not None else None,
                )
            )
    except ScriptError as exc:
        print(exc, file=sys.stderr)
        return 2
    except _NoOrder as exc:
        print(f"kiosk replay: {exc}", file=sys.stderr)
        return 2
    except SessionTaken as exc:  # another kiosk on this data directory took the session over
        print(f"kiosk replay: {exc}", file=sys.stderr)
        return 2
    finally:
        if store is not None:
            store.close()
    if store is not None and config.station is not None:
        from kiosk.sync import deliver_pending

        unsent = deliver_pending(store.path, config.station, max(0.0, args.station_wait))
        if unsent:
            print(f"kiosk replay: {unsent}", file=sys.stderr)
    if args.trace:
        from fileio.bounded import write_error
        from qos import dump_trace

        try:
            dump_trace(results[0].trace, args.trace, header=f"context trace of {results[0].script.source}")
        except OSError as exc:
            print(f"kiosk replay: {write_error(args.trace, exc)}", file=sys.stderr)
            return 2
    for result in results:
        if args.json:
            print(json.dumps(result.to_dict(), ensure_ascii=False))
        elif isinstance(result, TugReplay):
            print(result.human())
        else:
            _print_human(result)
    return 0
