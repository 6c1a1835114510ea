"""The effect of the longer_attempts adaptation (kiosk/core/adaptation.yaml) on the scripted patients.

Every scripted patient in recordings/patients/ runs through the real session and QoS engine on a
simulated clock twice: with the bundled adaptation policy, and with the same policy without its
longer_attempts rule. Prints JSON: per patient and in total, the session length (simulated
seconds from start to the summary) and the questions left unanswered, with and without it.
Patients whose script turns adaptation off (the CLARC test bench) are listed as unaffected.
Run: uv run python bench/adaptation_effect.py [SCRIPT ...]
"""

from __future__ import annotations

import json
import sys
from dataclasses import replace
from pathlib import Path

from kiosk.commands.replay import ScriptError, load_script, run_script
from kiosk.core.adaptation import load_policy
from kiosk.core.questionnaire import load_questionnaire

PATIENTS = Path(__file__).resolve().parents[1] / "recordings" / "patients"
RULE = "longer_attempts"


def run(path: Path, policy, questionnaire) -> dict:
    """Session length, unanswered questions and when the rule switched, for one replay."""
    try:
        result = run_script(load_script(path, questionnaire), questionnaire, policy=policy)
    except ScriptError as error:  # a script whose declared attempts no longer fit
        return {"error": str(error)}
    switched = [
        round(e.t, 1) for e in result.events if type(e).__name__ == "AdaptationChanged" and e.name == RULE and e.active
    ]
    return {
        "session_s": round(result.simulated_s, 1),
        "unanswered": len(result.session.snapshot().not_answered),
        "longer_attempts_on_at_s": switched[0] if switched else None,
    }


def main(argv: list[str]) -> int:
    questionnaire = load_questionnaire()
    with_rule = load_policy()
    if RULE not in {rule.name for rule in with_rule.rules}:
        print(json.dumps({"error": f"the bundled policy has no {RULE} rule"}))
        return 1
    without_rule = replace(with_rule, rules=tuple(r for r in with_rule.rules if r.name != RULE))
    paths = [Path(a) for a in argv] or sorted(PATIENTS.glob("*.yaml"))
    patients: dict[str, dict] = {}
    totals = {side: {"session_s": 0.0, "unanswered": 0} for side in ("with", "without")}
    for path in paths:
        script = load_script(path, questionnaire)
        if not script.adaptation:
            patients[path.stem] = {"unaffected": "adaptation is off in this script"}
            continue
        entry = {"with": run(path, with_rule, questionnaire), "without": run(path, without_rule, questionnaire)}
        patients[path.stem] = entry
        for side in totals:
            if "error" not in entry[side]:
                totals[side]["session_s"] += entry[side]["session_s"]
                totals[side]["unanswered"] += entry[side]["unanswered"]
    for side in totals:
        totals[side]["session_s"] = round(totals[side]["session_s"], 1)
    print(json.dumps({"rule": RULE, "patients": patients, "total": totals}, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
