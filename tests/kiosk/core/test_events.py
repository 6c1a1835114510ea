"""A session's events compare, hash and print as the frozen dataclasses they were: only their
``__init__`` is generated per class (a start's import cost), the rest is written once on
``SessionEvent``."""

from __future__ import annotations

import dataclasses

import pytest

from kiosk.core.session import events


def _event_classes() -> list[type]:
    found = [events.SessionEvent]
    for cls in found:
        found += cls.__subclasses__()
    return found


def _sample(cls: type, salt: int) -> list[object]:
    return [f"{field.name}-{salt}" if field.name != "t" else float(salt) for field in dataclasses.fields(cls)]


@pytest.mark.parametrize("cls", _event_classes(), ids=lambda cls: cls.__name__)
def test_an_event_behaves_as_the_generated_frozen_dataclass(cls):
    reference = dataclasses.make_dataclass(cls.__name__, [f.name for f in dataclasses.fields(cls)], frozen=True)
    one, same, other = cls(*_sample(cls, 1)), cls(*_sample(cls, 1)), cls(*_sample(cls, 2))
    ref_one, ref_same = reference(*_sample(cls, 1)), reference(*_sample(cls, 1))
    assert repr(one) == repr(ref_one)
    assert (one == same, one == other, one != same) == (ref_one == ref_same, False, False)
    assert hash(one) == hash(same) == hash(ref_one)
    assert one != ref_one and one.__eq__(ref_one) is NotImplemented  # another class is never equal
    assert len(_event_classes()) > 20
    with pytest.raises(dataclasses.FrozenInstanceError):
        one.t = 3.0  # type: ignore[misc]  # frozen, as before
    assert dataclasses.replace(one, t=5.0) == cls(*[5.0, *_sample(cls, 1)[1:]])
