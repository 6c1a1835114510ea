"""A final line break is not part of a name, a time or a digest: Python's ``$`` matches before one,
so every pattern that guards what a kiosk or an operator sends must end at the real end."""

from __future__ import annotations

import pytest

from station.auth import AuthError, check_name
from station.checks import RowRefused, iso_time


@pytest.mark.parametrize("name", ["bed2\n", "dr.lopez\n", "ward3\r\n"])
def test_a_name_with_a_final_line_break_is_refused(name):
    with pytest.raises(AuthError, match="use 1-64 letters"):
        check_name(name, "kiosk")


def test_a_plain_name_is_kept():
    assert check_name("ward3-bed2", "kiosk") == "ward3-bed2"


def test_a_time_with_a_final_line_break_is_refused():
    assert iso_time("2026-11-26T09:30:00Z", "at") == "2026-11-26T09:30:00Z"
    with pytest.raises(RowRefused):
        iso_time("2026-11-26T09:30:00Z\n", "at")
