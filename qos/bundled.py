"""The models shipped inside the package (``qos/models/NAME.roqme``), and loading a model by name
or path: apart from the package's ``__init__`` so that the trace module can load its model
without importing the package that lazily imports it.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from qos.errors import ModelError
from qos.shipped import MODELS

if TYPE_CHECKING:
    from qos.model import Model


def bundled_models() -> list[str]:
    """Names of the models shipped inside the package (``qos/models/NAME.roqme``)."""
    return sorted(entry.name[: -len(".roqme")] for entry in MODELS.iterdir() if entry.name.endswith(".roqme"))


def load_model(name_or_path: str | Path) -> Model:
    """Load a bundled model by name (``"clarc"``) or a ``.roqme`` file by path.

    Raises :class:`ModelError` with file, line and column when the model is malformed. A model
    that parsed is kept and read back on the next start (:mod:`qos.kept`): no lark, no parse.
    """
    from qos.kept import load_model_file_kept as load_model_file
    from qos.kept import parse_model_kept as parse_model

    text = str(name_or_path)
    if isinstance(name_or_path, Path) or text.endswith(".roqme") or "/" in text or "\\" in text:
        return load_model_file(name_or_path)
    if text not in bundled_models():
        raise ModelError(
            f"no bundled model named {text!r} (bundled: {', '.join(bundled_models())}); "
            "give a path to a .roqme file instead"
        )
    # bundled models may import each other
    return parse_model((MODELS / f"{text}.roqme").read_text(encoding="utf-8"), f"{text}.roqme", MODELS)
