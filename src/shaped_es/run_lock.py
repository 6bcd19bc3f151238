"""One writer per run directory: ``RUN/.lock`` holds the writer's pid, host and command and is
``flock``-ed, so a killed holder's lock is free again; without ``flock`` a lock of a dead pid on this host
is taken over. Re-entrant within a process (:data:`HELD`); :meth:`shaped_es.store.RunStore.lock` is the
way in."""

from __future__ import annotations

import contextlib
import errno
import json
import os
import socket
import sys
import time
from pathlib import Path

from shaped_es.store_io import StoreError

try:
    import fcntl
except ImportError:  # pragma: no cover - not POSIX
    fcntl = None

LOCK_NAME = ".lock"


class _Lock:
    def __init__(self, path: Path, fd: int | None):
        self.path, self.fd, self.count = path, fd, 0


HELD: dict[str, _Lock] = {}  # lock path -> this process's lock (re-entrant within the process)


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _read_owner(path: Path) -> dict:
    try:
        owner = json.loads(path.read_text())
        return owner if isinstance(owner, dict) else {}
    except (OSError, ValueError):
        return {}


def _owner_text(owner: dict) -> str:
    pid, host = owner.get("pid", "?"), owner.get("host", "?")
    cmd = f" ({owner['command']})" if owner.get("command") else ""
    return f"process {pid} on {host}{cmd}"


def _owner_record() -> bytes:
    cmd = " ".join(Path(sys.argv[0]).name if i == 0 else a for i, a in enumerate(sys.argv))[:200]
    return json.dumps({"pid": os.getpid(), "host": socket.gethostname(), "command": cmd,
                       "since": time.strftime("%Y-%m-%dT%H:%M:%S")}).encode()


def acquire(root: Path) -> _Lock:
    path = root / LOCK_NAME
    for _ in range(10):  # only loops when another process unlinked the file between our open and flock
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            if fcntl is not None:
                try:
                    fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                except BlockingIOError:
                    raise StoreError(_locked_message(root, _read_owner(path))) from None
                except OSError as exc:  # a filesystem without flock: fall back to the pid check
                    if exc.errno not in (errno.ENOLCK, errno.EOPNOTSUPP, errno.ENOSYS, errno.EINVAL):
                        raise
                    _check_pid_lock(root, path)
            else:  # pragma: no cover
                _check_pid_lock(root, path)
            try:
                same = os.stat(path).st_ino == os.fstat(fd).st_ino
            except FileNotFoundError:
                same = False
            if not same:  # the previous holder released (unlinked) it meanwhile: lock the new file
                os.close(fd)
                continue
            os.ftruncate(fd, 0)
            os.write(fd, _owner_record())
            os.fsync(fd)
            return _Lock(path, fd)
        except BaseException:
            with contextlib.suppress(OSError):
                os.close(fd)
            raise
    raise StoreError(f"cannot lock {root}: the lock file keeps changing")


def _check_pid_lock(root: Path, path: Path) -> None:
    owner = _read_owner(path)
    pid = owner.get("pid")
    if (isinstance(pid, int) and pid != os.getpid() and owner.get("host") == socket.gethostname()
            and _pid_alive(pid)):
        raise StoreError(_locked_message(root, owner))


def _locked_message(root: Path, owner: dict) -> str:
    return (f"{root} is in use by {_owner_text(owner)}; wait for it to finish or stop it (a lock left by "
            f"a process that died is taken over)")


def release(lock: _Lock) -> None:
    with contextlib.suppress(OSError):
        if lock.fd is not None and os.stat(lock.path).st_ino == os.fstat(lock.fd).st_ino:
            lock.path.unlink()
    if lock.fd is not None:
        with contextlib.suppress(OSError):
            os.close(lock.fd)
