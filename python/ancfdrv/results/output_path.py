"""The check of an output path before anything is computed (:func:`check_output_path`):
not a directory, not below a regular file, writable, never an input file, never a file that
is not HDF5 (the run and :meth:`Results.save <ancfdrv.results.Results.save>` both use it)."""
from __future__ import annotations

import os
from pathlib import Path
from typing import Iterable

from ..errors import InputError
from .lock import lock_path

#: files written beside the result (suffix): the plot of ``ancf run``, the XDMF of plates
DERIVED_SUFFIXES = {".png": "the plot", ".xdmf": "the XDMF description"}
_HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"


def _same_file(a: Path, b: Path) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:
        return a.resolve() == b.resolve()


def _is_hdf5(path: Path) -> bool:
    """HDF5's signature at offset 0, 512, 1024, ... (where a superblock may start)."""
    size = path.stat().st_size
    with open(path, "rb") as f:
        offset = 0
        while offset + len(_HDF5_SIGNATURE) <= size:
            f.seek(offset)
            if f.read(len(_HDF5_SIGNATURE)) == _HDF5_SIGNATURE:
                return True
            offset = 512 if offset == 0 else 2 * offset
    return False


def _writable_parent(out: Path) -> None:
    """The output's directory exists and is writable, or can be created."""
    parent = out.parent if str(out.parent) else Path(".")
    existing = parent
    while not existing.exists() and existing.parent != existing:
        if existing.is_symlink():
            raise InputError(f"cannot create the output directory: {existing} is a broken "
                             "symbolic link", file=str(out))
        existing = existing.parent
    if not existing.is_dir():
        raise InputError(f"cannot create the output directory: {existing} is not a directory",
                         file=str(out))
    if not os.access(existing, os.W_OK | os.X_OK):
        what = "directory" if existing == parent else "parent directory"
        raise InputError(f"the output {what} {existing} is not writable", file=str(out))


def check_output_path(out: Path, inputs: Iterable[Path] = (), *, xdmf: bool = False) -> None:
    """Refuse, before anything is computed, an output that cannot be written or whose
    writing would destroy something: raises InputError naming the path.

    Refused: a directory; a path below a regular file; a directory without write
    permission; an input file (compared as files: same inode, symbolic links followed),
    also through the plot or XDMF written beside the result; an existing file that is
    neither empty nor HDF5 (never overwritten); when the run writes XDMF (``xdmf``) a ':'
    in the file name, which XDMF cannot express.
    """
    out = Path(out)
    if out.name in ("", ".", ".."):
        raise InputError("the output must name a file, e.g. results/run.h5", file=str(out))
    if out.is_dir():
        raise InputError("the output is a directory; give a file name such as "
                         f"{out / 'run.h5'}", file=str(out))
    for suffix, what in DERIVED_SUFFIXES.items():
        if out.with_suffix(suffix) == out:
            raise InputError(f"the output must not end in {suffix}: {what} is written beside "
                             "the result under that name (use .h5)", file=str(out))
    if xdmf and ":" in out.name:
        raise InputError("the file name must not contain ':' (the XDMF description cannot "
                         "name such a file; or set output.xdmf = .false.)", file=str(out))
    derived = {out: "the output", out.with_suffix(".png"): "the plot written beside it",
               out.with_suffix(".xdmf"): "the XDMF written beside it",
               lock_path(out): "its lock file"}
    for source in inputs:
        for path, what in derived.items():
            if path.exists() and source.exists() and _same_file(path, source):
                if path == out:
                    raise InputError(f"the output is the input file {source}; choose another "
                                     "output file", file=str(out))
                raise InputError(f"{what} ({path}) would overwrite the input file {source}; "
                                 "choose another output file", file=str(out))
    _writable_parent(out)
    if out.exists() or out.is_symlink():
        if not out.exists():
            raise InputError("the output is a broken symbolic link", file=str(out))
        if not out.is_file():
            raise InputError("the output exists and is not a regular file", file=str(out))
        if not os.access(out, os.W_OK):
            raise InputError("the output file exists and is not writable", file=str(out))
        if out.stat().st_size and not _is_hdf5(out):
            raise InputError("the output file exists and is not an HDF5 file; refusing to "
                             "overwrite it (remove it or choose another output file)",
                             file=str(out))
