"""A package's names imported on first use: each from the module named for it, once; an unknown
name is Python's own AttributeError."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from basis.lazy import lazy_names


def test_a_lazy_name_is_imported_from_its_module_on_first_use_and_kept():
    namespace = {"__name__": "pkg"}
    get, listing = lazy_names(namespace, {"dedent": "textwrap", "JSONDecoder": "json"}, ["dedent", "JSONDecoder", "x"])
    import textwrap

    assert get("dedent") is textwrap.dedent and namespace["dedent"] is textwrap.dedent
    assert listing() == ["JSONDecoder", "__name__", "dedent", "x"]
    with pytest.raises(AttributeError, match="module 'pkg' has no attribute 'nothing'"):
        get("nothing")


def test_the_packages_load_their_heavy_names_only_when_asked():
    code = (
        "import json, sys, qos, kiosk.export as e\n"
        "heavy = {'qos.engine', 'kiosk.export.fhir'}\n"
        "before = sorted(heavy & set(sys.modules))\n"
        "qos.Engine, e.fhir_response\n"
        "print(json.dumps([before, sorted(heavy & set(sys.modules)), 'Engine' in dir(qos)]))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert json.loads(out) == [[], ["kiosk.export.fhir", "qos.engine"], True]
