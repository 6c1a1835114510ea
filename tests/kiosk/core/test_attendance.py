"""Presence and the unattended kiosk (issue 34 part 2, issue 36 part 5), on the simulated clock.

A presence report (camera or staff) publishes PersonDetected on change and stops the question
clock; away for the site's time, the ward is alerted (a logged ``away_alert``, an outbox alert);
after the site's number of unanswered questions in a row the kiosk waits for a touch.
"""

from __future__ import annotations

from kiosk.core.channels import Channel, ChannelInput, Command, Presence, PresenceSource
from kiosk.core.session import (
    AttemptOpened,
    AttemptTimedOut,
    AwayAlert,
    Finished,
    IgnoreReason,
    InputIgnored,
    PersonBack,
    PersonLost,
    Prompt,
    QuestionNotAnswered,
    Unattended,
    UnattendedEnded,
    Watching,
)
from kiosk.store.database import Store
from tests.kiosk.core.helpers import QUESTIONNAIRE, started

CAMERA = PresenceSource.CAMERA
WATCH = Watching(away_alert_after_s=60, unattended_after=2)


def seen(rig, value: bool, source: PresenceSource = CAMERA, detail: str = "") -> None:
    rig.session.handle(Presence(value, source, detail))


def log(store: Store, rig) -> list[tuple[str, str]]:
    return [(e.kind, e.detail) for e in store.session(rig.session.id).log]


def test_a_camera_report_is_handled_like_a_channel_input_and_published_on_change_only():
    rig = started(watching=WATCH)  # Q1 opens at 25; its attempt 1 ends at 55
    rig.at(40)
    seen(rig, False, detail="no person in 15 frames")
    rig.at(41)
    seen(rig, False)  # a second report that changes nothing publishes nothing
    rig.at(50)
    seen(rig, True)
    rig.at(51)
    seen(rig, True)
    assert [e for e in rig.session.trace if "PersonDetected" in e.get("set", {})][1:] == [
        {"t": 40, "set": {"PersonDetected": False}},
        {"t": 50, "set": {"PersonDetected": True}},
    ]
    assert [(type(e).__name__, e.source) for e in rig.events if isinstance(e, (PersonLost, PersonBack))] == [
        ("PersonLost", CAMERA),
        ("PersonBack", CAMERA),
    ]
    ignored = [e.reason for e in rig.of(InputIgnored)]
    assert ignored == [IgnoreReason.PERSON_ALREADY_LOST, IgnoreReason.PERSON_NOT_LOST]


def test_no_attempt_times_out_while_away_and_the_attempt_goes_on_with_its_time_left():
    rig = started(watching=WATCH)
    rig.at(35)  # 20 s left on attempt 1
    seen(rig, False)
    rig.run_until(1000)  # long away: nothing times out
    assert rig.of(AttemptTimedOut) == [] and rig.session.current_attempt == 1
    seen(rig, True)
    assert rig.session.remaining() == 20  # its time left (more than the 5 s grace)
    rig.run_until(1020)
    assert [(e.attempt, e.t) for e in rig.of(AttemptTimedOut)] == [(1, 1020)]


def test_away_longer_than_the_site_sets_alerts_the_ward_once(tmp_path):
    store = Store.open(tmp_path / "data")
    rig = started(store=store, watching=WATCH)
    rig.at(30)
    seen(rig, False, detail="no person")
    rig.run_until(89)
    assert rig.of(AwayAlert) == []  # 59 s away: no alert yet
    rig.run_until(500)
    assert [(e.t, e.away_s) for e in rig.of(AwayAlert)] == [(90, 60)]
    seen(rig, True)
    assert [k for k in log(store, rig) if k[0] in ("person_lost", "away_alert", "person_back")] == [
        ("person_lost", "camera: no person"),
        ("away_alert", "60"),
        ("person_back", "camera"),
    ]


def test_back_before_the_site_time_raises_no_alert_and_a_second_absence_counts_afresh():
    rig = started(watching=WATCH)
    rig.at(30)
    seen(rig, False)
    rig.at(80)
    seen(rig, True)  # back after 50 s
    rig.at(82)
    seen(rig, False)
    rig.run_until(141)
    assert rig.of(AwayAlert) == []  # 59 s into the second absence
    rig.run_until(142)
    assert [e.t for e in rig.of(AwayAlert)] == [142]


def test_staff_buttons_are_presence_reports_from_staff():
    rig = started(watching=WATCH)
    rig.at(30)
    rig.session.person_lost("ward station, nurse.kim")
    assert not rig.session.snapshot().person_present
    rig.run_until(90)
    assert len(rig.of(AwayAlert)) == 1  # staff-reported too: the station closes what staff caused
    rig.session.person_back("clinician screen")
    assert [e.source for e in rig.of(PersonBack)] == [PresenceSource.STAFF]


