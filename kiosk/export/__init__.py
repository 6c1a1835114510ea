"""Exports of stored sessions a hospital and its researchers can take as they are.

- :mod:`kiosk.export.result`: what every export states (answers after a clinician's review,
  totals recomputed from the option numbers, complete or not, signed off or not) and who exports
  (:class:`ExportSite`: the site, the kiosk, the site's FHIR systems and canonical URL).
- :mod:`kiosk.export.fhir`: FHIR R4 — a Questionnaire per language with translations, the
  QuestionnaireResponse, the total as an Observation; its docstring gives each choice and the
  part of R4 it follows. :mod:`kiosk.export.provenance`: each staff change as a Provenance.
  :mod:`kiosk.export.bundle`: transaction Bundles (the kiosk's and the station's, one code path).
- :mod:`kiosk.export.tables`: CSV for researchers, long and wide, ids that stay text.

Never a total for an incomplete result: a partial sum is only ever shown apart, as the points of
the answered items. The station passes the session's :class:`kiosk.core.review.Review`; the kiosk on
its own exports results as unreviewed. Every function takes the questionnaire and the identity
(:class:`ExportSite`) it is given, and reads no file or configuration.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from basis.lazy import lazy_names
from kiosk.config import site_from_config
from kiosk.core.site import ExportSite, export_identity, site_from_identity
from kiosk.export.result import (  # eager: `result` is both this module and its function
    PRACTICE_CHECKS,
    TOTAL_LINK,
    ExportError,
    PracticeOutcome,
    Result,
    practice_outcome,
    practice_outcomes,
    questionnaire_version,
    rescore,
    result,
    results,
    write_export,
    write_json,
    write_private,
)

if TYPE_CHECKING:
    from kiosk.export.bundle import Described, bundle_of, questionnaire_bundle, transaction_bundle
    from kiosk.export.fhir import (
        ITEM_WEIGHT,
        ORDINAL_VALUE,
        SIGNATURE,
        TRANSLATION,
        WORDING,
        fhir_device,
        fhir_questionnaire,
        fhir_response,
        practitioner,
        questionnaire_canonical,
        response_status,
    )
    from kiosk.export.provenance import REPLACED_ANSWER, fhir_provenances
    from kiosk.export.tables import CSV_COLUMNS, ID_TAGS, csv_text, result_rows, wide_columns, wide_csv_text, wide_rows
    from kiosk.export.total import fhir_total, observation_status

#: each public name -> the module that defines it: imported on first use, so the kiosk's first
#: screen (which needs only kiosk.export.result, imported above) does not wait for FHIR, bundles and CSV
_MODULES: dict[str, str] = {
    "CSV_COLUMNS": "kiosk.export.tables",
    "Described": "kiosk.export.bundle",
    "ID_TAGS": "kiosk.export.tables",
    "ITEM_WEIGHT": "kiosk.export.fhir",
    "ORDINAL_VALUE": "kiosk.export.fhir",
    "REPLACED_ANSWER": "kiosk.export.provenance",
    "SIGNATURE": "kiosk.export.fhir",
    "TRANSLATION": "kiosk.export.fhir",
    "WORDING": "kiosk.export.fhir",
    "bundle_of": "kiosk.export.bundle",
    "csv_text": "kiosk.export.tables",
    "result_rows": "kiosk.export.tables",
    "wide_rows": "kiosk.export.tables",
    "fhir_device": "kiosk.export.fhir",
    "fhir_provenances": "kiosk.export.provenance",
    "fhir_questionnaire": "kiosk.export.fhir",
    "fhir_response": "kiosk.export.fhir",
    "fhir_total": "kiosk.export.total",
    "observation_status": "kiosk.export.total",
    "practitioner": "kiosk.export.fhir",
    "questionnaire_bundle": "kiosk.export.bundle",
    "questionnaire_canonical": "kiosk.export.fhir",
    "response_status": "kiosk.export.fhir",
    "transaction_bundle": "kiosk.export.bundle",
    "wide_columns": "kiosk.export.tables",
    "wide_csv_text": "kiosk.export.tables",
}

__all__ = [
    "CSV_COLUMNS",
    "ID_TAGS",
    "ITEM_WEIGHT",
    "ORDINAL_VALUE",
    "PRACTICE_CHECKS",
    "SIGNATURE",
    "TOTAL_LINK",
    "TRANSLATION",
    "WORDING",
    "REPLACED_ANSWER",
    "Described",
    "bundle_of",
    "fhir_provenances",
    "practitioner",
    "ExportError",
    "ExportSite",
    "PracticeOutcome",
    "Result",
    "csv_text",
    "result_rows",
    "wide_rows",
    "export_identity",
    "fhir_device",
    "fhir_questionnaire",
    "fhir_response",
    "fhir_total",
    "observation_status",
    "practice_outcome",
    "practice_outcomes",
    "questionnaire_bundle",
    "questionnaire_canonical",
    "questionnaire_version",
    "rescore",
    "response_status",
    "result",
    "results",
    "site_from_config",
    "site_from_identity",
    "transaction_bundle",
    "wide_columns",
    "wide_csv_text",
    "write_export",
    "write_json",
    "write_private",
]


__getattr__, __dir__ = lazy_names(globals(), _MODULES, __all__)
