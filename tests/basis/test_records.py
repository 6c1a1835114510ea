"""``@record`` classes compare, hash and print as the dataclasses they were: only ``__init__`` (and a
frozen class's setattr/delattr) is generated per class, a start's import cost; the rest is written
once in basis.records."""

from __future__ import annotations

import copy
import dataclasses
import importlib
import pickle
import pkgutil
from dataclasses import field

import pytest
from hypothesis import given
from hypothesis import strategies as st

import basis
import fileio
import kiosk
import qos
import station
from basis import record
from basis.records import _eq, is_frozen


def _record_classes() -> list[type]:
    """Every class the project declares with @record (every module imported, not run as a script)."""
    found: dict[str, type] = {}
    for package in (basis, fileio, qos, kiosk, station):
        for info in pkgutil.walk_packages(package.__path__, package.__name__ + "."):
            if info.name.endswith("__main__") or ".migrations.versions" in info.name or info.name.endswith(".env"):
                continue
            module = importlib.import_module(info.name)
            for value in vars(module).values():
                if isinstance(value, type) and value.__dict__.get("__eq__") is _eq:
                    found[f"{value.__module__}.{value.__qualname__}"] = value
    return [found[name] for name in sorted(found)]


RECORDS = _record_classes()


def _twin(cls: type) -> type:
    """The stdlib dataclass with ``cls``'s fields and options: what ``cls`` was before."""
    specs = [(f.name, object, field(compare=f.compare, repr=f.repr, hash=f.hash)) for f in dataclasses.fields(cls)]
    twin = dataclasses.make_dataclass(cls.__name__, specs, frozen=is_frozen(cls))
    twin.__qualname__ = cls.__qualname__
    return twin


def _made(cls: type, values: dict[str, object]) -> object:
    """An instance of ``cls`` holding ``values`` (set as its __init__ would, without its checks)."""
    obj = object.__new__(cls)
    for name, value in values.items():
        object.__setattr__(obj, name, value)
    return obj


def test_the_project_declares_its_values_as_records():
    assert len(RECORDS) > 120


@pytest.mark.parametrize("cls", RECORDS, ids=lambda cls: f"{cls.__module__}.{cls.__qualname__}")
def test_a_record_class_behaves_as_the_dataclass_it_was(cls):
    twin = _twin(cls)
    names = [f.name for f in dataclasses.fields(cls)]
    values = {name: f"{name}-1" for name in names}
    one, same, ref = _made(cls, values), _made(cls, dict(values)), _made(twin, values)
    assert repr(one) == repr(ref)
    assert one == same and not one != same
    assert one.__eq__(ref) is NotImplemented  # another class is never equal
    for name in names:  # a field that takes part in comparing makes two records differ
        changed = _made(cls, {**values, name: "other"})
        assert (one == changed) == (ref == _made(twin, {**values, name: "other"}))
    if is_frozen(cls):
        assert hash(one) == hash(same) == hash(ref)
        with pytest.raises(dataclasses.FrozenInstanceError):
            setattr(one, names[0] if names else "x", "changed")
    else:
        assert cls.__hash__ is None or "__hash__" in vars(cls)  # unhashable, unless it says how


@record
class Point:
    x: int
    y: int = 0
    label: str = field(default="", compare=False)
    secret: str = field(default="", repr=False)
    tag: str = field(default="", hash=False)


#: the stdlib frozen dataclass with Point's fields and their compare/repr/hash options
PointAsDataclass = _twin(Point)


@record(frozen=False)
class Box:
    items: list[object] = field(default_factory=list)


@record
class Wrote:
    a: int

    def __repr__(self) -> str:
        return "mine"

    def __eq__(self, other: object) -> bool:
        return True

    def __hash__(self) -> int:
        return 7


@record
class Child(Point):
    z: int = 0


values = st.one_of(st.integers(), st.text(max_size=3), st.none(), st.floats(allow_nan=True))


