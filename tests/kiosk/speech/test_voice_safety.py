"""Issue 33's safety rules end to end with real audio: espeak-ng speaks, the audio pipeline and
pocketsphinx hear it under the prompt's grammar, and the real session acts (or does not).

A spoken no to "Is that right?" stores nothing, whatever way it is said.
"""

from __future__ import annotations

import pytest

from kiosk.core.session import AnswerNotConfirmed, Prompt

from .voice_kiosk import VoiceKiosk, backends

NO_SAID = ["no no", "that's not what I said", "not really", "nope", "no I said two", "that's wrong"]


@pytest.mark.parametrize("backend", backends("en"))
@pytest.mark.parametrize("said", NO_SAID)
def test_a_spoken_no_to_is_that_right_stores_nothing(backend, spoken, said):
    kiosk = VoiceKiosk(backend)
    kiosk.to_question("feeding")
    kiosk.say(spoken("independent"))
    assert [e for e in kiosk.events if isinstance(e, Prompt)][-1].kind == "confirm"
    asked = len(kiosk.inputs)
    kiosk.say(spoken(said))
    taken = [i for i in kiosk.inputs[asked:] if i.option == 1 and not i.needs_confirmation]
    assert taken == [] and kiosk.session.answers == {}
    # each way of saying no is in the grammar: heard as the No it is, the question is asked again
    assert [i.option for i in kiosk.inputs[asked:]] == [2]
    assert [e.why for e in kiosk.events if isinstance(e, AnswerNotConfirmed)] == ["declined"]
