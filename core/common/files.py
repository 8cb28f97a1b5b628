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
import socket
import tempfile
import time
from typing import Any, Dict, Iterator, Optional, Type


def _read_umask() -> int:
    mask = os.umask(0o022)  # the only way to read it is to set it: put it straight back
    os.umask(mask)
    return mask


UMASK = _read_umask()  # read once at import (os.umask is process-wide, not thread-safe)


def file_mode() -> int:
    """The mode a plain ``open(path, "w")`` gives a new file: 0o666 less the umask (mkstemp's files are 0600)."""
    return 0o666 & ~UMASK


def atomic_write_text(path: str, text: str) -> None:
    """Write ``text`` to ``path`` through a temporary file in the same folder; the file gets the mode the umask
    gives (not mkstemp's 0600), so other users of a shared project folder can read it."""
    folder = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix=".tmp-", suffix="-" + os.path.basename(path), dir=folder)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        with contextlib.suppress(OSError):  # a file system without modes (FAT, some shares)
            os.chmod(tmp, file_mode())
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
    tmp = os.path.join(folder, PARTIAL_PREFIX + os.path.basename(path))
    remove_path(tmp)
    try:
        yield tmp
        _honour_umask(tmp)
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


def atomic_copy(src: str, dst: str) -> str:
    """Copy the file ``src`` to ``dst`` atomically (a crash or cancel leaves ``dst`` as it was); nothing to do when
    both name the same file.  Returns ``dst``."""
    import shutil

    if os.path.exists(dst) and os.path.samefile(src, dst):
        return dst
    with atomic_output(dst) as tmp:
        shutil.copyfile(src, tmp)
    return dst


def _honour_umask(path: str) -> None:
    """Files made with mkstemp / NamedTemporaryFile inside a product are 0600: give them the umask's mode."""
    if os.path.isfile(path) and not os.path.islink(path):
        _fix_mode(path)
    elif os.path.isdir(path):
        for dirpath, _dirs, files in os.walk(path):
            for name in files:
                _fix_mode(os.path.join(dirpath, name))


def _fix_mode(path: str) -> None:
    with contextlib.suppress(OSError):
        if os.stat(path).st_mode & 0o777 == 0o600 and file_mode() != 0o600:
            os.chmod(path, file_mode())


def save_npz(path: str, compresslevel: Optional[int] = None, **arrays: Any) -> None:
    """``np.savez`` (``compresslevel``: deflate at that level, else stored) through :func:`atomic_output`: a
    failure (disk full) leaves neither a partial file nor a half-closed zip (no ``ZipFile.__del__`` traceback)."""
    import zipfile

    import numpy as np

    compression = zipfile.ZIP_STORED if compresslevel is None else zipfile.ZIP_DEFLATED
    try:
        with atomic_output(path) as tmp:
            zf = zipfile.ZipFile(tmp, "w", compression=compression, compresslevel=compresslevel)
            try:
                for name, arr in arrays.items():
                    with zf.open(name + ".npy", "w", force_zip64=True) as f:
                        np.lib.format.write_array(f, np.asanyarray(arr), allow_pickle=False)
            except BaseException:
                with contextlib.suppress(Exception):  # the first error is the one to report
                    zf.close()
                raise
            zf.close()
    except OSError as e:
        if e.filename:
            raise
        raise OSError(e.errno, e.strerror or str(e), path) from e  # "[Errno 28] No space left on device: 'path'"


def remove_path(path: str) -> None:
    if os.path.isdir(path) and not os.path.islink(path):
        shutil.rmtree(path, ignore_errors=True)
    elif os.path.lexists(path):
        with contextlib.suppress(OSError):
            os.unlink(path)


# --- who owns a run, and the debris of runs whose owner is gone ---------------------------------------------------
OWNER_FILE = ".owner.json"


def process_start(pid: int) -> Optional[str]:
    """A token of when process ``pid`` started (Linux: boot id + start tick), to tell a reused pid apart; None
    where it cannot be read (not Linux, no such process) and ``"zombie"`` for a dead, unreaped process."""
    try:
        with open(f"/proc/{int(pid)}/stat", encoding="ascii", errors="replace") as f:
            fields = f.read().rsplit(")", 1)[1].split()
        if fields[0] in ("Z", "X"):
            return "zombie"
        boot = ""
        with contextlib.suppress(OSError), open("/proc/sys/kernel/random/boot_id", encoding="ascii") as f:
            boot = f.read().strip()[:8]
        return f"{boot}:{fields[19]}"
    except (OSError, IndexError, ValueError):
        return None


def process_owner() -> Dict[str, Any]:
    """This process as the owner of a run: host, pid and start token (see :func:`owner_alive`)."""
    return {"host": socket.gethostname(), "pid": os.getpid(), "pid_started": process_start(os.getpid())}


def _pid_exists(pid: int) -> bool:
    if os.name == "nt":  # pragma: no cover - os.kill(pid, 0) would terminate the process on Windows
        import ctypes

        handle = ctypes.windll.kernel32.OpenProcess(0x1000, False, pid)  # PROCESS_QUERY_LIMITED_INFORMATION
        if not handle:
            return False
        code = ctypes.c_ulong()
        ctypes.windll.kernel32.GetExitCodeProcess(handle, ctypes.byref(code))
        ctypes.windll.kernel32.CloseHandle(handle)
        return code.value == 259  # STILL_ACTIVE
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process
        return True
    except OSError:
        return False
    return True


