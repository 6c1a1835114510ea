"""Live adaptation: the policy's hysteresis, and what the session does with it (real engine)."""

from __future__ import annotations

import pytest

from kiosk.core.adaptation import Adaptation, PolicyError, load_policy
from kiosk.core.channels import Channel
from kiosk.core.clock import SimClock
from kiosk.core.session import AdaptationChanged, IgnoreReason, InputIgnored, ListeningChanged, Prompt, Session
from kiosk.store.database import Store
from qos import Engine

from .helpers import MODEL, QUESTIONNAIRE, TIMING, started

VOICE_OFF = {"VoiceInteractionQuality": 0.1, "Interaction": 0.9}


def test_the_bundled_policy():
    rules = {r.name: r for r in load_policy().rules}
    assert (rules["voice_off"].metric, rules["voice_off"].below, rules["voice_off"].count) == (
        "VoiceInteractionQuality",
        0.2,
        3,
    )
    assert rules["slow_speech"].speech_rate < 1


def test_voice_off_needs_three_low_answers_and_recovers_only_above_the_upper_threshold():
    adaptation = Adaptation(load_policy())
    assert adaptation.observe(VOICE_OFF, answered=True) == []
    assert adaptation.observe(VOICE_OFF, answered=False) == []  # not an answer: does not count
    assert adaptation.observe(VOICE_OFF, answered=True) == []
    (change,) = adaptation.observe(VOICE_OFF, answered=True)
    assert (change.name, change.active) == ("voice_off", True)
    assert "VoiceInteractionQuality 0.10 < 0.2 for 3 answers in a row" == change.reason
    assert adaptation.observe({"VoiceInteractionQuality": 0.35, "Interaction": 0.9}, answered=True) == []
    assert adaptation.active == {"voice_off"}
    (change,) = adaptation.observe({"VoiceInteractionQuality": 0.45, "Interaction": 0.9}, answered=True)
    assert (change.name, change.active) == ("voice_off", False)


def test_a_good_reading_resets_the_count():
    adaptation = Adaptation(load_policy())
    for viq in (0.1, 0.1, 0.3, 0.1, 0.1):
        assert adaptation.observe({"VoiceInteractionQuality": viq}, answered=True) == []
    assert adaptation.observe({"VoiceInteractionQuality": 0.1}, answered=True)[0].active


def test_the_patient_asking_lifts_voice_off_and_it_needs_fresh_evidence_to_return():
    adaptation = Adaptation(load_policy())
    for _ in range(3):
        adaptation.observe(VOICE_OFF, answered=True)
    assert [c.active for c in adaptation.patient_requests_voice()] == [False]
    assert adaptation.patient_requests_voice() == []
    assert adaptation.observe(VOICE_OFF, answered=True) == []


def test_slow_speech_counts_every_update_and_sets_the_rate():
    adaptation = Adaptation(load_policy())
    low = {"Interaction": 0.2}
    assert adaptation.observe(low, answered=False) == []
    assert adaptation.observe(low, answered=False)[0].name == "slow_speech"
    assert adaptation.speech_rate == 0.85


def test_disabled_adaptation_does_nothing_and_turning_it_off_lifts_everything():
    adaptation = Adaptation(load_policy())
    for _ in range(3):
        adaptation.observe(VOICE_OFF, answered=True)
    lifted = adaptation.set_enabled(False)
    assert [(c.name, c.active) for c in lifted] == [("voice_off", False)]
    for _ in range(5):
        assert adaptation.observe(VOICE_OFF, answered=True) == []
    assert not adaptation.active


@pytest.mark.parametrize(
    ("text", "at", "message"),
    [
        (
            "rules:\n  - {name: voice_off, metric: VoiceInteractionQuality, below: 0.2, count: 3, count_on: answers,"
            " recover_above: 0.4, colour: red}\n",
            "colour: red",
            "unknown key 'colour' in a rule",
        ),
        (
            "rules:\n  - {name: shout, metric: Interaction, below: 0.2, count: 3, count_on: answers, recover_above: 0.4}\n",
            "shout",
            "unknown adaptation 'shout'",
        ),
        (
            "rules:\n  - {name: voice_off, metric: Interaction, below: 0.5, count: 3, count_on: answers, recover_above: 0.4}\n",
            "0.4}",
            "recover_above must not be below 'below'",
        ),
        (
            "rules:\n  - {name: voice_off, metric: Interaction, below: 0.2, count: 0, count_on: answers, recover_above: 0.4}\n",
            "0, count_on",
            "count must be a whole number of at least 1",
        ),
        (
            "rules:\n  - {name: voice_off, metric: VoiceInteractionQualty, below: 0.2, count: 3, count_on: answers,"
            " recover_above: 0.4}\n",
            "VoiceInteractionQualty",
            "unknown metric 'VoiceInteractionQualty' (the model's "
            "properties: Interaction, Performance, VoiceInteractionQuality; the kiosk's own: VoiceHeard)",
        ),
        (
            "rules:\n  - {name: voice_off, metric: Interaction, below: 1.5, count: 3, count_on: answers, recover_above: 1.8}\n",
            "1.5",
            "below must be a number between 0 and 1",
        ),
        (
            "rules:\n  - {name: voice_off, metric: Interaction, below: 0.2, count: 3, count_on: answers, recover_above: 1.5}\n",
            "1.5",
            "recover_above must be a number between 0 and 1",
        ),
        ("rules: [\n", None, ":2:1: YAML syntax"),
        ("policy: []\n", None, ":1:1: an adaptation policy is a mapping with one key, 'rules'"),
    ],
)
def test_a_bad_policy_file_is_one_positioned_message(tmp_path, text, at, message):
    path = tmp_path / "policy.yaml"
    path.write_text(text)
    with pytest.raises(PolicyError) as caught:
        load_policy(path)
    if at is not None:  # the problem is on line 2, where `at` starts
        message = f":2:{text.splitlines()[1].index(at) + 1}: {message}"
    assert str(caught.value).startswith(str(path) + message)


