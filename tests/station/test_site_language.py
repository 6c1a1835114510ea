"""A site's own language (a words file in its site folder, kiosk.config.site_folder) reaches the
station: the station checks a captured definition's languages by their form and by every text
being there, not against the kiosk's shipped words, so a result in Italian is kept, not refused."""

from __future__ import annotations

import copy

import pytest

from kiosk.core.questionnaire import load_questionnaire
from kiosk.core.questionnaire.definition import canonical
from kiosk.core.questionnaire.loading import bundled_path
from station.checks import RowRefused, check_definition


def _with_italian(definition: dict) -> dict:
    """Every text of ``definition`` also in Italian (the English text, marked)."""
    found = copy.deepcopy(definition)

    def add(node):
        if isinstance(node, dict):
            if "en" in node and all(isinstance(v, str) for v in node.values()):
                node["it"] = f"[it] {node['en']}"
            for value in node.values():
                add(value)
        elif isinstance(node, list):
            for value in node:
                add(value)

    add(found)
    found["languages"] = [*found["languages"], "it"]
    return found


def test_a_definition_in_a_sites_own_language_is_taken():
    definition = _with_italian(canonical(load_questionnaire(bundled_path("barthel.yaml"))))
    q = check_definition(definition, "create.definition")
    assert "it" in q.languages
    assert q.title["it"].startswith("[it] ")


@pytest.mark.parametrize("code", ["Italian", "it_IT", "", "x", "it-"])
def test_a_language_that_is_no_code_is_refused_naming_it(code):
    definition = _with_italian(canonical(load_questionnaire(bundled_path("barthel.yaml"))))
    definition["languages"] = [*definition["languages"][:-1], code]
    with pytest.raises(RowRefused, match="create.definition.languages: must be language codes"):
        check_definition(definition, "create.definition")


def test_a_language_declared_without_its_texts_is_still_refused():
    definition = canonical(load_questionnaire(bundled_path("barthel.yaml")))
    definition["languages"] = [*definition["languages"], "it"]
    with pytest.raises(RowRefused, match="has no 'it' text"):
        check_definition(definition, "create.definition")
