"""`kiosk models install`: download, checksum, unpack and install, against a local HTTP server."""

from __future__ import annotations

import hashlib
import http.server
import json
import stat
import threading
import zipfile
from functools import partial

import pytest

from kiosk.speech import models
from kiosk.speech.asr import AsrUnavailable, PocketSphinxRecogniser, open_recogniser


class _QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args) -> None:  # keep the access log out of the CLI's stderr
        pass


@pytest.fixture
def models_served(tmp_path, monkeypatch):
    """A private models folder and a web server on 127.0.0.1 serving the test's files."""
    served = tmp_path / "www"
    served.mkdir()
    monkeypatch.setenv("KIOSK_MODELS_DIR", str(tmp_path / "models"))
    monkeypatch.setenv("KIOSK_WHISPER", "off")
    monkeypatch.delenv("KIOSK_VOSK_MODEL", raising=False)
    handler = partial(_QuietHandler, directory=str(served))
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    yield served, f"http://127.0.0.1:{server.server_address[1]}"
    server.shutdown()
    server.server_close()


def _model_zip(path, top="vosk-model-small-xx-0.1", extra=None, model=True):
    """A zip laid out like an official Vosk model archive (the files are not a working model)."""
    with zipfile.ZipFile(path, "w") as zf:
        if model:
            zf.writestr(f"{top}/am/final.mdl", b"acoustic model bytes")
            zf.writestr(f"{top}/conf/mfcc.conf", "--sample-frequency=16000\n")
            zf.writestr(f"{top}/graph/HCLr.fst", b"graph")
        else:
            zf.writestr(f"{top}/README", "hello")
        for name, data in (extra or {}).items():
            zf.writestr(name, data)
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _leftovers(tmp_path):
    root = tmp_path / "models" / "vosk"
    return sorted(p.name for p in root.iterdir()) if root.exists() else []


def test_install_with_sha256_unpacks_into_place_privately(models_served, tmp_path, capsys):
    served, base = models_served
    digest = _model_zip(served / "m.zip")
    status = models.main(["install", "es", "--url", f"{base}/m.zip", "--sha256", digest.upper()])
    assert status == 0
    target = tmp_path / "models" / "vosk" / "es"
    assert (target / "am" / "final.mdl").read_bytes() == b"acoustic model bytes"
    assert _leftovers(tmp_path) == ["es"]  # no download or unpack folder left behind
    assert stat.S_IMODE((tmp_path / "models" / "vosk").stat().st_mode) == 0o700
    assert models.find_model("es") == target and models.find_model("fr") is None
    assert f"installed the es model in {target}" in capsys.readouterr().out


def test_bad_checksum_is_one_clear_error_and_keeps_the_previous_model(models_served, tmp_path, capsys):
    served, base = models_served
    good = _model_zip(served / "good.zip")
    assert models.main(["install", "fr", "--url", f"{base}/good.zip", "--sha256", good]) == 0
    _model_zip(served / "evil.zip", extra={"vosk-model-small-xx-0.1/am/extra": b"tampered"})
    capsys.readouterr()
    assert models.main(["install", "fr", "--url", f"{base}/evil.zip", "--sha256", good]) == 1
    err = capsys.readouterr().err
    assert err.startswith(f"kiosk models: checksum mismatch for {base}/evil.zip: expected sha256 {good}")
    assert "nothing was installed" in err and "Traceback" not in err
    assert _leftovers(tmp_path) == ["fr"]
    assert not (tmp_path / "models" / "vosk" / "fr" / "am" / "extra").exists()


def test_official_model_is_checked_against_the_index_md5(models_served, tmp_path, monkeypatch):
    served, base = models_served
    _model_zip(served / "vosk-model-small-en-us-0.15.zip")
    md5 = hashlib.md5((served / "vosk-model-small-en-us-0.15.zip").read_bytes()).hexdigest()
    (served / "model-list.json").write_text(
        json.dumps([{"lang": "en-us", "name": "vosk-model-small-en-us-0.15", "md5": md5, "size": 1}])
    )
    monkeypatch.setitem(models.OFFICIAL_MODELS, "en", f"{base}/vosk-model-small-en-us-0.15.zip")
    path = models.install("en", index_url=f"{base}/model-list.json")
    assert models.is_vosk_model(path)
    (served / "model-list.json").write_text(json.dumps([{"name": "vosk-model-small-en-us-0.15", "md5": "0" * 32}]))
    with pytest.raises(models.SpeechModelError, match="checksum mismatch .* expected md5 0000"):
        models.install("en", index_url=f"{base}/model-list.json")
    (served / "model-list.json").write_text("[]")
    with pytest.raises(models.SpeechModelError, match="has no checksum for vosk-model-small-en-us-0.15"):
        models.install("en", index_url=f"{base}/model-list.json")
    assert _leftovers(tmp_path) == ["en"]


