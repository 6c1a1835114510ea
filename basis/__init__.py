"""What every layer of the project builds on and that imports nothing of ours: :func:`record`, the
dataclass the project declares its values with, and :func:`~basis.lazy.lazy_names`, a package's
names imported on first use."""

from basis.records import record

__all__ = ["record"]
