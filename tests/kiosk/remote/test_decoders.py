"""The pure decoders: whatever bytes a remote sends, no crash and no press that was not sent."""

from __future__ import annotations

import logging

from hypothesis import given, settings
from hypothesis import strategies as st

from kiosk.core.channels import Command
from kiosk.remote.decoders import LineDecoder, ReportDecoder, ReportMatch
from kiosk.remote.profiles import load_profiles

SERIAL = load_profiles().serial[0]
LINES = dict(SERIAL.lines)  # "BTN 1" -> 1, "BTN R" -> repeat, ...
FRAMES = [f"{text}\n".encode() for text in LINES]

HID = load_profiles().hid[0]


def decode_lines(chunks: list[bytes], max_line: int = 64) -> list:
    decoder = LineDecoder(LINES, max_line=max_line, on_drop=lambda reason: None)
    return [press for chunk in chunks for press in decoder.feed(chunk)]


def split_at(data: bytes, cuts: list[int]) -> list[bytes]:
    points = sorted({min(c, len(data)) for c in cuts})
    return [data[a:b] for a, b in zip([0] + points, points + [len(data)])]


# --- serial line decoder ---------------------------------------------------------------------


def test_frames_split_anywhere_decode_to_their_buttons():
    data = b"BTN 1\nBTN R\r\nBTN 4\n"
    for cut in range(len(data) + 1):
        presses = decode_lines([data[:cut], data[cut:]])
        assert [p.button for p in presses] == [1, Command.REPEAT, 4]


def test_junk_is_dropped_with_a_reason_and_the_next_line_decodes(caplog):
    decoder = LineDecoder(LINES, label="serial test")
    with caplog.at_level(logging.WARNING, logger="kiosk.remote"):
        presses = decoder.feed(b"\xff\xfeBTN 2\nBTN 9\nBTN 3\n")
    assert [p.button for p in presses] == [3]
    assert "not UTF-8" in caplog.text and "unknown line 'BTN 9'" in caplog.text


def test_junk_without_newline_spoils_only_the_line_it_is_on():
    # resync happens at a newline: "xxBTN 1" is not a frame, the following "BTN 2" is
    assert [p.button for p in decode_lines([b"xxBTN 1\nBTN 2\n"])] == [2]


def test_over_long_line_is_dropped_and_decoding_resumes_after_its_newline(caplog):
    decoder = LineDecoder(LINES, max_line=16)
    with caplog.at_level(logging.WARNING, logger="kiosk.remote"):
        # the long line ends in a valid frame; it must not be taken for one
        presses = [p for chunk in (b"A" * 10, b"B" * 10, b"BTN 1", b"\nBTN 4\n") for p in decoder.feed(chunk)]
    assert [p.button for p in presses] == [4]
    assert "longer than 16 bytes" in caplog.text


def test_blank_lines_and_crlf_are_accepted():
    assert [p.button for p in decode_lines([b"\n\r\n  BTN 2 \r\n\n"])] == [2]


junk_line = (
    st.binary(max_size=80)
    .filter(lambda b: b"\n" not in b)
    .filter(lambda b: b.strip(b" \t\r") not in {text.encode() for text in LINES})
)


@settings(max_examples=300)
@given(
    items=st.lists(st.one_of(st.sampled_from(FRAMES), junk_line.map(lambda b: b + b"\n")), max_size=30),
    cuts=st.lists(st.integers(min_value=0, max_value=3000), max_size=20),
)
def test_exactly_the_valid_frames_come_out_of_frames_interleaved_with_junk(items, cuts):
    data = b"".join(items)
    presses = decode_lines(split_at(data, cuts))
    sent = [LINES[item[:-1].decode()] for item in items if item in FRAMES]
    assert [p.button for p in presses] == sent


@settings(max_examples=500)
@given(data=st.binary(max_size=400), cuts=st.lists(st.integers(min_value=0, max_value=400), max_size=10))
def test_random_bytes_only_yield_buttons_whose_exact_frame_was_sent(data, cuts):
    presses = decode_lines(split_at(data, cuts), max_line=32)
    lines = data.split(b"\n")[:-1]  # complete lines only: a press needs its newline
    for press in presses:
        assert press.frame.encode() in {line.strip(b" \t\r") for line in lines}
    assert len(presses) <= data.count(b"\n")


