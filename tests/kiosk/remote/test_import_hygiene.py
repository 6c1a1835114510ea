"""The remote channel runs on background threads beside any front end: it never imports Textual."""

from __future__ import annotations

import subprocess
import sys

import pytest


@pytest.mark.slow  # a subprocess
def test_remote_and_devices_leave_textual_out():
    code = "import sys, kiosk.remote, kiosk.remote.hid, kiosk.commands.devices; print('textual' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"
