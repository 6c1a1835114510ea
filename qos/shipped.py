"""Where the shipped models are: a module of its own, importing nothing, so that the parser (a site's
model may ``import "clarc.roqme"``) and the bundled models' loader share it without a cycle and a
kept model loads without lark."""

from __future__ import annotations

from pathlib import Path

#: the bundled models' folder (the package is installed as files, never zipped; importlib.resources
#: would cost a start zipfile and its readers for nothing)
MODELS = Path(__file__).parent / "models"