def test_while_away_the_screen_has_no_go_on_line():
    rig = started(watching=Watching(60, None))
    rig.run_until(85)  # Q1: both attempts ran out; "Let us go on" during the gap
    assert rig.session.snapshot().interlude == "not_answered"
    seen(rig, False)
    assert rig.session.snapshot().interlude is None  # the one message is the away notice
    rig.run_until(400)
    assert rig.session.current_item.id == "feeding"  # the gap is frozen too: Q2 waits
    seen(rig, True)
    rig.run_until(rig.session.now() + 15)
    assert rig.session.current_item.id == "bathing"


def test_after_two_unanswered_questions_the_kiosk_waits_for_a_touch(tmp_path):
    store = Store.open(tmp_path / "data")
    rig = started(store=store, watching=WATCH)
    rig.run_until(10_000)  # nobody there and no presence source: at most 2 questions time out
    assert [e.item_id for e in rig.of(QuestionNotAnswered)] == ["feeding", "bathing"]
    assert [e.count for e in rig.of(Unattended)] == [2]
    snap = rig.session.snapshot()
    assert snap.unattended and snap.attempt is None and snap.interlude is None
    messages = [p.key for p in rig.of(Prompt) if p.kind == "message"]
    assert messages[-2:] == ["not_answered", "unattended"]  # no "Let us go on" after the second
    assert rig.of(Prompt)[-1].text == "Are you still there? Touch the screen to go on."
    assert not rig.session.listening
    assert ("unattended", "2") in log(store, rig)
    assert rig.session.timers.timer is None  # nothing pending: no question opens by itself


def test_a_voice_does_not_go_on_a_touch_does_and_the_run_starts_again():
    rig = started(watching=WATCH)
    rig.run_until(10_000)
    rig.session.handle(ChannelInput(Channel.VOICE, option=1, detail="yes"))
    assert rig.of(InputIgnored)[-1].reason is IgnoreReason.WAITING_FOR_TOUCH
    rig.session.clinician_continue()  # the ward's Continue: the kiosk still waits for the touch
    assert rig.session.snapshot().unattended and rig.session.current_attempt is None
    rig.session.handle(ChannelInput(Channel.TOUCH, option=1, detail="screen"))
    assert [e.channel for e in rig.of(UnattendedEnded)] == [Channel.TOUCH]
    assert rig.session.current_item.id == "grooming" and rig.session.current_attempt == 1
    assert rig.of(AttemptOpened)[-1].t == 10_000
    rig.run_until(10_060)  # grooming unanswered: one in the new run, so the kiosk goes on
    assert rig.session.current_item.id == "grooming" and not rig.session.snapshot().unattended
    rig.run_until(10_075)
    assert (rig.session.current_item.id, rig.session.current_attempt) == ("dressing", 1)
    rig.run_until(10_135)  # dressing too: two in a row again
    assert rig.session.snapshot().unattended and len(rig.of(Unattended)) == 2


def test_an_answer_breaks_the_run():
    rig = started(watching=WATCH)
    rig.run_until(85)  # Q1 not answered
    rig.run_until(100)  # Q2 opens at 100
    rig.answer(2)
    rig.run_until(1000)
    assert rig.of(Unattended) and rig.of(Unattended)[0].t > 200  # Q3 and Q4 unanswered, not Q1 and Q3


def test_away_while_waiting_one_message_and_back_says_the_wait_again():
    rig = started(watching=WATCH)
    rig.run_until(10_000)
    seen(rig, False)
    assert rig.session.snapshot().unattended
    seen(rig, True)
    assert rig.of(Prompt)[-1].key == "unattended"  # said again to whoever came
    rig.command(Command.PAUSE)
    rig.answer(1)  # paused: a touch on the answer does not go on
    assert rig.session.snapshot().unattended
    rig.command(Command.PAUSE)  # resume
    assert rig.of(Prompt)[-1].key == "unattended"
    rig.session.handle(ChannelInput(Channel.REMOTE, option=3, detail="button 3"))
    assert not rig.session.snapshot().unattended


def test_the_last_question_unanswered_waits_then_a_touch_finishes():
    rig = started(watching=Watching(None, 1))
    for item in QUESTIONNAIRE.items:
        rig.run_until(rig.session.now() + 1000)
        assert rig.session.snapshot().unattended and rig.session.current_item.id == item.id
        assert not rig.session.finished
        rig.answer(1)  # the touch goes on (the next question, after the last the summary)
    assert rig.of(Finished) and len(rig.of(Unattended)) == len(QUESTIONNAIRE.items)


def test_without_watching_nothing_changes():
    rig = started()
    rig.run_until(100_000)
    assert rig.session.finished and rig.of(Unattended) == []
