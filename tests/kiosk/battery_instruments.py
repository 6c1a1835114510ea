"""A short second instrument for battery tests, written in today's format: the Barthel file cut
to its first two items under another id, title and band set (so the tests need no other
helper's instruments)."""

from __future__ import annotations

from pathlib import Path

import yaml

from kiosk.core.questionnaire import Questionnaire, load_questionnaire
from kiosk.core.questionnaire.loading import bundled_path

MINI_TITLE = {"en": "Two questions", "es": "Dos preguntas", "fr": "Deux questions", "de": "Zwei Fragen"}


def write_mini(directory: Path, *, id: str = "mini", title: str | None = None) -> Path:
    """Write the short instrument into ``directory`` and return its path (``title``: its English
    title instead of "Two questions")."""
    data = yaml.safe_load(Path(bundled_path("barthel.yaml")).read_text(encoding="utf-8"))
    data["id"] = id
    data["title"] = dict(MINI_TITLE) | ({"en": title} if title else {})
    data["items"] = data["items"][:2]
    data.pop("code", None)
    data["total_code"] = {"system": "urn:kiosk-test", "code": f"{id}-total", "display": "Two questions total"}
    for item in data["items"]:
        item.pop("code", None)
        for option in item.get("options", []):
            option.pop("code", None)
    top = max(sum(max(o["points"] for o in item["options"]) for item in data["items"]), 0)
    data["bands"] = {
        "default": "all",
        "sets": {"all": {"source": "test", "ranges": [{"id": "any", "min": 0, "max": top, "label": MINI_TITLE}]}},
    }
    path = directory / f"{id}.yaml"
    path.write_text(yaml.safe_dump(data, allow_unicode=True, sort_keys=False), encoding="utf-8")
    return path


def load_mini(directory: Path) -> Questionnaire:
    """The short instrument, loaded as the kiosk loads any file."""
    return load_questionnaire(write_mini(directory))
