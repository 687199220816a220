"""Writing files without following a symbolic link planted in their place, and telling a
full disk from a bug.

Every file the tool writes beside a result (plots, sweep summaries, XDMF) goes through
:func:`replace_atomically`: the content is written to a new temporary file in the same
directory (``mkstemp``: ``O_CREAT | O_EXCL``, which never follows a link), then renamed
onto the final name. ``rename`` replaces a symbolic link at the final name by the file; it
never writes to where the link points. A reader sees the old file or the new one, never a
half-written one, and a failed write leaves the old file as it was.

HDF5 result files are created by :func:`create_fresh`: whatever is at the name (a stale
file, a planted link) is unlinked first and the file is created exclusively, so the link's
target is never touched.

:func:`disk_full` says whether an OSError (or the text of an HDF5 error) is a full disk, a
quota or a file-size limit (``ulimit -f``): the run then ends with exit status 3 and the
rows already written are kept. :func:`ignore_file_size_signal` makes a file-size limit an
error (EFBIG) rather than the SIGXFSZ that would kill the process.
"""
from __future__ import annotations

import errno
import os
import signal
from contextlib import contextmanager
from pathlib import Path
from typing import IO, Any, Callable, Iterator

#: errno values of "the disk cannot take more": full, over quota, beyond the file-size limit
DISK_FULL_ERRNOS = (errno.ENOSPC, errno.EDQUOT, errno.EFBIG)
#: how HDF5 and the C library spell them in messages (HDF5 errors carry no errno)
DISK_FULL_TEXTS = ("no space left", "disk quota", "file too large", "errno = 28",
                   "errno = 27", "errno = 122")


def disk_full(exc: BaseException) -> bool:
    """Whether an exception says the disk (or the file-size limit) is full."""
    if isinstance(exc, OSError) and exc.errno in DISK_FULL_ERRNOS:
        return True
    text = str(exc).lower()
    return any(t in text for t in DISK_FULL_TEXTS)


def ignore_file_size_signal() -> None:
    """Ignore SIGXFSZ: beyond ``ulimit -f`` a write then fails with EFBIG, which the run
    reports (exit 3, rows kept), instead of the signal killing the process."""
    if hasattr(signal, "SIGXFSZ"):
        try:
            signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        except (ValueError, OSError):  # not the main thread
            pass


@contextmanager
def _swap_in(path: str | Path) -> Iterator[tuple[int, Path]]:
    """A temporary file beside ``path`` (its open descriptor and name) that replaces
    ``path`` in one rename when the block ends normally (a symbolic link at ``path`` is
    replaced, not followed), and is removed otherwise, leaving ``path`` as it was."""
    import tempfile   # (with shutil and random: ~2 ms of every command's start; few write so)
    path = Path(path)
    fd, temp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp",
                                dir=str(path.parent) if str(path.parent) else ".")
    try:
        yield fd, Path(temp)
        os.chmod(temp, 0o644 & ~_umask())
        os.replace(temp, path)
    except BaseException:
        try:
            os.unlink(temp)
        except OSError:
            pass
        raise


@contextmanager
def replace_atomically(path: str | Path, mode: str = "w", **open_kwargs: Any) -> Iterator[IO]:
    """A file object to write ``path``'s new content to; on success the content replaces
    ``path`` in one rename (a symbolic link at ``path`` is replaced, not followed), on
    failure the temporary file is removed and ``path`` is left as it was."""
    with _swap_in(path) as (fd, _), os.fdopen(fd, mode, **open_kwargs) as fh:
        yield fh
        fh.flush()


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def write_text(path: str | Path, text: str) -> None:
    """``Path.write_text`` without following a link at ``path`` (atomic)."""
    with replace_atomically(path, "w", encoding="utf-8") as fh:
        fh.write(text)


def write_bytes(path: str | Path, data: bytes) -> None:
    """``Path.write_bytes`` without following a link at ``path`` (atomic)."""
    with replace_atomically(path, "wb") as fh:
        fh.write(data)


def save_figure(fig: Any, path: str | Path, **kwargs: Any) -> None:
    """``fig.savefig(path)`` without following a link at ``path`` (atomic); the format
    comes from ``path``'s suffix."""
    path = Path(path)
    kwargs.setdefault("format", path.suffix.lstrip(".") or "png")
    with replace_atomically(path, "wb") as fh:
        fig.savefig(fh, **kwargs)


def write_with(path: str | Path, writer: Callable[[Path], None]) -> None:
    """Let ``writer`` write a temporary file (given its path), then move it onto ``path``."""
    with _swap_in(path) as (fd, temp):
        os.close(fd)
        writer(temp)


def create_fresh(path: str | Path) -> None:
    """Make room for a new file at ``path``: whatever is there (a stale result, a symbolic
    link planted in its place) is unlinked, so that an exclusive create never writes
    through a link. A directory is left alone (the create then fails)."""
    path = Path(path)
    try:
        if path.is_symlink() or path.is_file():
            path.unlink()
    except FileNotFoundError:
        pass


#: what a write must leave free besides its own bytes: HDF5's metadata and the final status
#: written after a refused write (a write that fails inside HDF5 can crash the library when
#: the file is closed, so the room is checked before writing instead)
ROOM_MARGIN_BYTES = 256 * 1024


def room_for(path: str | Path) -> tuple[int, int]:
    """(bytes free on the filesystem of ``path`` for this user, bytes the file may still
    grow under ``ulimit -f``); a very large number when unknown or unlimited."""
    path = Path(path)
    big = 2**63 - 1
    free = big
    try:
        st = os.statvfs(path.parent if str(path.parent) else ".")
        free = st.f_bavail * st.f_frsize
    except OSError:
        pass
    grow = big
    try:
        import resource
        soft, _ = resource.getrlimit(resource.RLIMIT_FSIZE)
        if soft != resource.RLIM_INFINITY:
            size = path.stat().st_size if path.exists() else 0
            grow = max(soft - size, 0)
    except (OSError, ValueError, ImportError):
        pass
    return free, grow


def check_room(path: str | Path, nbytes: int, margin: int = ROOM_MARGIN_BYTES) -> None:
    """Raise OSError (ENOSPC, or EFBIG for the file-size limit) when writing ``nbytes``
    more to ``path`` would not leave ``margin`` bytes; nothing is written then."""
    free, grow = room_for(path)
    need = int(nbytes) + int(margin)
    if need > free:
        raise OSError(errno.ENOSPC, f"No space left on device: {need:,} bytes needed to write "
                      f"{Path(path).name}, {free:,} free")
    if need > grow:
        raise OSError(errno.EFBIG, f"File too large: writing {need:,} more bytes to "
                      f"{Path(path).name} would pass the file-size limit (ulimit -f)")
