"""`kiosk models`: install Vosk speech-recognition models; list which recogniser each language uses.

    kiosk models install LANG [--url URL --sha256 HEX]
    kiosk models list

``install`` downloads the official small Vosk model for LANG (en, es, fr, de) from alphacephei.com
and checks it against the MD5 the official model index publishes, or any model zip from
``--url`` checked against ``--sha256`` (required then). The archive is downloaded, verified and
unpacked beside the models folder and only then moved into place, so a failed or tampered
download leaves nothing half-installed and keeps a previous model.

Models live in ``KIOSK_MODELS_DIR`` or the user data folder (``vosk/LANG``). At run time
:func:`find_model` also honours ``KIOSK_VOSK_MODEL``: a model folder (its language taken from
its official name, e.g. ``vosk-model-small-es-0.42``) or a folder holding such models.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import shutil
import sys
import tempfile
import urllib.error
import urllib.request
import zipfile
from collections.abc import Sequence
from pathlib import Path, PurePosixPath

from basis.errors import KioskError

#: the official small models (about 40-50 MB each), from https://alphacephei.com/vosk/models
OFFICIAL_MODELS = {
    "en": "https://alphacephei.com/vosk/models/vosk-model-small-en-us-0.15.zip",
    "es": "https://alphacephei.com/vosk/models/vosk-model-small-es-0.42.zip",
    "fr": "https://alphacephei.com/vosk/models/vosk-model-small-fr-0.22.zip",
    "de": "https://alphacephei.com/vosk/models/vosk-model-small-de-0.15.zip",
}
#: the official index: one entry per model with its name and MD5
OFFICIAL_INDEX = "https://alphacephei.com/vosk/models/model-list.json"
DOWNLOAD_TIMEOUT_S = 60
#: what works without a network, said whenever a download or the index cannot be reached
OFFLINE_ROUTES = (
    "; without a network, copy the model zip to this machine and run "
    "`kiosk models install {language} --url file:///path/to/model.zip --sha256 HEX`, "
    "or unpack it and set KIOSK_VOSK_MODEL=/path/to/the/model/folder"
)


class SpeechModelError(KioskError):
    """A speech-recognition model could not be installed or found; the message says where and
    what. (Not :class:`qos.ModelError`, a malformed QoS model: the two had one name.)"""


def models_dir() -> Path:
    """Where installed models live (``KIOSK_MODELS_DIR`` overrides the user data folder)."""
    if override := os.environ.get("KIOSK_MODELS_DIR"):
        return Path(override)
    import platformdirs

    return platformdirs.user_data_path("barthel-kiosk") / "models"


def is_vosk_model(path: Path) -> bool:
    """Whether ``path`` looks like an unpacked Vosk model (acoustic model and configuration)."""
    return path.is_dir() and (path / "am" / "final.mdl").is_file() and (path / "conf").is_dir()


def model_language(path: Path) -> str | None:
    """The language in an official model name: ``vosk-model-small-en-us-0.15`` → ``en``."""
    parts = [p for p in path.name.lower().split("-") if p not in ("vosk", "model", "small")]
    return parts[0] if parts and parts[0].isalpha() else None


def installed_model(language: str) -> Path | None:
    """The model `kiosk models install` put in place for ``language``, if any."""
    path = models_dir() / "vosk" / language
    return path if is_vosk_model(path) else None


def find_model(language: str, configured: str | Path | None = None) -> Path | None:
    """The Vosk model to use for ``language``, or None.

    ``configured`` (the config's ``vosk_model``, else ``KIOSK_VOSK_MODEL``) is a model folder,
    used only if its name does not say it is for another language, or a folder of models; then
    the model `kiosk models install` put in place.
    """
    if configured := configured or os.environ.get("KIOSK_VOSK_MODEL"):
        root = Path(configured)
        if is_vosk_model(root) and model_language(root) in (language, None):
            return root
        if root.is_dir():
            for candidate in sorted(root.iterdir()):
                if is_vosk_model(candidate) and (candidate.name == language or model_language(candidate) == language):
                    return candidate
    return installed_model(language)


# --- installing ------------------------------------------------------------------------------


def _download(url: str, into: Path) -> tuple[Path, str, str]:
    """Stream ``url`` to a private file in ``into``; returns it with its SHA-256 and MD5."""
    sha256, md5 = hashlib.sha256(), hashlib.md5()
    fd, name = tempfile.mkstemp(prefix=".download-", suffix=".zip", dir=into)  # 0600
    try:
        with os.fdopen(fd, "wb") as out, urllib.request.urlopen(url, timeout=DOWNLOAD_TIMEOUT_S) as response:
            while chunk := response.read(1 << 20):
                sha256.update(chunk)
                md5.update(chunk)
                out.write(chunk)
    except (urllib.error.URLError, OSError) as exc:
        os.unlink(name)
        raise SpeechModelError(
            f"cannot download {url}: {getattr(exc, 'reason', exc)}"
            + ("" if url.startswith("file:") else OFFLINE_ROUTES)
        ) from None
    return Path(name), sha256.hexdigest(), md5.hexdigest()


def _official_md5(url: str, index_url: str) -> str:
    name = PurePosixPath(url).name.removesuffix(".zip")
    try:
        with urllib.request.urlopen(index_url, timeout=DOWNLOAD_TIMEOUT_S) as response:
            index = json.load(response)
    except (urllib.error.URLError, OSError, ValueError) as exc:
        raise SpeechModelError(
            f"cannot read the model index {index_url}: {getattr(exc, 'reason', exc)}" + OFFLINE_ROUTES
        ) from None
    for entry in index if isinstance(index, list) else []:
        if isinstance(entry, dict) and entry.get("name") == name and entry.get("md5"):
            return str(entry["md5"]).lower()
    raise SpeechModelError(f"the model index {index_url} has no checksum for {name}")


def _unpack(archive: Path, into: Path) -> Path:
    """Unpack into a fresh private folder in ``into``; returns the model folder inside it."""
    folder = Path(tempfile.mkdtemp(prefix=".unpack-", dir=into))  # 0700
    try:
        with zipfile.ZipFile(archive) as zf:
            for member in zf.namelist():
                path = PurePosixPath(member)
                if path.is_absolute() or ".." in path.parts:
                    raise SpeechModelError(f"{archive.name}: unsafe path {member!r} in the archive")
            zf.extractall(folder)
    except zipfile.BadZipFile as exc:
        shutil.rmtree(folder)
        raise SpeechModelError(f"the download is not a zip archive ({exc})") from None
    except SpeechModelError:
        shutil.rmtree(folder)
        raise
    # official archives hold one top folder named after the model
    entries = list(folder.iterdir())
    model = entries[0] if len(entries) == 1 and entries[0].is_dir() else folder
    if not is_vosk_model(model):
        shutil.rmtree(folder)
        raise SpeechModelError("the archive does not contain a Vosk model (no am/final.mdl and conf/)")
    return model


def install(language: str, url: str | None = None, sha256: str | None = None, index_url: str = OFFICIAL_INDEX) -> Path:
    """Download, verify and install a model for ``language``; returns where it now lives.

    Without ``url`` the official model is fetched and checked against the official MD5; with
    ``url``, ``sha256`` is required.
    """
    if url is None:
        if language not in OFFICIAL_MODELS:
            raise SpeechModelError(
                f"no official model known for language {language!r} "
                f"(known: {', '.join(OFFICIAL_MODELS)}); give --url and --sha256"
            )
        url = OFFICIAL_MODELS[language]
        expected, algorithm = (sha256, "sha256") if sha256 else (_official_md5(url, index_url), "md5")
    elif not sha256:
        raise SpeechModelError("a model from --url needs --sha256 to check it")
    else:
        expected, algorithm = sha256, "sha256"
    expected = expected.strip().lower()

    parent = models_dir() / "vosk"
    parent.parent.parent.mkdir(mode=0o700, parents=True, exist_ok=True)  # the app's own folder too
    for level in (parent.parent, parent):
        level.mkdir(mode=0o700, exist_ok=True)
    archive, got_sha256, got_md5 = _download(url, parent)
    unpacked: Path | None = None
    try:
        got = got_sha256 if algorithm == "sha256" else got_md5
        if got != expected:
            raise SpeechModelError(
                f"checksum mismatch for {url}: expected {algorithm} {expected}, got {got}; nothing was installed"
            )
        model = _unpack(archive, parent)
        unpacked = model if model.parent == parent else model.parent
        target = parent / language
        old = parent / f".old-{language}"
        if target.exists():
            target.rename(old)
        model.rename(target)
        shutil.rmtree(old, ignore_errors=True)
        return target
    finally:
        archive.unlink(missing_ok=True)
        if unpacked is not None and unpacked != parent / language:
            shutil.rmtree(unpacked, ignore_errors=True)


# --- the command -----------------------------------------------------------------------------


def _list() -> list[str]:
    """One line per language: the recogniser :func:`kiosk.speech.asr.open_recogniser` would
    open for it, and why (decided from what is installed, without loading a model)."""
    from kiosk.speech.asr.whisper_files import whisper_status

    lines = []
    for language in OFFICIAL_MODELS:
        whisper, why = whisper_status(language)
        path = find_model(language)
        if whisper is not None:
            detail = "PocketSphinx ends the turn" if language == "en" else "the endpointer ends the turn"
            lines.append(f"{language}  whisper       Whisper {whisper}, installed ({detail})")
        elif path is not None:
            lines.append(f"{language}  vosk          {path} (fallback: Whisper {why})")
        elif language == "en":
            lines.append(f"{language}  pocketsphinx  bundled English model (fallback: Whisper {why})")
        else:
            lines.append(
                f"{language}  none          voice answers off (Whisper {why}); `kiosk models install {language}`"
            )
    return lines


def main(argv: Sequence[str]) -> int:
    """`kiosk models install LANG [--url URL --sha256 HEX]` / `kiosk models list`."""
    parser = argparse.ArgumentParser(prog="kiosk models", description="Install and list speech models.")
    sub = parser.add_subparsers(dest="action", required=True)
    add = sub.add_parser("install", help="download, verify and install a Vosk model")
    add.add_argument("language", help="en, es or fr")
    add.add_argument("--url", help="a model zip from another address (needs --sha256)")
    add.add_argument("--sha256", help="the archive's SHA-256, hex")
    sub.add_parser("list", help="which recogniser each language would use, and why")
    args = parser.parse_args(list(argv))
    if args.action == "list":
        print("\n".join(_list()))
        return 0
    try:
        path = install(args.language, url=args.url, sha256=args.sha256)
    except SpeechModelError as exc:
        print(f"kiosk models: {str(exc).replace('{language}', args.language)}", file=sys.stderr)
        return 1
    print(f"installed the {args.language} model in {path}")
    return 0