@given(st.tuples(values, values, values, values, values), st.tuples(values, values, values, values, values))
def test_a_record_equals_hashes_and_prints_as_the_same_dataclass(a, b):
    ra, rb = Point(*a), Point(*b)  # type: ignore[arg-type]  # any values, as a dataclass takes them
    da, db = PointAsDataclass(*a), PointAsDataclass(*b)  # type: ignore[arg-type]
    assert repr(ra) == repr(da)
    assert (ra == rb) == (da == db) and (ra != rb) == (da != db) and (ra == ra) == (da == da)
    assert hash(ra) == hash(da)
    assert dataclasses.astuple(ra) == dataclasses.astuple(da) and dataclasses.asdict(ra) == dataclasses.asdict(da)


def test_a_mutable_record_is_unhashable_and_prints_itself_inside_itself_as_dots():
    box = Box()
    box.items.append(box)
    assert repr(box) == "Box(items=[...])"
    with pytest.raises(TypeError):
        hash(box)
    assert Box([1]) == Box([1]) != Box([2])


def test_a_record_keeps_what_its_class_wrote_and_a_subclass_compares_only_with_its_own_class():
    assert (repr(Wrote(1)), Wrote(1) == Wrote(2), hash(Wrote(1))) == ("mine", True, 7)
    assert Child(1) != Point(1) and Point(1) != Child(1)
    assert repr(Child(1, z=2)) == "Child(x=1, y=0, label='', tag='', z=2)"
    assert hash(Child(1, 2)) == hash((1, 2, "", 0))  # x, y, secret, z: label and tag are not hashed


def test_a_record_is_still_a_dataclass_for_replace_match_and_pickle():
    p = Point(1, 2, "a")
    assert dataclasses.replace(p, y=5) == Point(1, 5)
    assert Point.__match_args__ == ("x", "y", "label", "secret", "tag")
    assert pickle.loads(pickle.dumps(p)) == p and pickle.loads(pickle.dumps(p)).label == "a"
    with pytest.raises(dataclasses.FrozenInstanceError):
        del p.x


@record
class Defaults:
    a: int
    b: list[int] = field(default_factory=list)
    c: str = ""

    def __post_init__(self) -> None:
        if not self.c:
            object.__setattr__(self, "c", f"c{self.a}")  # as a frozen dataclass's __post_init__ does


class Plain(Defaults):
    """A plain subclass: it may carry attributes of its own, never change the record's fields."""


def test_a_frozen_record_refuses_every_change_once_made_as_a_frozen_dataclass_does():
    d = Defaults(1)
    assert (d.a, d.b, d.c) == (1, [], "c1")
    for change in (
        lambda: setattr(d, "a", 2),
        lambda: setattr(d, "c", "x"),
        lambda: setattr(d, "new", 1),
        lambda: delattr(d, "a"),
        lambda: delattr(d, "new"),
    ):
        with pytest.raises(dataclasses.FrozenInstanceError):
            change()
    assert (d.a, d.c, hasattr(d, "new")) == (1, "c1", False)
    p = Plain(2)
    p.note = "mine"  # type: ignore[attr-defined]  # a plain subclass's own attribute, as with dataclass
    with pytest.raises(dataclasses.FrozenInstanceError):
        p.a = 3  # type: ignore[misc]  # the record's field stays frozen
    for twin in (copy.copy(d), copy.deepcopy(d), pickle.loads(pickle.dumps(d)), dataclasses.replace(d)):
        assert twin == d and twin is not d
        with pytest.raises(dataclasses.FrozenInstanceError):
            twin.a = 5  # type: ignore[misc]  # a copy is as frozen as the original


def test_a_frozen_record_that_writes_its_own_setattr_is_refused_as_dataclass_refuses_it():
    class Mine:
        a: int

        def __setattr__(self, name: str, value: object) -> None:
            object.__setattr__(self, name, value)

    with pytest.raises(TypeError, match="__setattr__"):
        record(Mine)


def test_frozen_and_mutable_records_do_not_mix_in_one_hierarchy_as_with_dataclass():
    class Mutable(Point):  # a mutable record under a frozen one
        z: int = 0

    with pytest.raises(TypeError, match="non-frozen record Mutable from Point"):
        record(frozen=False)(Mutable)

    class Frozen(Box):  # a frozen record under a mutable one
        z: int = 0

    with pytest.raises(TypeError, match="frozen record Frozen from Box"):
        record(Frozen)