@given(data=st.binary(max_size=300), cuts=st.lists(st.integers(min_value=0, max_value=300), max_size=10))
def test_how_reads_split_the_stream_never_changes_what_is_decoded(data, cuts):
    assert decode_lines(split_at(data, cuts)) == decode_lines([data])


# --- HID report decoder ----------------------------------------------------------------------


def hid_decoder(debounce: float = 0.03) -> ReportDecoder:
    return ReportDecoder(HID.buttons, report_id=HID.report_id, debounce=debounce, on_drop=lambda r: None)


def test_a_held_button_is_one_press():
    decoder = hid_decoder()
    reports = [bytes([1, 0x04, 0])] * 20 + [bytes([1, 0, 0])]
    presses = [p for i, r in enumerate(reports) for p in decoder.feed(r, i * 0.05)]
    assert [p.button for p in presses] == [3]


def test_contact_bounce_within_the_debounce_time_is_one_press():
    decoder = hid_decoder(debounce=0.03)
    timeline = [(0.000, 0x01), (0.004, 0x00), (0.008, 0x01), (0.500, 0x00), (0.505, 0x01), (0.510, 0x00)]
    presses = [p for t, bits in timeline for p in decoder.feed(bytes([1, bits, 0]), t)]
    assert [p.button for p in presses] == [1]


def test_two_real_presses_are_two():
    decoder = hid_decoder()
    timeline = [(0.0, 0x02), (0.2, 0x00), (0.4, 0x02), (0.6, 0x00)]
    assert [p.button for t, bits in timeline for p in decoder.feed(bytes([1, bits, 0]), t)] == [2, 2]


def test_buttons_pressed_together_each_count_and_commands_decode():
    decoder = hid_decoder()
    presses = decoder.feed(bytes([1, 0x41, 0x01]), 0.0)
    assert {p.button for p in presses} == {1, Command.CALL_DOCTOR, Command.VOLUME_UP}


def test_unknown_reports_are_ignored_without_changing_state(caplog):
    decoder = ReportDecoder(HID.buttons, report_id=1, debounce=0.0)
    with caplog.at_level(logging.INFO, logger="kiosk.remote"):
        assert decoder.feed(bytes([1, 0x08, 0]), 0.0)[0].button == 4
        assert decoder.feed(bytes([2, 0x00, 0]), 0.1) == []  # another report id
        assert decoder.feed(bytes([1]), 0.2) == []  # too short
        assert decoder.feed(bytes([1, 0x08, 0]), 0.3) == []  # still held: the unknown ones did not release it
    assert "another report id" in caplog.text and "1-byte report" in caplog.text


def test_value_matches_decode_one_code_per_report():
    decoder = ReportDecoder(
        {Command.VOLUME_UP: ReportMatch(byte=1, value=0xE9), Command.VOLUME_DOWN: ReportMatch(byte=1, value=0xEA)},
        report_id=2,
    )
    timeline = [(0.0, 0xE9), (0.1, 0x00), (0.2, 0xEA), (0.3, 0xE9)]
    presses = [p.button for t, code in timeline for p in decoder.feed(bytes([2, code]), t)]
    assert presses == [Command.VOLUME_UP, Command.VOLUME_DOWN, Command.VOLUME_UP]


@settings(max_examples=500)
@given(st.lists(st.tuples(st.binary(max_size=8), st.floats(min_value=0, max_value=0.2)), max_size=40))
def test_random_reports_only_yield_buttons_held_in_the_report_and_released_before(reports):
    decoder = hid_decoder()
    now = 0.0
    held_before: dict = {}
    for report, step in reports:
        now += step
        presses = decoder.feed(report, now)
        known = len(report) >= 3 and report[0] == HID.report_id
        for press in presses:
            match = HID.buttons[press.button]
            assert known and match.held(report) and not held_before.get(press.button, False)
        assert len({p.button for p in presses}) == len(presses)
        if known:
            held_before = {button: match.held(report) for button, match in HID.buttons.items()}


@given(st.lists(st.integers(min_value=0, max_value=127), max_size=40))
def test_well_spaced_reports_give_exactly_one_press_per_rising_edge(bit_states):
    decoder = hid_decoder(debounce=0.03)
    by_mask = {m.mask: button for button, m in HID.buttons.items() if m.byte == 1}
    previous = 0
    for i, bits in enumerate(bit_states):
        presses = {p.button for p in decoder.feed(bytes([1, bits, 0]), i * 0.1)}
        assert presses == {button for mask, button in by_mask.items() if bits & mask and not previous & mask}
        previous = bits
