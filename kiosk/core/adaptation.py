"""Live adaptation: the kiosk changes how it talks to the patient from the QoS metrics.

A policy (``kiosk/core/adaptation.yaml``) is a list of rules with hysteresis. The session feeds every
QoS update to :meth:`Adaptation.observe` and acts on the changes it returns (stop listening for
speech, speak more slowly); each change is a session event and a stored record. Adaptation only
changes the kiosk's behaviour, never the contexts sent to the QoS engine.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

from basis import record
from basis.errors import KioskError
from fileio.positions import Problem, parse_file
from kiosk.core.room import METRIC as ROOM_METRIC
from qos import Model, load_model

#: the QoS model the kiosk runs (sessions, replays, stored traces); the rules watch its properties
MODEL = "clarc"

#: adaptations the session knows how to carry out
KNOWN = ("voice_off", "voice_room", "slow_speech", "longer_attempts")
#: the adaptations that stop listening for speech and ask for touch or the remote: voice_off (this
#: patient's voice answers fare badly: VoiceInteractionQuality) and voice_room (voice is not
#: heard well in this room: :mod:`kiosk.core.room`)
VOICE_OFF = frozenset({"voice_off", "voice_room"})
#: metrics the kiosk measures itself, which rules may watch beside the model's properties
KIOSK_METRICS = (ROOM_METRIC,)
_RULE_KEYS = {"name", "metric", "below", "count", "count_on", "recover_above", "speech_rate", "attempt_factor"}
#: keys a rule may leave out, with their defaults
_OPTIONAL = {"speech_rate": 1.0, "attempt_factor": 1.0}


class PolicyError(KioskError, ValueError):
    """An adaptation policy file is unusable; the message names file, line and column."""


@record
class Rule:
    """Switch ``name`` on after ``count`` consecutive readings of ``metric`` below ``below``;
    off once it rises above ``recover_above``."""

    name: str
    metric: str
    below: float
    count: int
    #: "answers": only readings taken right after an answer count; "updates": every QoS update
    count_on: str
    recover_above: float
    #: for slow_speech: the factor applied to the normal speech rate
    speech_rate: float = 1.0
    #: for longer_attempts: the factor applied to the attempt window
    attempt_factor: float = 1.0


@record
class Policy:
    """A validated set of rules."""

    rules: tuple[Rule, ...]


@record
class AdaptationChange:
    """An adaptation switched on or off, and why (one sentence a clinician can read)."""

    name: str
    active: bool
    reason: str


def load_policy(path: str | Path | None = None, model: Model | None = None) -> Policy:
    """Load an adaptation policy (default: the bundled ``kiosk/core/adaptation.yaml``).

    Each rule's metric must be a property of ``model`` (default: the bundled CLARC model the
    session runs), so a misspelt metric is an error instead of a rule that never fires.
    """
    if path is None:
        data, positions, problems = parse_file(
            str(Path(__file__).with_name("adaptation.yaml")), "adaptation.yaml", keep=True
        )
        name = "adaptation.yaml"
    else:
        name = str(path)
        data, positions, problems = parse_file(path, keep=True)
    if problems or positions is None:
        raise PolicyError("\n".join(map(str, problems)))

    def fail(p: tuple[Any, ...], message: str, key: bool = False) -> PolicyError:
        line, col = positions.of(p, key=key)
        return PolicyError(str(Problem(name, line, col, message)))

    if not isinstance(data, dict) or set(data) != {"rules"} or not isinstance(data["rules"], list):
        raise fail((), "an adaptation policy is a mapping with one key, 'rules', holding a list")
    properties = sorted((model or load_model(MODEL)).properties)
    rules: list[Rule] = []
    for i, raw in enumerate(data["rules"]):
        p = ("rules", i)
        if not isinstance(raw, dict):
            raise fail(p, "each rule is a mapping")
        unknown = set(raw) - _RULE_KEYS
        if unknown:
            raise fail(p + (sorted(unknown)[0],), f"unknown key {sorted(unknown)[0]!r} in a rule", key=True)
        missing = _RULE_KEYS - set(_OPTIONAL) - set(raw)
        if missing:
            raise fail(p, f"rule is missing {sorted(missing)[0]!r}")
        if raw["name"] not in KNOWN:
            raise fail(p + ("name",), f"unknown adaptation {raw['name']!r} (known: {', '.join(KNOWN)})")
        if any(rule.name == raw["name"] for rule in rules):
            raise fail(p + ("name",), f"a second rule for {raw['name']!r} (one rule per adaptation)")
        if raw["metric"] not in (*properties, *KIOSK_METRICS):
            raise fail(
                p + ("metric",),
                f"unknown metric {raw['metric']!r} (the model's properties: {', '.join(properties)}; "
                f"the kiosk's own: {', '.join(KIOSK_METRICS)})",
            )
        if raw["count_on"] not in ("answers", "updates"):
            raise fail(p + ("count_on",), "count_on is 'answers' or 'updates'")
        # speech_rate: a factor on the normal rate; below half the kiosk's words would come with
        # pauses of seconds between them (0 would stop it speaking at all)
        for key, low, top in (
            ("below", 0, 1),
            ("recover_above", 0, 1),
            ("speech_rate", 0.5, 2),
            ("attempt_factor", 1, 4),
        ):
            value = raw.get(key, 1.0)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not low <= value <= top:
                raise fail(p + (key,), f"{key} must be a number between {low} and {top}")
        if not isinstance(raw["count"], int) or isinstance(raw["count"], bool) or raw["count"] < 1:
            raise fail(p + ("count",), "count must be a whole number of at least 1")
        if raw["recover_above"] < raw["below"]:
            raise fail(p + ("recover_above",), "recover_above must not be below 'below' (that is the hysteresis)")
        rules.append(
            Rule(
                raw["name"],
                str(raw["metric"]),
                float(raw["below"]),
                raw["count"],
                raw["count_on"],
                float(raw["recover_above"]),
                float(raw.get("speech_rate", 1.0)),
                float(raw.get("attempt_factor", 1.0)),
            )
        )
    return Policy(tuple(rules))


class Adaptation:
    """The live state of a policy for one session."""

    def __init__(self, policy: Policy, enabled: bool = True) -> None:
        self.policy = policy
        self.enabled = enabled
        self._low: dict[str, int] = {rule.name: 0 for rule in policy.rules}
        self._active: set[str] = set()
        #: adaptations whose evidence means nothing now (voice_off while voice in is unavailable)
        self._held: set[str] = set()

    @property
    def active(self) -> frozenset[str]:
        """The adaptations in force."""
        return frozenset(self._active)

    @property
    def speech_rate(self) -> float:
        """Factor on the normal speech rate (below 1 while slow_speech is on)."""
        rates = [r.speech_rate for r in self.policy.rules if r.name in self._active and r.name == "slow_speech"]
        return min(rates, default=1.0)

    @property
    def attempt_factor(self) -> float:
        """Factor on the attempt window (above 1 while longer_attempts is on)."""
        factors = [
            r.attempt_factor for r in self.policy.rules if r.name in self._active and r.name == "longer_attempts"
        ]
        return max(factors, default=1.0)

    def observe(self, metrics: Mapping[str, float], answered: bool) -> list[AdaptationChange]:
        """Take the metrics after one QoS update; returns the adaptations switched on or off."""
        if not self.enabled:
            return []
        changes = []
        for rule in self.policy.rules:
            value = metrics.get(rule.metric)
            if value is None or rule.name in self._held:
                continue
            if rule.name in self._active:
                if value > rule.recover_above:
                    self._active.discard(rule.name)
                    self._low[rule.name] = 0
                    changes.append(
                        AdaptationChange(
                            rule.name, False, f"{rule.metric} recovered to {value:.2f} (> {rule.recover_above:g})"
                        )
                    )
                continue
            if rule.count_on == "answers" and not answered:
                continue
            self._low[rule.name] = self._low[rule.name] + 1 if value < rule.below else 0
            if self._low[rule.name] >= rule.count:
                self._active.add(rule.name)
                readings = "answers" if rule.count_on == "answers" else "updates"
                changes.append(
                    AdaptationChange(
                        rule.name,
                        True,
                        f"{rule.metric} {value:.2f} < {rule.below:g} for {self._low[rule.name]} {readings} in a row",
                    )
                )
        return changes

    def hold(self, name: str, held: bool, reason: str) -> list[AdaptationChange]:
        """Keep ``name`` from switching on while ``held`` (readings do not count), or let it count
        again. Holding lifts it if it is in force, with ``reason``; released, it needs fresh evidence."""
        if not held:
            self._held.discard(name)
            return []
        self._held.add(name)
        if name in self._low:
            self._low[name] = 0
        if name not in self._active:
            return []
        self._active.discard(name)
        return [AdaptationChange(name, False, reason)]

    def patient_requests_voice(self) -> list[AdaptationChange]:
        """The patient asked to answer by voice again: lift voice_off and voice_room (each needs
        fresh evidence to return)."""
        lifted = sorted(VOICE_OFF & self._active)
        for name in lifted:
            self._active.discard(name)
            self._low[name] = 0
        return [AdaptationChange(name, False, "the patient asked to answer by voice") for name in lifted]

    def restore(self, active: Iterable[str], enabled: bool) -> None:
        """Continue a stored session's state: these adaptations in force, adaptation on or off.

        Their low-reading counts start afresh; names the policy no longer has are dropped.
        """
        self.enabled = enabled
        self._active = {name for name in active if name in self._low} if enabled else set()

    def set_enabled(self, enabled: bool) -> list[AdaptationChange]:
        """The clinician switches adaptation on or off; off lifts everything in force."""
        self.enabled = enabled
        if enabled:
            return []
        lifted = [
            AdaptationChange(name, False, "adaptation turned off by the clinician") for name in sorted(self._active)
        ]
        self._active.clear()
        self._low = {name: 0 for name in self._low}
        return lifted
