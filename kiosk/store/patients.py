"""Pseudonymous patient ids: the only way the store names a patient (never a name)."""

from __future__ import annotations

import re
import secrets

#: a pseudonymous patient id: letters, digits, '-' and '_', no spaces (so not "Ann Smith"); the
#: (?!\n) keeps a final line break out, which a bare '$' lets through (the script schema's pattern)
PATIENT_ID = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_-]{1,63}(?!\n)$")


def new_patient_id() -> str:
    """A fresh random pseudonymous patient id, e.g. ``P-7K3Q-X9M4-TB2H``.

    60 random bits: across a hospital's kiosks, a clash among a million patients has a chance of
    about 4 in 10 million (six characters, as before, gave 5 % among 10,000). Ids stored with the
    older, shorter form stay valid."""
    alphabet = "ABCDEFGHJKLMNPQRSTUVWXYZ23456789"  # no 0/O, 1/I: read aloud and typed by staff
    return "P-" + "-".join("".join(secrets.choice(alphabet) for _ in range(4)) for _ in range(3))
