"""Presence is debounced on the frames' clock: a missed frame or a bend is no leaving, a glimpse no
return."""

from __future__ import annotations

from kiosk.camera import Presence


def feed(presence: Presence, frames):
    return [(t, change) for t, seen in frames if (change := presence.feed(t, seen)) is not None]


def test_a_person_counts_as_there_after_a_second_of_frames():
    presence = Presence(away_s=3.0, back_s=1.0)
    changes = feed(presence, [(i / 10, True) for i in range(15)])
    assert changes == [(1.0, True)] and presence.present is True


def test_short_misses_do_not_count_as_leaving():
    presence = Presence(away_s=3.0, back_s=1.0, present=True)
    frames = [(i / 10, i % 7 != 0) for i in range(100)]  # every seventh frame missed
    assert feed(presence, frames) == []


def test_leaving_counts_after_the_away_time_and_coming_back_after_the_back_time():
    presence = Presence(away_s=3.0, back_s=1.0, present=True)
    frames = [(t / 10, not 20 <= t < 80) for t in range(120)]  # gone from 2.0 s to 8.0 s
    assert feed(presence, frames) == [(5.0, False), (9.0, True)]


def test_a_glimpse_while_away_is_not_a_return():
    presence = Presence(away_s=3.0, back_s=1.0, present=False)
    frames = [(t / 10, 10 <= t < 15) for t in range(40)]
    assert feed(presence, frames) == [] and presence.present is False