def owner_alive(owner: Any) -> Optional[bool]:
    """Whether the process recorded as ``owner`` (:func:`process_owner`) still runs: True / False on this host,
    None when it cannot tell (no owner recorded, another host sharing the folder)."""
    if not isinstance(owner, dict) or owner.get("host") != socket.gethostname():
        return None
    try:
        pid = int(owner.get("pid"))
    except (TypeError, ValueError):
        return None
    started = owner.get("pid_started")
    if pid == os.getpid():
        return not (started and started != process_start(pid))
    if not _pid_exists(pid):
        return False
    now = process_start(pid)
    if now == "zombie":
        return False
    return not (started and now and now != started)  # the pid was reused by another process


def owned_tempdir(prefix: str, folder: str) -> str:
    """``tempfile.mkdtemp(prefix=prefix, dir=folder)`` with this process recorded inside as its owner, so that a
    later run can tell debris of a killed run (:func:`clean_debris`) from the work folder of a running one."""
    path = tempfile.mkdtemp(prefix=prefix, dir=folder)
    with contextlib.suppress(OSError), open(os.path.join(path, OWNER_FILE), "w", encoding="utf-8") as f:
        json.dump(process_owner(), f)
    return path


def clean_debris(folder: str, prefix: str, unowned_age_s: float = 3600.0) -> list:
    """Remove the ``prefix*`` work folders (:func:`owned_tempdir`) in ``folder`` whose owner process is gone, and
    ``prefix*`` folders without an owner (left by an older version) untouched for ``unowned_age_s``.  A folder of
    a running process, or of another host sharing the folder, stays.  Returns the removed paths."""
    removed = []
    try:
        names = os.listdir(folder)
    except OSError:
        return removed
    for name in names:
        path = os.path.join(folder, name)
        if not name.startswith(prefix) or not os.path.isdir(path) or os.path.islink(path):
            continue
        gone = False
        try:
            with open(os.path.join(path, OWNER_FILE), encoding="utf-8") as f:
                gone = owner_alive(json.load(f)) is False
        except (OSError, ValueError):
            with contextlib.suppress(OSError):
                gone = time.time() - os.stat(path).st_mtime > unowned_age_s
        if gone:
            remove_path(path)
            removed.append(path)
    return removed


PARTIAL_PREFIX = ".partial-"  # atomic_output's temporary name
TEMP_PREFIX = ".tmp-"  # atomic_write_text's


def clean_partials(folder: str, depth: int = 2, temp_age_s: float = 60.0) -> list:
    """Remove what killed runs left of :func:`atomic_output` (``.partial-*``) and :func:`atomic_write_text`
    (``.tmp-*`` older than ``temp_age_s``) in ``folder`` and its sub-folders down to ``depth``.  Call it only when
    no other process writes there (a workspace whose stages are not running elsewhere).  Returns the paths."""
    removed = []
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return removed
    for entry in entries:
        name = entry.name
        with contextlib.suppress(OSError):
            if name.startswith(PARTIAL_PREFIX) or (
                    name.startswith(TEMP_PREFIX) and time.time() - entry.stat(follow_symlinks=False).st_mtime
                    > temp_age_s):
                remove_path(entry.path)
                removed.append(entry.path)
            elif depth > 0 and entry.is_dir(follow_symlinks=False) and not name.startswith("."):
                removed += clean_partials(entry.path, depth - 1, temp_age_s)
    return removed


def read_json_record(path: str, error: Type[Exception]) -> Optional[Any]:
    """The JSON document at ``path``, or None when there is no such file; ``error`` naming the file when it
    exists but cannot be read or parsed (a damaged record is never mistaken for a missing one)."""
    if not os.path.isfile(path):
        return None
    try:
        with open(path, encoding="utf-8") as f:
            return json.load(f)
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as e:
        raise error(f"{path} cannot be read: {e}") from e


def same_path(a: str, b: str) -> bool:
    """Whether ``a`` and ``b`` name the same file: the same file on disk (links, case-insensitive file systems), or
    the same normalised absolute path when either does not exist yet."""
    if not a or not b:
        return False
    try:
        if os.path.exists(a) and os.path.exists(b):
            return os.path.samefile(a, b)
    except OSError:
        pass
    return os.path.normcase(os.path.realpath(a)) == os.path.normcase(os.path.realpath(b))


def refuse_overwriting_inputs(outputs: Dict[str, Optional[str]], inputs: Dict[str, Optional[str]],
                              error: Type[Exception]) -> None:
    """``error`` naming the file when an output (what -> path; None = not written) is one of the inputs (what ->
    path), or when two outputs are the same file: checked before any work, so that no input is ever replaced by
    a product made from it."""
    for out_what, out in outputs.items():
        for in_what, src in inputs.items():
            if out and src and same_path(out, src):
                raise error(f"the {out_what} would overwrite its input, the {in_what} {src}: choose another output "
                            "file")
    named = [(w, p) for w, p in outputs.items() if p]
    for i, (wa, pa) in enumerate(named):
        for wb, pb in named[i + 1:]:
            if same_path(pa, pb):
                raise error(f"the {wa} and the {wb} would be written to one file ({pa}): choose other output files")


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
