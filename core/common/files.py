"""Files written so that a crash or a cancel never leaves a half-written product, and cheap fingerprints.

Every product of a stage is written through :func:`atomic_output` or :func:`atomic_write_text`: the new file or
folder appears under its name only when complete, and a previous complete product stays until then.
"""
from __future__ import annotations

import contextlib
import hashlib
import json
import os
import shutil
import tempfile
from typing import Any, Iterator


def atomic_write_text(path: str, text: str) -> None:
    """Write ``text`` to ``path`` through a temporary file in the same folder."""
    folder = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix=".tmp-", suffix="-" + os.path.basename(path), dir=folder)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


@contextlib.contextmanager
def atomic_output(path: str) -> Iterator[str]:
    """Yield a temporary path beside ``path``; rename it to ``path`` only on success.

    Works for files and folders.  A crash or cancel leaves nothing at ``path``
    that looks complete (a previous complete product stays as it was until the
    new one is ready).
    """
    folder = os.path.dirname(os.path.abspath(path))
    os.makedirs(folder, exist_ok=True)
    tmp = os.path.join(folder, ".partial-" + os.path.basename(path))
    remove_path(tmp)
    try:
        yield tmp
        if os.path.isdir(tmp) and os.path.isdir(path):
            old = os.path.join(folder, ".old-" + os.path.basename(path))
            remove_path(old)
            os.replace(path, old)
            os.replace(tmp, path)
            remove_path(old)
        else:
            if os.path.isdir(path):
                remove_path(path)
            os.replace(tmp, path)
    except BaseException:
        remove_path(tmp)
        raise


def remove_path(path: str) -> None:
    if os.path.isdir(path) and not os.path.islink(path):
        shutil.rmtree(path, ignore_errors=True)
    elif os.path.lexists(path):
        with contextlib.suppress(OSError):
            os.unlink(path)


def file_fingerprint(path: str) -> str:
    """Cheap fingerprint of a file: size, mtime and a hash of its first 64 KiB."""
    st = os.stat(path)
    h = hashlib.sha1()
    with open(path, "rb") as f:
        h.update(f.read(65536))
    return f"{st.st_size}:{int(st.st_mtime)}:{h.hexdigest()[:16]}"


def fingerprint(obj: Any) -> str:
    """Stable hash of a JSON-serialisable object (stage parameters, image lists)."""
    return hashlib.sha1(json.dumps(obj, sort_keys=True, default=str).encode()).hexdigest()[:16]
