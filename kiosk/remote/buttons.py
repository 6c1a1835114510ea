"""The buttons a remote can have, and how a press becomes a :class:`~kiosk.core.channels.ChannelInput`.

A button is either an answer number (1-4, printed on the remote and on the screen's answer
buttons) or a :class:`~kiosk.core.channels.Command` (repeat, pause, call doctor, volume up/down).
Device profiles name buttons the way a clinician would write them: ``1`` .. ``4``, ``repeat``,
``pause``, ``call_doctor``, ``volume_up``, ``volume_down``.
"""

from __future__ import annotations

from kiosk.core.channels import Channel, ChannelInput, Command

#: one button of a remote: an answer option number or a command
Button = int | Command

#: answer buttons a remote may carry (the Barthel index has at most four options per item)
ANSWER_BUTTONS = range(1, 5)


def parse_button(value: object) -> Button:
    """Read a button name from a profile (``3``, ``"3"``, ``"repeat"``...).

    Raises ``ValueError`` with a sentence listing the accepted names.
    """
    if isinstance(value, bool):  # YAML turns "yes"/"on" into booleans; never a button
        raise ValueError(f"{value!r} is not a button")
    text = str(value).strip()
    if text.isdigit():
        number = int(text)
        if number in ANSWER_BUTTONS:
            return number
        raise ValueError(f"answer buttons are 1 to 4, got {number}")
    try:
        return Command(text)
    except ValueError:
        names = ", ".join(c.value for c in Command)
        raise ValueError(f"{text!r} is not a button; use 1-4 or one of {names}") from None


def button_name(button: Button) -> str:
    """The profile name of a button, e.g. ``"3"`` or ``"call_doctor"``."""
    return button.value if isinstance(button, Command) else str(button)


def to_input(button: Button, detail: str) -> ChannelInput:
    """The channel input a press of ``button`` on a remote produces; ``detail`` is what was received."""
    if isinstance(button, Command):
        return ChannelInput(channel=Channel.REMOTE, command=button, detail=detail)
    return ChannelInput(channel=Channel.REMOTE, option=button, detail=detail)


#: the kiosk's own keys (channel KEYBOARD) and the button each stands for: answers 1-4, pause,
#: call doctor, repeat, and C for "Change my answer" (undo; backspace too, the key a keyboard user
#: reaches for to take something back). 5-9 are numbers too: under the explanation any number
#: starts, on a question they get the gentle "Please choose 1, 2 or 3". Letters work in either
#: case (the app looks a capital up by its small letter).
KIOSK_KEY_BUTTONS: dict[str, Button] = {
    "1": 1,
    "2": 2,
    "3": 3,
    "4": 4,
    "5": 5,
    "6": 6,
    "7": 7,
    "8": 8,
    "9": 9,
    "p": Command.PAUSE,
    "d": Command.CALL_DOCTOR,
    "r": Command.REPEAT,
    "c": Command.UNDO,
    "backspace": Command.UNDO,
}

#: keys the kiosk itself binds; a keyboard-emulating remote must not claim them, or one key press
#: would count twice (compared case-insensitively)
KIOSK_KEYS = frozenset(KIOSK_KEY_BUTTONS)
