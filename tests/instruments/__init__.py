"""Instruments written for the tests (not shipped): what the downstream code must handle besides
the Barthel."""

from pathlib import Path

HERE = Path(__file__).resolve().parent
#: four items of 2 and 3 options, totals 0-25, bands "normal" 0-10 and "suggests" 15-25
MOOD4 = HERE / "mood4.yaml"
#: a scripted patient answering MOOD4 (touch, voice, remote): total 20, band "suggests"
MOOD4_PATIENT = HERE / "mood4_patient.yaml"
