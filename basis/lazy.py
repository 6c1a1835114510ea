"""Names a package imports on first use (PEP 562): a program that uses one part of a package does
not wait for the others to load."""

from __future__ import annotations

import importlib
from collections.abc import Callable, Iterable, Mapping
from typing import Any


def lazy_names(
    namespace: dict[str, Any], modules: Mapping[str, str], public: Iterable[str]
) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """A package's ``__getattr__`` and ``__dir__``: ``namespace`` is its ``globals()``, ``modules``
    maps each name imported on first use to the module defining it, ``public`` is its ``__all__``.
    A name, once imported, is kept in the namespace (no second lookup); an unknown one is the
    AttributeError Python gives."""
    listed = sorted(public)

    def __getattr__(name: str) -> Any:
        if name not in modules:
            raise AttributeError(f"module {namespace['__name__']!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(modules[name]), name)
        namespace[name] = value
        return value

    def __dir__() -> list[str]:
        return sorted(set(namespace) | set(listed))

    return __getattr__, __dir__
