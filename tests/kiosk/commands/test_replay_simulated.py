"""`kiosk replay --data-dir` stores simulated sessions (issue 10 part 1): a replay killed half-way
leaves nothing the real kiosk offers -- not to a patient, not even to staff -- and `kiosk results`
says which sessions were simulated."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from kiosk.commands.results import main as results_main
from kiosk.store.database import Store

ROOT = Path(__file__).resolve().parents[3]

#: the real `kiosk replay` main; its engine stops the world after the third answer, like a kill
#: arriving while the scripted patient is half-way
KILLED_REPLAY = textwrap.dedent("""
    import sys
    import qos
    from kiosk.commands import replay

    class HalfWay(qos.Engine):
        answers = 0
        def update(self, t, set=None, emit=None):
            result = super().update(t, set=set, emit=emit)
            if set and (set.get("FirstAttemptAnswered") or set.get("SecondAttemptAnswered")):
                HalfWay.answers += 1
                if HalfWay.answers == 4:  # the operation after the third answer: three are committed
                    print("HALFWAY", flush=True)
                    sys.stdin.read()
            return result

    qos.Engine = HalfWay
    sys.exit(replay.main(sys.argv[1:]))
""")


@pytest.mark.slow  # a subprocess
def test_a_killed_replay_leaves_a_simulated_session_the_kiosk_never_offers(tmp_path, capsys):
    data = tmp_path / "data"
    config = tmp_path / "config.yaml"
    config.write_text(f"data_dir: {data}\n")
    child = subprocess.Popen(
        [
            sys.executable,
            "-c",
            KILLED_REPLAY,
            str(ROOT / "recordings/patients/barthel2.yaml"),
            "--data-dir",
            str(data),
            "--config",
            str(config),
        ],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
        cwd=ROOT,
    )
    try:
        assert child.stdout.readline().strip() == "HALFWAY"
        os.kill(child.pid, signal.SIGKILL)
    finally:
        child.wait(timeout=60)
    with Store.open(data) as kiosk:
        assert kiosk.unfinished_sessions() == []  # staff are not offered it either
        (summary,) = kiosk.sessions()
        assert summary.simulated and summary.status == "interrupted" and summary.answered == 3
    assert results_main(["--data-dir", str(data)]) == 0
    (line,) = capsys.readouterr().out.splitlines()
    assert "TB-0002" in line and "interrupted, simulated" in line
    assert results_main([summary.id, "--data-dir", str(data)]) == 0
    assert "simulated (a scripted patient, kiosk replay)" in capsys.readouterr().out.splitlines()[0]
