"""Checking a dataset folder against its ``sha256sum``-style manifest."""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field
from pathlib import Path

from tsrkit.datasets.errors import DatasetError

__all__ = ["CHUNK", "Verification", "read_manifest", "sha256_file", "verify_manifest"]

CHUNK = 1 << 20


@dataclass(frozen=True)
class Verification:
    """What :func:`verify_manifest` found: counts and the files at fault."""

    checked: int
    missing: tuple[str, ...] = ()
    altered: tuple[str, ...] = ()
    unlisted: tuple[str, ...] = field(default=())

    @property
    def ok(self) -> bool:
        """True when every listed file is present and unchanged."""
        return not self.missing and not self.altered


def read_manifest(path: Path) -> dict[str, str]:
    """``{relative path: sha256 hex}`` from lines ``<hex>  <path>`` (``*`` binary mark allowed).

    Raises
    ------
    DatasetError
        For a missing manifest or a malformed line (naming the line).
    """
    try:
        text = Path(path).read_text(encoding="utf-8")
    except FileNotFoundError:
        raise DatasetError(path, "manifest not found") from None
    entries = {}
    for number, line in enumerate(text.splitlines(), 1):
        if not line.strip():
            continue
        digest, sep, name = line.partition(" ")
        name = name.strip().lstrip("*")
        if not sep or len(digest) != 64 or not name:
            raise DatasetError(path, "expected '<sha256>  <file>'", f"line {number}")
        entries[str(Path(name))] = digest.lower()
    return entries


def sha256_file(path: Path) -> str:
    """The SHA-256 hex digest of a file, read in 1 MiB chunks."""
    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        while chunk := fh.read(CHUNK):
            digest.update(chunk)
    return digest.hexdigest()


def verify_manifest(root: Path, manifest: Path) -> Verification:
    """Hash every file the manifest lists under ``root``; report missing and altered ones.

    Files present under ``root`` but not listed (other than the manifest) are reported as
    ``unlisted`` for information; they do not make the check fail.
    """
    root = Path(root)
    entries = read_manifest(manifest)
    missing, altered = [], []
    for name, digest in entries.items():
        target = root / name
        if not target.is_file():
            missing.append(name)
        elif sha256_file(target) != digest:
            altered.append(name)
    listed = set(entries) | {str(Path(manifest).resolve().relative_to(root.resolve()))}
    unlisted = sorted(
        str(p.relative_to(root))
        for p in root.rglob("*")
        if p.is_file() and str(p.relative_to(root)) not in listed
    )
    return Verification(len(entries), tuple(missing), tuple(altered), tuple(unlisted))