def _touch_answers_until_voice_off(rig):
    for _ in range(6):
        rig.run_until(rig.session.now() + 15)
        rig.at(rig.session.now() + 3)
        rig.answer(1, Channel.TOUCH)
        if rig.of(AdaptationChanged):
            return
    pytest.fail("voice_off never switched on")


def test_the_session_stops_listening_tells_the_patient_and_records_it(tmp_path):
    store = Store.open(tmp_path)
    rig = started(adaptation=Adaptation(load_policy()), store=store)
    rig.run_until(25)
    _touch_answers_until_voice_off(rig)
    change = rig.of(AdaptationChanged)[-1]
    assert (change.name, change.active) == ("voice_off", True)
    assert rig.session.snapshot().adaptations == {"voice_off"}
    assert [p.key for p in rig.of(Prompt) if p.kind == "message"][-1] == "voice_off"
    rig.run_until(rig.session.now() + 15)
    assert not rig.session.listening  # the next attempt is open, but voice is off
    rig.answer(2, Channel.VOICE)
    assert rig.of(InputIgnored)[-1].reason is IgnoreReason.VOICE_OFF
    trace_before = list(rig.session.trace)
    rig.session.request_voice()
    assert rig.session.listening and rig.of(ListeningChanged)[-1].listening
    assert rig.session.trace == trace_before  # adaptations never reach the QoS engine
    rig.answer(2, Channel.VOICE)
    stored = store.session(rig.session.id)
    assert [(a.name, a.active) for a in stored.adaptations] == [("voice_off", True), ("voice_off", False)]
    assert stored.answers[-1].channel is Channel.VOICE


def test_the_clinician_can_switch_adaptation_off_mid_session():
    rig = started(adaptation=Adaptation(load_policy()))
    rig.run_until(25)
    _touch_answers_until_voice_off(rig)
    rig.session.set_adaptation_enabled(False)
    assert rig.of(AdaptationChanged)[-1].reason == "adaptation turned off by the clinician"
    assert not rig.session.snapshot().adaptations


def test_low_interaction_slows_speech_and_repeats_the_question():
    rig = started(adaptation=Adaptation(load_policy()))
    rig.run_until(400)  # nobody answers: time-outs drag Interaction down
    slow = [e for e in rig.of(AdaptationChanged) if e.name == "slow_speech"]
    assert slow and slow[0].active
    after = rig.events[rig.events.index(slow[0]) :]
    later = [p for p in after if isinstance(p, Prompt) and p.kind == "question"]
    assert later and all(p.speech_rate == 0.85 for p in later)


def test_a_second_rule_for_the_same_adaptation_is_an_error(tmp_path):
    rule = "  - {name: slow_speech, metric: Interaction, below: 0.2, count: 3, count_on: answers, recover_above: 0.4}\n"
    path = tmp_path / "policy.yaml"
    path.write_text("rules:\n" + rule + rule)
    with pytest.raises(PolicyError) as caught:
        load_policy(path)
    assert str(caught.value) == f"{path}:3:12: a second rule for 'slow_speech' (one rule per adaptation)"


def test_the_metric_is_checked_against_the_model_given(tmp_path):
    from qos import parse_model

    path = tmp_path / "policy.yaml"
    path.write_text(
        "rules:\n  - {name: voice_off, metric: Interaction, below: 0.2, count: 3, count_on: answers,"
        " recover_above: 0.4}\n"
    )
    assert load_policy(path).rules[0].metric == "Interaction"
    other = parse_model("roqme Other\nproperty Calm reference 0.5\n", "other.roqme")
    with pytest.raises(
        PolicyError,
        match=r":2:31: unknown metric 'Interaction' \(the model's properties: Calm; the kiosk's own: VoiceHeard\)",
    ):
        load_policy(path, model=other)


def _resumed(store: Store, rig) -> Session:
    """The kiosk restarted after a crash: the stored session continues with a fresh policy state."""
    stored = store.session(rig.session.id)
    return Session.from_stored(
        QUESTIONNAIRE,
        stored,
        clock=SimClock(start=900),
        engine=Engine(MODEL),
        store=store,
        timing=TIMING,
        adaptation=Adaptation(load_policy()),
    )


def test_a_resumed_session_keeps_voice_off_in_force(tmp_path):
    store = Store.open(tmp_path)
    rig = started(adaptation=Adaptation(load_policy()), store=store)
    rig.run_until(25)
    _touch_answers_until_voice_off(rig)
    resumed = _resumed(store, rig)
    assert resumed.snapshot().adaptations == {"voice_off"}  # it does not listen again to a patient it could not hear


def test_a_resumed_session_keeps_the_clinicians_adaptation_switch(tmp_path):
    store = Store.open(tmp_path)
    rig = started(adaptation=Adaptation(load_policy()), store=store)
    rig.run_until(25)
    rig.session.set_adaptation_enabled(False)
    resumed = _resumed(store, rig)
    assert resumed.adaptation is not None and not resumed.adaptation.enabled
    assert [e.detail for e in store.session(rig.session.id).log if e.kind == "adaptation_enabled"] == ["off"]
