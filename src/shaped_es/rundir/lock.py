"""One writer per run directory: the writer ``flock``-s the run directory itself (a descriptor on it, which
a stray ``rm RUN/.lock`` cannot take away from a live holder) and ``RUN/.lock``, which holds its pid, host
and command for the message others get; a killed holder's locks are free again. Where the filesystem
cannot ``flock`` a directory (NFS), the lock file alone is the lock; without ``flock`` at all, a lock of a
dead pid on this host is taken over. Re-entrant within a process (:data:`HELD`);
:meth:`shaped_es.rundir.store.RunStore.lock` is the way in."""

from __future__ import annotations

import contextlib
import errno
import json
import os
import socket
import sys
import time
from pathlib import Path

from shaped_es.rundir.atomic import StoreError

try:
    import fcntl
except ImportError:  # pragma: no cover - not POSIX
    fcntl = None

LOCK_NAME = ".lock"


_NO_FLOCK = (errno.ENOLCK, errno.EOPNOTSUPP, errno.ENOSYS, errno.EINVAL)


class _Lock:
    def __init__(self, path: Path, fd: int | None, dir_fd: int | None = None):
        self.path, self.fd, self.dir_fd, self.count = path, fd, dir_fd, 0


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
    if not owner:
        return "another process (its .lock file, which names it, was removed or is unreadable)"
    pid, host = owner.get("pid", "?"), owner.get("host", "?")
    cmd = f" ({owner['command']})" if owner.get("command") else ""
    return f"process {pid} on {host}{cmd}"


def _owner_record() -> bytes:
    cmd = " ".join(Path(sys.argv[0]).name if i == 0 else a for i, a in enumerate(sys.argv))[:200]
    return json.dumps({"pid": os.getpid(), "host": socket.gethostname(), "command": cmd,
                       "since": time.strftime("%Y-%m-%dT%H:%M:%S")}).encode()


def _lock_directory(root: Path) -> int | None:
    """``flock`` a descriptor on the run directory itself; None where that is not supported (the lock
    file alone then decides); ``StoreError`` naming the holder if another process has it."""
    if fcntl is None:  # pragma: no cover - not POSIX
        return None
    fd = os.open(root, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        os.close(fd)
        raise StoreError(_locked_message(root, _read_owner(root / LOCK_NAME))) from None
    except OSError as exc:  # NFS emulates flock with POSIX locks, which a read-only descriptor cannot take
        os.close(fd)
        if exc.errno not in (*_NO_FLOCK, errno.EBADF):
            raise
        return None
    return fd


def acquire(root: Path) -> _Lock:
    dir_fd = _lock_directory(root)
    try:
        lock = _acquire_file(root)
    except BaseException:
        if dir_fd is not None:
            os.close(dir_fd)
        raise
    lock.dir_fd = dir_fd
    return lock


def probe(root: Path) -> None:
    """``StoreError`` if another process holds the lock of ``root`` (nothing is created or changed)."""
    fd = _lock_directory(root)
    if fd is not None:
        os.close(fd)  # closing the only descriptor drops the flock
    path = root / LOCK_NAME
    if path.exists():
        release(_acquire_file(root))


def holder(root: Path) -> str | None:
    """The one line naming the live process that holds ``root``'s lock, or None when it is free; unlike
    :func:`probe`, nothing is created, written or removed (not even a dead holder's ``.lock``)."""
    try:
        fd = _lock_directory(root)
    except StoreError as exc:
        return str(exc)
    if fd is not None:
        os.close(fd)
    path = root / LOCK_NAME
    if not path.is_file():
        return None
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    except OSError:
        return None
    try:
        if fcntl is not None:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            return None
    except BlockingIOError:
        return _locked_message(root, _read_owner(path))
    except OSError as exc:  # no flock here (or NFS's, which a read-only descriptor cannot take): the pid
        if exc.errno not in (*_NO_FLOCK, errno.EBADF):
            raise
    finally:
        os.close(fd)  # drops the flock just taken
    try:  # without flock: a live pid on this host holds it
        _check_pid_lock(root, path)
    except StoreError as exc:
        return str(exc)
    return None


def _acquire_file(root: Path) -> _Lock:
    path = root / LOCK_NAME
    for _ in range(10):  # only loops when another process unlinked the file between our open and flock
        try:  # never through a symlink: a .lock that points elsewhere would have that file emptied
            fd = os.open(path, os.O_RDWR | os.O_CREAT | getattr(os, "O_NOFOLLOW", 0), 0o644)
        except OSError as exc:
            if path.is_symlink():
                raise StoreError(f"{path} is a symlink; a run's lock is a file of its own there (nothing was "
                                 f"written through it): remove the link and run again") from None
            raise
        try:
            if fcntl is not None:
                try:
                    fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                except BlockingIOError:
                    raise StoreError(_locked_message(root, _read_owner(path))) from None
                except OSError as exc:  # a filesystem without flock: fall back to the pid check
                    if exc.errno not in _NO_FLOCK:
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
    for fd in (lock.fd, lock.dir_fd):  # the lock file first: the directory's lock guards its removal
        if fd is not None:
            with contextlib.suppress(OSError):
                os.close(fd)
