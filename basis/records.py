"""``@record``: a dataclass whose generated methods, but for ``__init__``, are written once here.

On Python 3.11 :func:`dataclasses.dataclass` compiles every method it generates with ``exec``:
six for a frozen class (``__init__``, ``__repr__``, ``__eq__``, ``__hash__``, ``__setattr__``,
``__delattr__``). The kiosk declares about 130 value classes before its welcome, and making them
was about a fifth of its start (docs/startup.md). A record generates only ``__init__``; the others
are the shared functions below, which behave as the generated ones:

- the same repr (fields with ``repr=True``, recursion shown as ``...``);
- equality only between instances of the very same class, over the fields with ``compare=True``;
- the same hash (a frozen record hashes the tuple of its hashed fields; a mutable one is unhashable);
- frozen: a field cannot be assigned or deleted once ``__init__`` has set it, and an instance of
  the record class itself takes no other attribute (:class:`dataclasses.FrozenInstanceError`, as a
  frozen dataclass). ``__post_init__`` sets a field with ``object.__setattr__``, as there.

A class that writes one of them itself keeps its own, as with ``dataclass``. Everything else is a
plain dataclass: :func:`dataclasses.fields`, :func:`~dataclasses.replace`, :func:`~dataclasses.asdict`,
``field(...)``, ``__match_args__``, copying and pickling (a frozen record is a dataclass made with
``frozen=False`` whose ``__setattr__`` refuses: its generated ``__init__`` assigns through it, so
making an instance costs about twice a frozen dataclass's, a microsecond more for five fields).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from operator import attrgetter
from reprlib import recursive_repr
from typing import Any, TypeVar, cast, dataclass_transform, overload

_T = TypeVar("_T", bound=type)


class _Shape:
    """What the shared methods read of one record class, worked out on first use."""

    __slots__ = ("compared", "hashed", "shown")

    def __init__(self, cls: type) -> None:
        fields = dataclasses.fields(cls)
        self.compared = _tuple_of([f.name for f in fields if f.compare])
        self.hashed = _tuple_of([f.name for f in fields if (f.compare if f.hash is None else f.hash)])
        self.shown = tuple(f.name for f in fields if f.repr)


#: a record class (or a subclass of one) -> its shape
_SHAPES: dict[type, _Shape] = {}
#: the classes declared frozen with @record (their own instances take no new attribute)
_FROZEN: set[type] = set()


def _tuple_of(names: list[str]) -> Callable[[Any], tuple[Any, ...]]:
    """A function giving an object's values of ``names`` as a tuple (the generated methods' tuple)."""
    if not names:
        return lambda obj: ()
    if len(names) == 1:
        one = attrgetter(names[0])
        return lambda obj: (one(obj),)
    return attrgetter(*names)


def _shape(cls: type) -> _Shape:
    shape = _SHAPES.get(cls)
    if shape is None:
        shape = _SHAPES[cls] = _Shape(cls)
    return shape


def is_frozen(cls: type) -> bool:
    """Whether ``cls`` was declared a frozen record (``@record``, not ``@record(frozen=False)``)."""
    return cls in _FROZEN


@recursive_repr()
def _repr(self: Any) -> str:
    shown = ", ".join(f"{name}={getattr(self, name)!r}" for name in _shape(type(self)).shown)
    return f"{type(self).__qualname__}({shown})"


def _eq(self: Any, other: object) -> bool:
    if other.__class__ is self.__class__:
        values = _shape(type(self)).compared
        return values(self) == values(other)
    return NotImplemented


def _hash(self: Any) -> int:
    return hash(_shape(type(self)).hashed(self))


def _setattr(self: Any, name: str, value: Any) -> None:
    cls = type(self)
    if name in cls.__record_fields__:
        if name in self.__dict__:  # set by __init__ already: frozen
            raise dataclasses.FrozenInstanceError(f"cannot assign to field {name!r}")
    elif cls in _FROZEN:
        raise dataclasses.FrozenInstanceError(f"cannot assign to field {name!r}")
    object.__setattr__(self, name, value)


def _delattr(self: Any, name: str) -> None:
    cls = type(self)
    if name in cls.__record_fields__ or cls in _FROZEN:
        raise dataclasses.FrozenInstanceError(f"cannot delete field {name!r}")
    object.__delattr__(self, name)


def _make(cls: _T, frozen: bool, kw_only: bool) -> _T:
    own = cls.__dict__
    # as dataclass decides: a __hash__ the class wrote counts, the None that writing __eq__ leaves does not
    explicit_hash = "__hash__" in own and not (own["__hash__"] is None and "__eq__" in own)
    if "__repr__" not in own:
        cls.__repr__ = _repr  # type: ignore[assignment]  # the shared method, set on the class
    if "__eq__" not in own:
        cls.__eq__ = _eq  # type: ignore[assignment]  # the shared method, set on the class
    if not explicit_hash:
        cls.__hash__ = _hash if frozen else None  # type: ignore[assignment]  # as dataclass(eq=True)
    for base in cls.__mro__[1:-1]:  # as dataclass refuses mixing frozen and mutable along a hierarchy
        if "__record_fields__" in base.__dict__ and (base in _FROZEN) != frozen:
            kind = "frozen" if frozen else "non-frozen"
            raise TypeError(f"cannot inherit {kind} record {cls.__name__} from {base.__name__}")
    if frozen:
        if "__setattr__" in own or "__delattr__" in own:  # as dataclass(frozen=True) refuses
            raise TypeError(f"cannot overwrite __setattr__ or __delattr__ of frozen record {cls.__name__}")
        cls.__setattr__ = _setattr  # type: ignore[assignment]  # the shared method, set on the class
        cls.__delattr__ = _delattr  # type: ignore[assignment]  # the shared method, set on the class
        _FROZEN.add(cls)
    made: Any = dataclasses.dataclass(cls, kw_only=kw_only, repr=False, eq=False)
    # the names frozen __setattr__ guards, read on every assignment (a plain subclass inherits them)
    made.__record_fields__ = frozenset(f.name for f in dataclasses.fields(made))
    return cast(_T, made)


@overload
def record(cls: _T, /) -> _T: ...
@overload
def record(*, frozen: bool = True, kw_only: bool = False) -> Callable[[_T], _T]: ...
@dataclass_transform(frozen_default=True, field_specifiers=(dataclasses.field, dataclasses.Field))
def record(cls: _T | None = None, /, *, frozen: bool = True, kw_only: bool = False) -> Any:
    """A dataclass, frozen unless ``frozen=False``, with the shared methods (see the module).
    ``@record`` and ``@record(frozen=False)``."""
    if cls is None:
        return lambda c: _make(c, frozen, kw_only)
    return _make(cls, frozen, kw_only)