@pytest.mark.parametrize(
    "build,message",
    [
        (lambda p: _model_zip(p, extra={"../../escape.txt": b"x"}), "unsafe path '../../escape.txt'"),
        (lambda p: _model_zip(p, model=False), "does not contain a Vosk model"),
        (
            lambda p: (p.write_bytes(b"<html>not found</html>"), hashlib.sha256(p.read_bytes()).hexdigest())[1],
            "not a zip archive",
        ),
    ],
)
def test_bad_archives_install_nothing(models_served, tmp_path, build, message):
    served, base = models_served
    digest = build(served / "m.zip")
    with pytest.raises(models.SpeechModelError, match=message):
        models.install("es", url=f"{base}/m.zip", sha256=digest)
    assert _leftovers(tmp_path) == []
    assert not (tmp_path / "escape.txt").exists()


def test_download_errors_and_missing_checksum(models_served, capsys):
    _, base = models_served
    assert models.main(["install", "es", "--url", f"{base}/missing.zip", "--sha256", "ab"]) == 1
    assert f"cannot download {base}/missing.zip" in capsys.readouterr().err
    assert models.main(["install", "es", "--url", f"{base}/m.zip"]) == 1
    assert "needs --sha256" in capsys.readouterr().err
    assert models.main(["install", "pt"]) == 1
    assert "no official model known for language 'pt'" in capsys.readouterr().err


def test_list_and_recogniser_choice_follow_what_is_installed(models_served, tmp_path, capsys):
    served, base = models_served
    assert models.main(["list"]) == 0
    out = capsys.readouterr().out
    assert "en  pocketsphinx" in out and "es  none" in out
    assert isinstance(open_recogniser("en"), PocketSphinxRecogniser)
    with pytest.raises(AsrUnavailable, match="no speech model for language 'es'"):
        open_recogniser("es")
    digest = _model_zip(served / "m.zip")
    models.install("es", url=f"{base}/m.zip", sha256=digest)
    assert models.main(["list"]) == 0
    assert f"es  vosk          {tmp_path / 'models' / 'vosk' / 'es'}" in capsys.readouterr().out
    # the archive has the layout but not a working model: the real vosk refuses it, clearly
    with pytest.raises(AsrUnavailable, match="vosk model .* cannot be loaded"):
        open_recogniser("es")


def test_kiosk_vosk_model_points_at_a_model_or_a_folder_of_models(tmp_path, monkeypatch):
    monkeypatch.setenv("KIOSK_MODELS_DIR", str(tmp_path / "none"))
    monkeypatch.setenv("KIOSK_WHISPER", "off")
    shelf = tmp_path / "shelf"
    for name in ("vosk-model-small-fr-0.22", "vosk-model-small-en-us-0.15"):
        (shelf / name / "am").mkdir(parents=True)
        (shelf / name / "am" / "final.mdl").write_bytes(b"x")
        (shelf / name / "conf").mkdir()
    monkeypatch.setenv("KIOSK_VOSK_MODEL", str(shelf))
    assert models.find_model("fr") == shelf / "vosk-model-small-fr-0.22"
    assert models.find_model("en") == shelf / "vosk-model-small-en-us-0.15"
    assert models.find_model("es") is None
    monkeypatch.setenv("KIOSK_VOSK_MODEL", str(shelf / "vosk-model-small-fr-0.22"))
    assert models.find_model("fr") == shelf / "vosk-model-small-fr-0.22"
    assert models.find_model("en") is None  # a French model is not used for English


def test_configured_model_is_only_used_for_its_own_language(tmp_path, monkeypatch):
    monkeypatch.setenv("KIOSK_MODELS_DIR", str(tmp_path / "none"))
    monkeypatch.setenv("KIOSK_WHISPER", "off")
    monkeypatch.delenv("KIOSK_VOSK_MODEL", raising=False)
    spanish = tmp_path / "vosk-model-small-es-0.42"
    (spanish / "am").mkdir(parents=True)
    (spanish / "am" / "final.mdl").write_bytes(b"x")
    (spanish / "conf").mkdir()
    assert models.find_model("es", spanish) == spanish
    assert models.find_model("fr", spanish) is None
    assert isinstance(open_recogniser("en", spanish), PocketSphinxRecogniser)


def test_offline_install_names_the_routes_that_work_and_the_file_route_works(models_served, tmp_path, capsys):
    """No network: the official download fails (here: an index nobody serves), and the message
    names the two offline routes; the file:// route then installs the same model."""
    _, base = models_served
    with pytest.raises(models.SpeechModelError) as failure:
        models.install("fr", index_url=f"{base}/no-index.json")
    assert "--url file://" in str(failure.value) and "KIOSK_VOSK_MODEL" in str(failure.value)
    assert models.main(["install", "fr", "--url", f"{base}/gone.zip", "--sha256", "ab"]) == 1
    err = capsys.readouterr().err
    assert "kiosk models install fr --url file:///path/to/model.zip --sha256 HEX" in err
    assert "KIOSK_VOSK_MODEL" in err
    digest = _model_zip(tmp_path / "copied.zip", top="vosk-model-small-fr-0.22")
    assert models.main(["install", "fr", "--url", (tmp_path / "copied.zip").as_uri(), "--sha256", digest]) == 0
    assert models.find_model("fr") == tmp_path / "models" / "vosk" / "fr"
