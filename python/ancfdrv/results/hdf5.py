"""HDF5 result files (SPEC section 4), written with h5py.

A file is created (and its root, /model and /counters written) before any solve, so a
failed run still leaves a readable file that says what was attempted.

Conventions:

* every dataset has a ``units`` attribute (SI: m, s, N, J, ...; '1' for dimensionless,
  'count' for counters, 'index' for connectivity); integer counters are stored as int64;
* the root attribute ``status`` is 'running' while the run writes, then 'ok', 'failed'
  (with ``message``), 'unstable' (the energy grew beyond solver.energy_tolerance, or a
  load-controlled static state has /static stability_index > 0, with ``message``:
  :class:`~ancfdrv.errors.UnstableError`) or 'interrupted' (SIGINT/SIGTERM:
  every step computed before the signal is in the file); /dynamic has the same
  ``status``. A file that still says 'running' while no process holds its lock
  (:mod:`ancfdrv.results.lock`) was abandoned: its writer was killed (every flushed chunk
  is kept);
* the root attributes carry the provenance: package version, git commit (when run from
  a checkout), library versions, compiler, platform, thread settings, command line.
"""
from __future__ import annotations

import contextlib
import datetime as _dt
import functools
import json
import os
import platform
import shlex
import subprocess
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any, Iterator

import h5py
import numpy as np

from .._version import __version__
from ..codes import mesh_parts
from ..errors import InputError
from ..system.model import Model
from ..io.safe_write import check_room, create_fresh
from ..io.scene import Scene
from ..solvers.static import StaticResult

if TYPE_CHECKING:
    from ..solvers.path import StaticPath
    from .xdmf import MeshLayout

#: the statuses a result file can carry (root attribute and /dynamic attribute)
STATUSES = ("running", "ok", "failed", "unstable", "interrupted")
#: generalized coordinates: positions (m) and position gradients (dimensionless)
COORDINATE_UNITS = "mixed (m for positions, 1 for gradients)"
#: constraint multipliers: forces for position constraints, moments for gradient ones
MULTIPLIER_UNITS = "mixed (N for position constraints, N m for gradient constraints)"
#: constraint values: lengths for position constraints, numbers for gradient ones
CONSTRAINT_UNITS = "mixed (m for position constraints, 1 for gradient constraints)"
CONTACT_UNITS = {"penetration": "m", "normal_force": "N", "friction_force": "N",
                 "slip_speed": "m/s", "xi": "1", "eta": "1"}
#: a buffered dynamic writer writes at least this often (and every chunk_steps rows)
FLUSH_SECONDS = 1.0
#: ... and when this many bytes of rows wait, once FLUSH_MIN_SECONDS have passed since its
#: last write: wide rows (q of every step, /dynamic/q) wait in bounded buffers (the 512-
#: element cantilever's 16 MB of q waited whole, and the merge of a flush copied them:
#: 92 MB peak against 66 MB without q; issue 23), and a write's fixed cost (~0.2 ms a
#: series) is paid at most a few times a second
FLUSH_BYTES = 4 << 20
FLUSH_MIN_SECONDS = 0.25


def _chunk_bytes(chunk) -> int:
    """The bytes a waiting chunk holds (its row arrays and its XDMF frames' points)."""
    return (sum(getattr(getattr(chunk, f, None), "nbytes", 0)
                for f in ("time", "probes", "deflections", "lam", "energy", "constraint",
                          "stats", "q", "contact"))
            + (chunk.frames[1].nbytes if getattr(chunk, "frames", None) else 0))


#: the text type of string attributes (h5py's: variable-length UTF-8)
_TEXT = h5py.string_dtype()


@functools.lru_cache(maxsize=None)
def _types(dtype: np.dtype) -> tuple[h5py.h5t.TypeID, h5py.h5t.TypeID]:
    """(file type, memory type) of a numpy dtype, as h5py's attribute and dataset creation
    makes them (``py_create`` logical and bit-for-bit); made once per dtype."""
    return h5py.h5t.py_create(dtype, logical=True), h5py.h5t.py_create(dtype)


def _attr_array(value: Any) -> np.ndarray | None:
    """The array h5py would store for an attribute value of the common kinds (text,
    integer, boolean as int64, float, numeric arrays); None for anything else."""
    if isinstance(value, str):
        return np.array(value, dtype=_TEXT)
    if isinstance(value, (bool, np.bool_, int, np.integer)):
        return np.array(np.int64(value))
    if isinstance(value, (float, np.floating)):
        return np.asarray(value)
    if isinstance(value, np.ndarray) and value.dtype.kind in "fiu" and value.ndim:
        return np.ascontiguousarray(value)
    return None


#: the dataspace of scalar attributes (made once; h5py's ``create_simple(())`` is scalar)
_SCALAR = h5py.h5s.create(h5py.h5s.SCALAR)


def _attrs(target: h5py.AttributeManager, values: dict[str, Any], *,
           fresh: bool = False) -> None:
    """Write attributes (bool and int as int64). The common kinds go through h5py's
    low-level API with the types made once (the same HDF5 types and values as
    ``attrs[key] = value``, a quarter of its cost: a run writes ~160 attributes); any
    other value through h5py's high-level API. ``fresh``: none of the names exists yet
    (a new object), so none is looked up to be replaced."""
    oid = target._id
    for key, value in values.items():
        data = _attr_array(value)
        if data is None:
            target[key] = value
            continue
        name = key.encode("utf-8")
        if not fresh and h5py.h5a.exists(oid, name):
            h5py.h5a.delete(oid, name)
        file_type, memory_type = _types(data.dtype)
        space = h5py.h5s.create_simple(data.shape) if data.ndim else _SCALAR
        attr = h5py.h5a.create(oid, name, file_type, space)
        try:
            attr.write(data, mtype=memory_type)
        finally:
            attr.close()


@functools.lru_cache(maxsize=64)
def _dataset_plist(chunks: tuple[int, ...] | None,
                   compact: bool = False) -> h5py.h5p.PropDCID:
    """A dataset creation property list as h5py's ``create_dataset`` makes it (no times
    tracked; chunked when ``chunks``; the compact layout, the values kept in the dataset's
    object header, when ``compact``); made once per chunk shape (HDF5 copies it into
    each dataset it creates)."""
    plist = h5py.h5p.create(h5py.h5p.DATASET_CREATE)
    if chunks is not None:
        plist.set_chunk(chunks)
    elif compact:
        plist.set_layout(h5py.h5d.COMPACT)
    plist.set_obj_track_times(False)
    return plist


#: the largest series written in the compact layout by the last flush (the values in the
#: object header: no separate block to allocate and index; HDF5 allows < 64 kB)
COMPACT_BYTES = 16 * 1024


@functools.lru_cache(maxsize=1)
def _group_plists() -> tuple[h5py.h5p.PropGCID, h5py.h5p.PropLCID]:
    """The group and link creation property lists h5py's ``create_group`` uses for an
    ASCII name (no times tracked, creation order not tracked, intermediate groups
    created)."""
    from h5py._hl.base import dlcpl
    gcpl = h5py.h5p.create(h5py.h5p.GROUP_CREATE)
    gcpl.set_obj_track_times(False)
    lcpl = dlcpl.copy()
    lcpl.set_char_encoding(h5py.h5t.CSET_ASCII)
    return gcpl, lcpl


def _subgroup(group: h5py.Group, name: str) -> h5py.Group:
    """``group.require_group(name)`` for a plain ASCII name, through h5py's low-level API
    (the group h5py makes, a fifth of the calls)."""
    if "/" in name or not name.isascii() or h5py.get_config().track_order:
        return group.require_group(name)
    key = name.encode("ascii")
    if group.id.links.exists(key):   # an existing member (HDF5 refuses to open a non-group)
        return h5py.Group(h5py.h5g.open(group.id, key))
    gcpl, lcpl = _group_plists()
    return h5py.Group(h5py.h5g.create(group.id, key, lcpl=lcpl, gcpl=gcpl))


def _has(group: h5py.Group, name: str) -> bool:
    """``name in group`` for a plain ASCII name (one low-level call)."""
    if "/" in name or not name.isascii():
        return name in group
    return group.id.links.exists(name.encode("ascii"))


@functools.lru_cache(maxsize=256)
def _text_array(text: str) -> np.ndarray:
    """The array a text attribute stores (made once per text: units repeat)."""
    return np.array(text, dtype=_TEXT)


def _parent(group: h5py.Group, name: str,
            groups: dict[str, h5py.Group] | None = None) -> tuple[h5py.Group, bytes]:
    """The group that holds ``name`` (its intermediate groups created as h5py does) and
    the last part of the name; ``groups``: the subgroups of ``group`` found so far."""
    head, _, tail = name.rpartition("/")
    if not head:
        return group, tail.encode("utf-8")
    if groups is None:
        return _subgroup(group, head), tail.encode("utf-8")
    if head not in groups:
        groups[head] = _subgroup(group, head)
    return groups[head], tail.encode("utf-8")


def _new_dataset(group: h5py.Group, name: str, data: np.ndarray | None = None, *,
                 shape: tuple[int, ...] | None = None, dtype: Any = None,
                 maxshape: tuple[int | None, ...] | None = None,
                 chunks: tuple[int, ...] | None = None,
                 units: str | None = None,
                 groups: dict[str, h5py.Group] | None = None,
                 compact: bool = False) -> h5py.h5d.DatasetID:
    """A new dataset through h5py's low-level API (what ``create_dataset`` stores, at a
    fifth of its cost), with its ``units`` attribute; ``data`` written when given;
    ``groups``: see :func:`_parent`."""
    parent, leaf = _parent(group, name, groups)
    if data is not None:
        shape, dtype = data.shape, data.dtype
    dtype = np.dtype(dtype)
    limit = None if maxshape is None else tuple(h5py.h5s.UNLIMITED if m is None else m
                                                for m in maxshape)
    space = h5py.h5s.create_simple(shape, limit)
    dataset = h5py.h5d.create(parent.id, leaf, _types(dtype)[0], space,
                              dcpl=_dataset_plist(chunks, compact))
    if data is not None:
        dataset.write(h5py.h5s.ALL, h5py.h5s.ALL, data)
    if units is not None:
        file_type, memory_type = _types(_TEXT)
        attr = h5py.h5a.create(dataset, b"units", file_type, _SCALAR)
        try:
            attr.write(_text_array(units), mtype=memory_type)
        finally:
            attr.close()
    return dataset


def _dataset(group: h5py.Group, name: str, data: Any, units: str) -> h5py.Dataset:
    """A new dataset holding ``data`` (integers and booleans as int64) with its ``units``;
    numbers and fixed-length byte strings through h5py's low-level API (:func:`_new_dataset`:
    a strided array, such as a reaction's force columns, copied contiguous first), other
    kinds through ``create_dataset``."""
    data = np.asarray(data)
    if data.dtype.kind in "iub":
        data = data.astype(np.int64)
    if data.dtype.kind not in "fiS":
        dataset = group.create_dataset(name, data=data)
        dataset.attrs["units"] = units
        return dataset
    if not data.flags.c_contiguous:   # (ascontiguousarray would make a scalar 1-d)
        data = np.ascontiguousarray(data)
    return h5py.Dataset(_new_dataset(group, name, data, units=units))


def _run(command: list[str], cwd: str | None = None) -> str:
    """First line of a command's output ('' when it fails or is missing)."""
    try:
        done = subprocess.run(command, cwd=cwd, capture_output=True, text=True, timeout=5,
                              check=False)
    except (OSError, subprocess.SubprocessError):
        return ""
    lines = done.stdout.strip().splitlines()
    return lines[0].strip() if done.returncode == 0 and lines else ""


def _source_tree() -> Path | None:
    """The checkout the package runs from (``<checkout>/python/ancfdrv``: an editable
    install, a development run), None for an installed package."""
    package = Path(__file__).resolve().parents[1]
    root = package.parents[1]
    if package.parent.name == "python" and (root / "meson.build").is_file():
        return root
    return None


def _build_info() -> tuple[str, str] | None:
    """(commit, compiler) as the build recorded them (``ancfdrv._build_info``, written by
    meson.build) for an installed package; None when running from the checkout or when a
    copy lacks the record."""
    if _source_tree() is not None:
        return None
    try:
        from .._build_info import COMPILER, GIT_COMMIT
    except ImportError:
        return None
    return GIT_COMMIT, COMPILER


def _git_commit() -> str:
    """'<sha>' or '<sha> (modified)': of the checkout the package runs from (asked from
    git), of the commit an installed package was built from (the build's record), else
    what git says of the package's directory."""
    built = _build_info()
    if built is not None:
        return built[0]
    here = str(Path(__file__).resolve().parent)
    sha = _run(["git", "rev-parse", "HEAD"], cwd=here)
    if not sha:
        return ""
    dirty = _run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=here)
    return sha + (" (modified)" if dirty else "")


def _compiler() -> str:
    """The Fortran compiler that built the kernel (Meson's record: the installed package's
    build record, an editable build's Meson introspection), else the first line of
    ``gfortran --version`` on PATH."""
    built = _build_info()
    if built is not None and built[1]:
        return built[1]
    try:
        from ..kernel import _kernel
        for parent in Path(_kernel.__file__).resolve().parents[:3]:
            info = parent / "meson-info" / "intro-compilers.json"
            if info.is_file():
                return json.loads(info.read_text())["host"]["fortran"]["full_version"]
    except Exception:  # noqa: BLE001 - provenance is best effort, never fatal
        pass
    line = _run(["gfortran", "--version"])
    return f"{line} (gfortran on PATH)" if line else ""


#: where the kernel's build finds MUMPS's C header (meson.build: mumps_seq, then /usr/include)
MUMPS_HEADERS = ("/usr/include/mumps_seq/dmumps_c.h", "/usr/include/dmumps_c.h")


def _mumps() -> str:
    """The MUMPS library the kernel loaded, with the version its header declares
    (MUMPS_VERSION; asking dpkg for the package took 80 ms of every run)."""
    try:
        from ..kernel import _kernel  # noqa: F401 - loads the library
        with open("/proc/self/maps") as maps:
            libraries = {line.split()[-1] for line in maps if "dmumps" in line}
    except OSError:
        return ""
    if not libraries:
        return ""
    name = Path(sorted(libraries)[0]).name
    for header in MUMPS_HEADERS:
        try:
            text = Path(header).read_text(errors="replace")
        except OSError:
            continue
        for line in text.splitlines():
            words = line.split()
            if len(words) == 3 and words[:2] == ["#define", "MUMPS_VERSION"]:
                return f"{name} (MUMPS {words[2].strip(chr(34))}, {header})"
    return name


def _scipy_version() -> str:
    """scipy's version without importing scipy, which a dynamic run never needs (issue 23:
    a run's memory): its ``version.py`` read as text (importlib.metadata would cost ~4 MB)."""
    if "scipy" in sys.modules:
        return sys.modules["scipy"].__version__
    import importlib.util
    spec = importlib.util.find_spec("scipy")
    try:
        text = (Path(spec.origin).parent / "version.py").read_text()
    except (AttributeError, TypeError, OSError):
        text = ""
    for line in text.splitlines():
        name, _, value = line.partition("=")
        value = value.strip()
        if name.strip() == "version" and value[:1] in ("'", '"'):
            return value.strip("'\"")
    import scipy
    return scipy.__version__


@functools.lru_cache(maxsize=1)
def _static_provenance() -> dict[str, str]:
    return {"git_commit": _git_commit(), "numpy_version": np.__version__,
            "scipy_version": _scipy_version(), "h5py_version": h5py.__version__,
            "hdf5_version": h5py.version.hdf5_version, "mumps": _mumps(),
            "compiler": _compiler(), "python_version": platform.python_version(),
            "platform": platform.platform()}


def provenance() -> dict[str, str]:
    """What produced a result: versions, compiler, platform, threads, command line."""
    out = {"ancfdrv_version": __version__, **_static_provenance()}
    for name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS"):
        out[name] = os.environ.get(name, "")
    out["command"] = shlex.join(sys.argv)
    return out


def open_result(path: str | Path, attempts: int = 50) -> h5py.File:
    """Open a result file for reading; retries while a writer holds HDF5's own lock (a
    running run opens the file for each chunk it writes). Raises InputError when the
    file is missing or is not HDF5."""
    path = Path(path)
    if path.is_dir():
        raise InputError("a directory, not a result file", file=str(path))
    if not path.is_file():
        raise InputError("result file not found", file=str(path))
    try:
        if not h5py.is_hdf5(path):
            raise InputError("not an HDF5 file", file=str(path))
    except OSError as exc:  # unreadable (permissions, I/O error)
        raise InputError(f"cannot read the file: {exc.strerror or exc}",
                         file=str(path)) from None
    for attempt in range(attempts):
        try:
            return h5py.File(path, "r")
        except OSError as exc:
            if attempt == attempts - 1 or "lock" not in str(exc).lower():
                if "truncated" in str(exc).lower():
                    raise InputError("the HDF5 file is truncated (shorter than its own "
                                     "header says: a copy or a write cut short)",
                                     file=str(path)) from None
                raise InputError(f"cannot read the HDF5 file ({exc})", file=str(path)) from None
            time.sleep(0.02)
    raise AssertionError("unreachable")


def _open_file(path: Path, mode: str = "a") -> h5py.File:
    """Open for writing. A reader holding HDF5's lock (``ancf info``, a viewer) delays a
    write by at most about a second; after that the writer goes on without HDF5's lock
    (the run's own lock, :mod:`ancfdrv.results.lock`, already excludes other writers), so a
    reader never makes a run fail. No chunk cache (HDF5's default: up to 1 MB a dataset):
    a writer writes each series once per opening, so the cache kept only what it was about
    to write (the XDMF frames' chunks of 200 kB at 512 elements; 0.2-0.6 MB of the
    cantilever's peak)."""
    for _ in range(50):
        try:
            return h5py.File(path, mode, rdcc_nbytes=0)
        except OSError as exc:
            if "lock" not in str(exc).lower():
                raise
            time.sleep(0.02)
    return h5py.File(path, mode, locking=False, rdcc_nbytes=0)


#: files a run keeps open between its writes (:func:`holding`): absolute path -> the open
#: file (None until the first write opens it)
_HELD: dict[str, h5py.File | None] = {}


class _Kept:
    """A held file as a context manager that does not close it."""

    def __init__(self, h5: h5py.File) -> None:
        self.h5 = h5

    def __enter__(self) -> h5py.File:
        return self.h5

    def __exit__(self, *exc: Any) -> None:
        return None


def _open_write(path: Path, mode: str = "a") -> Any:
    """The file for a write (``with _open_write(path) as h5``): opened and closed around
    it, or, while the run holds it (:func:`holding`), the one open file."""
    key = os.path.abspath(path)
    if key not in _HELD:
        return _open_file(path, mode)
    h5 = _HELD[key]
    if h5 is None or not h5.id.valid:
        h5 = _HELD[key] = _open_file(path, mode)
    return _Kept(h5)


@contextlib.contextmanager
def holding(path: str | Path) -> Iterator[None]:
    """Keep the result file open across the writes in the block (one open instead of one
    per write: the file was opened 8-13 times by a small run, ~1 ms each). Blocks that
    compute (solves, the stepping) run in :func:`released`, so the file on disk is closed
    and complete while the run computes, as without holding: a killed run keeps what was
    written, and ``ancf info`` reads a running file."""
    key = os.path.abspath(path)
    if key in _HELD:
        yield
        return
    _HELD[key] = None
    try:
        yield
    finally:
        h5 = _HELD.pop(key, None)
        if h5 is not None and h5.id.valid:
            h5.close()


@contextlib.contextmanager
def released(path: str | Path) -> Iterator[None]:
    """Inside :func:`holding`: close the file for the block (each write in it opens and
    closes the file), hold it again after."""
    key = os.path.abspath(path)
    if key not in _HELD:
        yield
        return
    h5 = _HELD.pop(key)
    if h5 is not None and h5.id.valid:
        h5.close()
    try:
        yield
    finally:
        _HELD[key] = None


def drop(path: str | Path) -> None:
    """Close a held file now, ignoring an error (after a failure: the next write reopens
    it and meets the error again if it lasts)."""
    key = os.path.abspath(path)
    h5 = _HELD.get(key)
    if key in _HELD:
        _HELD[key] = None
    if h5 is not None and h5.id.valid:
        try:
            h5.close()
        except Exception:  # noqa: BLE001 - the failure being handled matters more
            pass


def reading(path: str | Path) -> Any:
    """The file for reading (``with reading(path) as h5``): the held file, else opened
    read-only."""
    key = os.path.abspath(path)
    h5 = _HELD.get(key)
    if h5 is not None and h5.id.valid:
        return _Kept(h5)
    return h5py.File(path, "r")


def create(path: Path, scene: Scene, model: Model) -> None:
    """New result file with the root attributes (provenance included) and /model."""
    path.parent.mkdir(parents=True, exist_ok=True)
    create_fresh(path)  # never write through a symbolic link planted at the name
    check_room(path, 16 * model.ndof * 8)  # a full disk: refused before HDF5 writes
    bending = next((b.bending for b in model.bodies if b.bending is not None), None)
    with _open_write(path, "w-") as h5:
        _attrs(h5.attrs, {
            **provenance(),
            "created": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
            "scene": scene.text,
            "scene_file": str(scene.path),
            "overrides": "\n".join(scene.overrides),
            # the &parameters' values and each key given by an expression or a point
            # name ('address = as written => value'; SPEC section 8.2)
            "parameters": "\n".join(f"{k} = {v!r}" for k, v in scene.parameters.items()),
            "expressions": "\n".join(scene.expressions),
            "title": scene["scene"]["title"],
            "kind": scene.kind,
            "formulation": scene["scene"]["formulation"],
            "effects": ",".join(scene.effects),
            "warnings": "\n".join(model.warnings),
            "status": "running",
            "message": "",
            # what sweeps compare: probe and component (beams: the tip sag)
            "response_probe": (model.response or ("", 0))[0],
            "response_component": np.int64((model.response or ("", 0))[1]),
            "linear_joints": model.linear_joints,
            "iteration_matrix": "constant" if model.constant_policy else "refactorized",
            # 'continuum' or 'cubic' (beam.bending) of the first beam
            **({"bending": bending} if bending is not None else {}),
        }, fresh=True)
        group = _subgroup(h5, "model")
        model_attrs = dict(model.summary())
        geometry = model.plate_geometry()
        if geometry is not None:  # plates and leaves: initial node positions, connectivity
            _dataset(group, "nodes", geometry[0], "m")
            elements = _dataset(group, "elements", geometry[1], "index")
            elements.attrs["description"] = "corner nodes of each element (0-based rows of nodes)"
        beams = [b for b in model.bodies if b.section_directors]  # lines with a section
        if len(beams) == 1:
            _dataset(group, "node_s", beams[0].stations, "m")
        elif not beams:  # another line family alone (a cable: 6 coordinates per node)
            lines = [b for b in model.bodies if b.flexible and hasattr(b, "stations")]
            if len(lines) == 1:
                _dataset(group, "node_s", lines[0].stations, "m")
                model_attrs["node_coordinates"] = np.int64(lines[0].ncoordinates
                                                           // len(lines[0].stations))
        _dataset(group, "e0", model.e0, COORDINATE_UNITS)
        model_attrs["constraint_names"] = "\n".join(model.constraints.names)
        model_attrs["bodies"] = "\n".join(f"{b.name}: {type(b).__name__.lower()}"
                                          for b in model.bodies)
        if model.notes:
            model_attrs["notes"] = "\n".join(model.notes)
        _attrs(group.attrs, model_attrs, fresh=True)


def write_layout(h5: h5py.File, layout: MeshLayout) -> None:
    """/model/mesh: the initial points, the connectivity and what each point belongs to
    (:class:`~.xdmf.MeshLayout`)."""
    model = _subgroup(h5, "model")
    if _has(model, "mesh"):
        del model["mesh"]
    group = _subgroup(model, "mesh")
    _dataset(group, "points", layout.points, "m")
    kind, connectivity, ncells = layout.topology()
    topology = _dataset(group, "topology", connectivity, "index")
    _attrs(topology.attrs, {"description": (
        "XDMF connectivity (0-based rows of points): " + {
            "Quadrilateral": "the corner points of each plate element",
            "Polyline": "2-point lines (beam and cable elements, rigid body axes and "
                        "boxes, force elements, distance joints; a line from a point to "
                        "itself: a lone point, a point mass or a joint)",
            "Mixed": "per cell its XDMF code, then quad: 4 points; line: 2, 2 points (a "
                     "line from a point to itself: a lone point, a point mass or a "
                     "joint)"}[kind])}, fresh=True)
    _attrs(group.attrs, {"topology_type": kind, "ncells": np.int64(ncells),
                         "bodies": "\n".join(layout.bodies)}, fresh=True)


def write_static(path: Path, model: Model, result: StaticResult) -> None:
    """The /static group: q, lambda, probes, deflections, solver statistics and the mesh
    points at the state (``mesh_nodes``, ``mesh_displacement`` from /model/mesh/points)."""
    with _open_write(path) as h5:
        if _has(h5, "static"):
            del h5["static"]
        group = _subgroup(h5, "static")
        _dataset(group, "q", result.e, COORDINATE_UNITS)
        _dataset(group, "lambda", result.lam, MULTIPLIER_UNITS)
        history = _dataset(group, "residual_history", np.asarray(result.history, dtype=float),
                           "1")
        _attrs(history.attrs, {"description": "relative force residual per iteration"},
               fresh=True)
        for name, position in model.probe_positions(result.e).items():
            _dataset(group, f"probes/{name}", position, "m")
        for name, deflection in model.deflections(result.e).items():
            _dataset(group, f"deflection/{name}", deflection, "m")
        from .xdmf import MeshLayout
        layout = MeshLayout.from_model(model)
        if layout is not None:  # the deformed shape (ancf plot, the static XDMF)
            if "model/mesh" not in h5:
                write_layout(h5, layout)
            nodes = layout.positions(model, result.e[None, :])[0]
            _dataset(group, "mesh_nodes", nodes, "m")
            _dataset(group, "mesh_displacement", nodes - layout.points, "m")
        _attrs(group.attrs, {"method": result.method, "iterations": result.iterations,
                             "residual_norm": result.residual_norm,
                             "constraint_norm": result.constraint_norm,
                             "wall_time_s": result.wall_time_s, **result.extra}, fresh=True)
        if result.path is not None:
            _write_path(group, result.path)


def _write_path(group: h5py.Group, path: StaticPath) -> None:
    """/static/path of an arc-length run (solvers/path.StaticPath): the converged points'
    load factors, the control probe's displacement and the tangent's negative eigenvalue
    count, with the limit and bifurcation points as attributes."""
    _dataset(group, "path/load_factor", path.load_factor, "1")
    _dataset(group, "path/displacement", path.displacement, "m")
    _dataset(group, "path/negative_eigenvalues", path.negative_eigenvalues, "1")
    _attrs(group["path"].attrs, {
        "probe": path.probe, "target_load_factor": path.target_load_factor,
        "reached": path.reached, "message": path.message,
        "limit_points": np.asarray(path.limit_points, dtype=np.int64),
        "limit_load_factors": np.asarray(path.limit_load_factors, dtype=float),
        "bifurcation_points": np.asarray(path.bifurcation_points, dtype=np.int64),
        "description": "converged points of the arc-length path; limit_points and "
                       "bifurcation_points index them (a limit: an extremum of the load "
                       "factor, refined in limit_load_factors; a bifurcation: the count of "
                       "negative eigenvalues changes with no extremum)"}, fresh=True)


#: what the final status may add to a file (counters, timing and status attributes: 8.8 kB
#: on a new file); with less room left :func:`finish` writes nothing (OSError) rather than
#: have HDF5 fail inside its write, which leaves a file no reader can open
FINISH_BYTES = 64 * 1024


def phase_times(timing: dict[str, float]) -> dict[str, float]:
    """The phases SPEC section 4 names, summed over every analysis of a run (the static
    solve, the settling solve before a dynamic run, the stepping, the modal and buckling
    analyses): model build and assembly, factorization, solve, contact, output, total, and
    ``compute``, the first three together: what the run's numbers cost, without the
    process's start-up, the scene's reading and the writing of results (the time axis of
    a sweep's accuracy-versus-time chart)."""
    def summed(*names: str) -> float:
        return float(sum(timing.get(name, 0.0) for name in names))
    phases = {
        "assembly": summed("model", "static_assembly", "settle_assembly", "modal_assembly"),
        "factorization": summed("static_factorization", "settle_factorization",
                                "dynamic_setup"),
        "solve": summed("static_solve", "settle_solve", "dynamic_stepping", "modal_static",
                        "modal_eigen", "buckling_total"),
        "contact": 0.0,
        "output": summed("output", "dynamic_output"),
        "total": summed("total")}
    phases["compute"] = phases["assembly"] + phases["factorization"] + phases["solve"]
    return phases


def finish(path: Path, model: Model, timing: dict[str, float], status: str,
           message: str = "") -> None:
    """Counters, timing and the final status (also after a failure or an interrupt)."""
    if status not in STATUSES:
        raise ValueError(f"unknown status {status!r}")
    check_room(path, FINISH_BYTES, margin=0)
    with _open_write(path) as h5:
        for name in ("counters", "timing"):
            if _has(h5, name):
                del h5[name]
        counters = _subgroup(h5, "counters")
        _attrs(counters.attrs, {**{k: int(v) for k, v in sorted(model.counters.items())},
                                "constraint_evaluations": np.int64(
                                    model.constraints.evaluations)}, fresh=True)
        group = _subgroup(h5, "timing")
        # every timing, then the phases SPEC section 4 names (which replace a timing of the
        # same name), summed over the analyses (dynamic stepping counts as solve: the
        # kernel's factorization-free steps are substitutions and residuals)
        _attrs(group.attrs, {**{k: float(v) for k, v in timing.items()},
                             **phase_times(timing)}, fresh=True)
        _attrs(h5.attrs, {
            "status": status, "message": message,
            "finished": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
            "warnings": "\n".join(model.warnings)})
        if _has(h5, "dynamic"):
            _attrs(h5["dynamic"].attrs, {"status": status})
        has_motion = ("dynamic/mesh_nodes" in h5 and "dynamic/time" in h5
                      and len(h5["dynamic/time"]) > 0)
        series = None
        if has_motion:
            _last_frame(h5, model)
            from .xdmf import Series, xdmf_target, write_series
            try:  # described in this opening of the file (its views made), written after
                target = xdmf_target(path)
                series = Series.of(h5)
            except Exception as exc:  # noqa: BLE001 - an optional output never fails a run
                _no_xdmf(model, path, exc)
    if series is not None:
        try:
            write_series(series, target)
        except Exception as exc:  # noqa: BLE001 - an optional output never fails a run
            _no_xdmf(model, path, exc)


def _no_xdmf(model: Model, path: Path, exc: Exception) -> None:
    model.warnings.append(f"the XDMF description of {path} was not written: "
                          f"{type(exc).__name__}: {exc}")


def _last_frame(h5: h5py.File, model: Model) -> None:
    """A run that stopped (failure, interrupt) between XDMF frames: its last row becomes
    a frame too (from the stored q or q_last), so the motion ends where the run ended."""
    from .xdmf import MeshLayout
    group = h5["dynamic"]
    last = len(group["time"]) - 1
    if "q" in group and len(group["q"]) == last + 1:
        q_last = group["q"][last:last + 1]
    elif "q_last" in group:
        q_last = group["q_last"][()][None, :]
    else:
        return
    if "mesh_rows" not in group:
        return
    rows = group["mesh_rows"]
    if len(rows) and rows[-1] >= last:
        return
    layout = MeshLayout.from_model(model)
    if layout is None or layout.npoints != group["mesh_nodes"].shape[1]:
        return
    nodes = layout.positions(model, q_last)
    k = len(rows)
    for name, values in (("mesh_nodes", nodes),
                         ("mesh_displacement", nodes - layout.points[None, :, :]),
                         ("mesh_rows", np.array([last]))):
        _append_rows(group.id, name, k, values)   # (its view, if any: xdmf.Series.of)


def _text(value: Any) -> Any:
    return value.decode() if isinstance(value, bytes) else value


def read_summary(path: Path) -> dict[str, Any]:
    """The main figures of a result file as a flat dict (used by info, sweep, plot).
    Raises InputError when the file is missing, not HDF5 or not an ancfdrv result."""
    out: dict[str, Any] = {}
    with open_result(path) as h5:
        if not isinstance(h5.get("model"), h5py.Group):
            raise InputError("not an ancfdrv result file (no /model group)", file=str(path))
        out.update({k: _text(v) for k, v in h5.attrs.items()})
        out.update({f"model.{k}": _text(v) for k, v in h5["model"].attrs.items()})
        if "static" in h5:
            static = h5["static"]
            out.update({f"static.{k}": _text(v) for k, v in static.attrs.items()})
            for name in static.get("deflection", {}):
                out[f"static.deflection.{name}"] = static["deflection"][name][()]
                out[f"static.probes.{name}"] = static["probes"][name][()]
            for name in static.get("deflection_support", {}):  # general scenes
                out[f"static.deflection_support.{name}"] = \
                    static["deflection_support"][name][()]
        if "dynamic" in h5:
            dynamic = h5["dynamic"]
            out.update({f"dynamic.{k}": _text(v) for k, v in dynamic.attrs.items()})
            if "stages" in dynamic:
                out.update({f"stages.{k}": v for k, v in dynamic["stages"].attrs.items()})
            if "time" in dynamic and len(dynamic["time"]):
                out["dynamic.t_reached"] = float(dynamic["time"][-1])
                for name in dynamic.get("deflection", {}):
                    out[f"dynamic.deflection.{name}.final"] = dynamic["deflection"][name][-1]
                for name in dynamic.get("deflection_support", {}):  # general scenes
                    series = dynamic["deflection_support"][name]
                    if len(series):
                        out[f"dynamic.deflection_support.{name}.final"] = series[-1]
        out.update(eigen_summary(h5))
        if "timing" in h5:
            out.update({f"timing.{k}": v for k, v in h5["timing"].attrs.items()})
        if "counters" in h5:
            out.update({f"counters.{k}": v for k, v in h5["counters"].attrs.items()})
    return out


def run_figures(h5: h5py.File) -> dict[str, Any]:
    """What ``ancf run`` prints of its result file (open), under :func:`read_summary`'s
    keys: the model's counts, the static deflections (also relative to the supports) and
    the dynamic step; read alone (the whole summary reads ~150 attributes)."""
    model = h5["model"].attrs
    out: dict[str, Any] = {f"model.{k}": _text(model[k])
                           for k in ("nnodes", "ndof", "nconstraints")}
    static = h5.get("static")
    if static is not None:
        for name in static.get("deflection", {}):
            out[f"static.deflection.{name}"] = static["deflection"][name][()]
        for name in static.get("deflection_support", {}):
            out[f"static.deflection_support.{name}"] = static["deflection_support"][name][()]
    dynamic = h5.get("dynamic")
    if dynamic is not None and "dt" in dynamic.attrs:
        out["dynamic.dt"] = _text(dynamic.attrs["dt"])
    return out


def verdict(path: Path, summary: dict[str, Any] | None = None) -> tuple[str, str]:
    """What became of the run that wrote a result file: ('ok' | 'failed' | 'unstable' |
    'interrupted' | 'running' | 'abandoned' | 'unknown', one line saying why)."""
    from .lock import holder
    summary = read_summary(path) if summary is None else summary
    status = str(summary.get("status", ""))
    message = str(summary.get("message", "")).replace("\n", "; ")
    rows = ""
    if "dynamic.t_reached" in summary:
        rows = f"dynamic reached t = {summary['dynamic.t_reached']:.6g} s"
    if status == "running":
        writer = holder(path)
        if writer is not None:
            return "running", f"being written by {writer.describe()}" + (
                f"; {rows} so far" if rows else "")
        return "abandoned", ("status 'running' but no process writes it: the writer was "
                             "killed; the steps flushed before are kept"
                             + (f" ({rows})" if rows else ""))
    if status == "ok":
        return "ok", "the run finished" + (f"; {rows}" if rows else "")
    if status in ("failed", "unstable", "interrupted"):
        detail = message or status
        return status, detail + (f" ({rows})" if rows and rows not in detail else "")
    return "unknown", f"status attribute {status!r}"


def _append_rows(group_id: h5py.h5g.GroupID, name: str, start: int,
                 values: np.ndarray) -> None:
    """Rows start.. of the extendable dataset group/name := values, through h5py's
    low-level API (its high-level lookup, resize and slice assignment cost ~0.2 ms per
    series and flush: a third of the output time of a small model's run)."""
    data = h5py.h5d.open(group_id, name.encode())
    shape = data.shape
    values = np.ascontiguousarray(values, dtype=data.dtype)
    data.set_extent((start + len(values), *shape[1:]))
    if values.size == 0:
        return
    space = data.get_space()
    space.select_hyperslab((start,) + (0,) * (len(shape) - 1), values.shape)
    data.write(h5py.h5s.create_simple(values.shape), space, values)


def _steps(chunk, before) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(step_size, substeps, step_cuts) of a chunk's rows; a chunk without them: one
    step each, of the rows' time difference (``before``: the time of the row before
    the chunk, None for the initial row, whose step is 0)."""
    n = len(chunk.time)
    size = getattr(chunk, "step_size", None)
    if size is None:
        previous = np.concatenate([[chunk.time[0] if before is None else before],
                                   chunk.time[:-1]]) if n else np.zeros(0)
        size = chunk.time - previous
    substeps = getattr(chunk, "substeps", None)
    if substeps is None:
        substeps = (np.asarray(size) > 0).astype(np.int64)
    cuts = getattr(chunk, "cuts", None)
    if cuts is None:
        cuts = np.zeros(n, dtype=np.int64)
    return (np.asarray(size, dtype=float), np.asarray(substeps, dtype=np.int64),
            np.asarray(cuts, dtype=np.int64))


def row_series(chunk, probe_names: list[str], npoints: int, total0: float,
               before: float | None) -> list[tuple[str, np.ndarray]]:
    """The rows of a chunk as /dynamic stores them: (series name, values) in the order the
    writer writes them (time, probes, deflection, lambda, energy with its balance, contact,
    constraint_violation, the step statistics, step_size, substeps, step_cuts), q apart.
    ``total0``: the total energy of the run's first row; ``before``: the time of the row
    before the chunk (None for a chunk that starts the run or carries its step sizes).
    The one place these values are made: the file's writer and a run kept in memory
    (:mod:`ancfdrv.results.memory`) both use it."""
    from ..solvers.dynamic import CONTACT_FIELDS, ENERGY_NAMES
    out: list[tuple[str, np.ndarray]] = [("time", chunk.time)]
    for p, name in enumerate(probe_names):
        out.append((f"probes/{name}", chunk.probes[:, p, :]))
        out.append((f"deflection/{name}", chunk.deflections[:, p, :]))
    out.append(("lambda", chunk.lam))
    for k, name in enumerate(ENERGY_NAMES):
        out.append((f"energy/{name}", chunk.energy[:, k]))
    # total - total(0) - work of drives, moving frames, contact damping, friction and
    # material damping
    out.append(("energy/balance", chunk.energy[:, 4] - total0 - chunk.energy[:, 5]
                - chunk.energy[:, 6] - chunk.energy[:, 8] - chunk.energy[:, 9]
                - chunk.energy[:, 10]))
    if npoints and chunk.contact is not None:
        for k, name in enumerate(CONTACT_FIELDS):
            out.append((f"contact/{name}", chunk.contact[:, :, k]))
    out.append(("constraint_violation", chunk.constraint))
    out.append(("newton_iterations", np.rint(chunk.stats[:, 0]).astype(np.int64)))
    out.append(("factorizations", np.rint(chunk.stats[:, 1]).astype(np.int64)))
    out.append(("jacobian_evaluations", np.rint(chunk.stats[:, 2]).astype(np.int64)))
    size, substeps, cuts = _steps(chunk, before)
    out += [("step_size", size), ("substeps", substeps), ("step_cuts", cuts)]
    return out


#: the fields of a chunk besides q that the writer stores (copied by :func:`thinned_chunk`)
ROW_FIELDS = ("time", "probes", "deflections", "lam", "energy", "constraint", "stats",
              "contact", "step_size", "substeps", "cuts")


#: the most XDMF views (virtual datasets) made in one opening of the file: HDF5 holds
#: ~20 kB of memory for each view made until the file is closed (the 128-element
#: cantilever's 201 views: 4 MB at the end of the run); each further opening costs ~1 ms
VIEWS_PER_OPENING = 32


def _add_views(path: Path, first: int, stop: int) -> None:
    """The XDMF views of frames first <= k < stop (:func:`~.xdmf.add_step_views`), at most
    VIEWS_PER_OPENING of them in each opening of the file (a held file is closed for it)."""
    from .xdmf import add_step_views
    with released(path):
        for start in range(first, stop, VIEWS_PER_OPENING):
            with _open_write(path) as h5:
                add_step_views(h5, start, min(start + VIEWS_PER_OPENING, stop))


#: the most bytes of XDMF frames' points a flush joins into one write (the writes of a
#: group cost ~0.6 ms whatever its frames)
FRAME_GROUP_BYTES = 1 << 18


def _frame_groups(parts: list[tuple[np.ndarray, np.ndarray]], limit: int
                  ) -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """Consecutive frame parts (rows, points) joined into groups of at most ``limit``
    bytes of points (a part larger than that alone), in order."""
    group: list[tuple[np.ndarray, np.ndarray]] = []
    size = 0
    for part in parts:
        if group and size + part[1].nbytes > limit:
            yield _joined_frames(group)
            group, size = [], 0
        group.append(part)
        size += part[1].nbytes
    if group:
        yield _joined_frames(group)


def _joined_frames(group: list[tuple[np.ndarray, np.ndarray]]
                   ) -> tuple[np.ndarray, np.ndarray]:
    if len(group) == 1:
        return group[0]
    return np.concatenate([g[0] for g in group]), np.concatenate([g[1] for g in group])


def thinned_chunk(chunk, first_row: int, stride: int, last_row: int, frames: bool):
    """A chunk without q, as a writer keeps it when /dynamic/q is not stored: the
    :data:`ROW_FIELDS` copied, ``q_last`` (the last row's q) and ``q = None``; and its
    frame rows (the XDMF frames' rows: every ``stride``-th row counted from the run's
    first and ``last_row``; ``first_row`` is the chunk's first row in the run), as
    (rows, q at those rows), or None when ``frames`` is False or no row is a frame row.
    Used by the file's :class:`DynamicWriter` and by the in-memory writer alike."""
    from types import SimpleNamespace
    copies = {}
    made = getattr(chunk, "rows", None)
    if made is not None:
        # the fields still the views of the kernel's rows they were made as: the rows'
        # columns before q copied once and the same views made of the copy (one copy of
        # nt rows instead of one strided copy per field; the same values)
        rows, width, fields, make = made
        fresh = make(np.array(rows[:, :width]))
        copies = {f: fresh[f] for f, v in fields.items()
                  if v is not None and getattr(chunk, f, None) is v}
    out = SimpleNamespace(**{f: copies[f] if f in copies else None
                             if getattr(chunk, f, None) is None
                             else np.array(getattr(chunk, f)) for f in ROW_FIELDS})
    out.q = None
    n = len(chunk.time)
    out.q_last = np.array(chunk.q[-1]) if n else None
    if not (frames and n):
        return out, None
    # the frame rows: every stride-th row of the run and last_row (ascending), picked
    # by index (a mask over every row cost as much as the copy)
    picked = np.arange((-first_row) % stride, n, stride)
    if 0 <= last_row - first_row < n and last_row % stride:
        at = last_row - first_row
        picked = np.insert(picked, int(np.searchsorted(picked, at)), at)
    return out, ((first_row + picked, chunk.q[picked]) if len(picked) else None)


def complete_answers(recorder) -> bool:
    """Record the chunk still waiting in a DynamicAnswers recorder (``complete()``), before
    its answers are written or kept. False when that fails (as when a chunk fails in the
    runner's sink): the answers are then not written, and the model's warnings say why."""
    complete = getattr(recorder, "complete", None)
    if complete is None:
        return True
    from ..errors import AncfError
    try:
        complete()
    except (AncfError, ValueError, FloatingPointError) as exc:
        recorder.model.warnings.append(f"dynamic reactions, section forces and stresses "
                                       f"not recorded: {exc}")
        return False
    return True


class DynamicWriter:
    """Appends the chunks of a dynamic run to /dynamic (SPEC section 4).

    Chunks are buffered and written together (merged: one write per series), with the
    file closed after each write, whenever ``flush_rows`` rows are waiting or
    FLUSH_SECONDS have passed since the last write (or since the writer was made: the
    initial row waits for the rows after it, one write instead of two in a short run);
    :meth:`flush` writes the rest. So the file on disk lags the computation by at most
    ``flush_rows`` rows or about a second (the runner sizes ``flush_rows`` to ~16 MB),
    and a run that stops (failure, SIGINT, SIGTERM) flushes everything.
    """

    def __init__(self, path: Path, model: Model, store_q: bool,
                 flush_rows: int = 1, *, xdmf: bool | None = None, total_rows: int = 0,
                 frames: int = 1000, write_q: bool | None = None) -> None:
        """``store_q``: the chunks carry the coordinates q of every step. ``write_q``: they
        go to /dynamic/q (None: whenever the chunks carry them); otherwise only the last
        row's, as /dynamic/q_last. ``xdmf``: write the node positions of every body for
        the XDMF description (needs ``store_q``; None: for models with plates, as before),
        at most ``frames`` of the ``total_rows`` rows the run will write
        (:func:`~.xdmf.frame_rows`)."""
        from ..solvers.dynamic import CONTACT_FIELDS, ENERGY_NAMES
        from .xdmf import MeshLayout, frame_count, frame_rows, inline
        self.path, self.names, self.store_q = path, list(model.probes), store_q
        self.write_q = store_q if write_q is None else bool(write_q and store_q)
        self.flush_rows = max(1, int(flush_rows))
        self.model = model
        self.npoints = model.npoint
        self.contact_fields = CONTACT_FIELDS
        if xdmf is None:
            xdmf = bool(model.plate_bodies())
        self.layout = MeshLayout.from_model(model) if xdmf and store_q else None
        self.nnodes = self.layout.npoints if self.layout is not None else 0
        self.stride, self.last_row = frame_rows(total_rows, frames) if total_rows > 0 \
            else (1, -1)
        # the per-frame views a larger series' XDMF description names, made at each flush
        # (a small one carries its values inline: :func:`~.xdmf.inline`)
        self.views = bool(self.nnodes) and (
            total_rows <= 0 or not inline(self.nnodes, frame_count(total_rows, frames)))
        self.frames = 0
        self.energy_names = ENERGY_NAMES
        self.rows = 0
        self.ndof = model.ndof
        self._q_last = bool(store_q and not self.write_q)   # /dynamic/q_last is written
        self._q_last_made = False
        self._pending: list[Any] = []
        self._pending_rows = 0
        self._pending_bytes = 0
        self._row_bytes: int | None = None   # a waiting row's bytes (:meth:`_waiting_bytes`)
        self._last_write = time.monotonic()
        ncon, ndof = len(model.constraints), model.ndof
        self.total_rows = total_rows
        # what a flush may allocate besides its rows: one HDF5 chunk of every series
        self.chunk_bytes = 8 * (self._chunk_rows(1) * (4 + 16) + self._chunk_rows(3)
                                * 6 * len(self.names) + self._chunk_rows(max(ncon, 1))
                                * max(ncon, 1) + self._chunk_rows(max(self.npoints, 1))
                                * 8 * self.npoints + 16 * (ndof + 6 * self.nnodes))
        check_room(path, self.chunk_bytes)
        with _open_write(path) as h5:
            if _has(h5, "dynamic"):
                del h5["dynamic"]
            group = _subgroup(h5, "dynamic")
            _attrs(group.attrs, {"status": "running", "rows": np.int64(0)}, fresh=True)

            # the row series are made by the first flush, with its rows (one HDF5 call per
            # series instead of two: a short run writes once); ``series`` records them
            self._series: dict[str, tuple] = {}
            self._made: set[str] = set()
            self._group_attrs: dict[str, dict[str, Any]] = {}
            self._groups: dict[str, h5py.Group] = {}  # /dynamic's subgroups (one opening)

            def series(name: str, units: str, width: tuple[int, ...] = (),
                       dtype: str = "f8", attrs: dict[str, Any] | None = None,
                       now: bool = False, rows: int | None = None) -> None:
                # a model without constraints has lambda[nt, 0]: HDF5 chunks must be
                # positive, so that axis gets a free maximum
                chunk = tuple(max(1, w) for w in width)
                limit = tuple(w if w else None for w in width)
                self._series[name] = (units, width, np.dtype(dtype), (None, *limit),
                                      (rows or self._chunk_rows(int(np.prod(chunk))),
                                       *chunk)
                                      if width != (ndof,) else (16, ndof), attrs or {})
                if now:
                    self._make(group, name, None)
            series("time", "s")
            for name in self.names:
                series(f"probes/{name}", "m", (3,))
                series(f"deflection/{name}", "m", (3,))
            series("lambda", MULTIPLIER_UNITS, (ncon,))
            for name in ENERGY_NAMES:
                series(f"energy/{name}", "J")
            series("energy/balance", "J")
            series("constraint_violation", CONSTRAINT_UNITS)
            series("newton_iterations", "count", dtype="i8")
            series("factorizations", "count", dtype="i8")
            series("jacobian_evaluations", "count", dtype="i8")
            # step control (issue 26): which step reached each row, how many steps and cuts
            series("step_size", "s", attrs={"description": (
                "the smallest step taken to reach the row (0 for the initial row); the rows "
                "stay on the grid t0 + k dt, steps land on it exactly")})
            series("substeps", "count", dtype="i8")
            series("step_cuts", "count", dtype="i8")
            if self.npoints:  # per contact point: penetration, forces, slip, projection
                for name in CONTACT_FIELDS:
                    series(f"contact/{name}", CONTACT_UNITS.get(name, "1"), (self.npoints,))
                self._group_attrs["contact"] = {
                    "points": "\n".join(model.contact_point_names)}
            if self.write_q:
                series("q", COORDINATE_UNITS, (ndof,))
            # q_last (store_q without write_q): where a run that stops between XDMF frames
            # ends; made by the first flush with its value, as the series (not made here
            # and reopened by every flush: ~0.2 ms of a short run)
            if self.nnodes:  # points of every body per frame, for ParaView (XDMF)
                write_layout(h5, self.layout)
                for name in ("mesh_nodes", "mesh_displacement"):
                    data = group.create_dataset(name, shape=(0, self.nnodes, 3),
                                                maxshape=(None, self.nnodes, 3), dtype="f8",
                                                chunks=(16, self.nnodes, 3))
                    data.attrs["units"] = "m"
                series("mesh_rows", "index", dtype="i8", now=True, rows=1024, attrs={
                    "description": "the row of /dynamic/time of each row of mesh_nodes "
                                   "(XDMF frames)"})

    #: the rows of a series' HDF5 chunk: the run's rows when known (one chunk: a run
    #: written at its end writes each series in one piece, 2 ms less for 10000 rows), at
    #: most CHUNK_BYTES per chunk, at least 1024 rows
    CHUNK_BYTES = 256 * 1024

    def _chunk_rows(self, width: int) -> int:
        """Rows per HDF5 chunk of a series with ``width`` numbers per row."""
        if self.total_rows <= 0:
            return 1024
        return min(self.total_rows, max(1024, self.CHUNK_BYTES // (8 * max(width, 1))))

    def _make(self, group: h5py.Group, name: str, values: np.ndarray | None) -> None:
        """Series ``name`` of /dynamic, holding ``values`` (None: no rows); made by the
        last flush (:meth:`flush_last`) not extendable: compact up to COMPACT_BYTES,
        else contiguous."""
        units, width, dtype, limit, chunks, attrs = self._series[name]
        if values is None:
            values = np.zeros((0, *width), dtype=dtype)
        values = np.ascontiguousarray(values, dtype=dtype)
        compact = False
        if self._last:
            limit = chunks = None
            compact = values.nbytes <= COMPACT_BYTES
        dataset = _new_dataset(group, name, values, maxshape=limit, chunks=chunks, units=units,
                               groups=self._groups, compact=compact)
        if attrs:
            _attrs(h5py.AttributeManager(h5py.Dataset(dataset)), attrs, fresh=True)
        self._made.add(name)
        head = name.rpartition("/")[0]
        if head in self._group_attrs:
            _attrs(self._groups[head].attrs, self._group_attrs.pop(head), fresh=True)

    def _put(self, group: h5py.Group, name: str, values: np.ndarray) -> None:
        """Rows self.rows.. of series ``name``: appended, or the series made with them."""
        if name in self._made:
            _append_rows(group.id, name, self.rows, values)
        else:
            self._make(group, name, values)

    def _make_rest(self, group: h5py.Group) -> None:
        """The series no flush has written yet, without rows (every series exists once
        the run has written; a chunk without contact data leaves those empty), and
        q_last (zeros) when no row gave it."""
        for name in self._series:
            if name not in self._made:
                self._make(group, name, None)
        if self._q_last and not self._q_last_made:
            self._put_q_last(group, None)

    def _put_q_last(self, group: h5py.Group, values: np.ndarray | None) -> None:
        """/dynamic/q_last := values (None: made without a value, it reads zeros); made
        by its first write (compact up to COMPACT_BYTES, else contiguous: never
        extended), written in place after."""
        if values is not None:
            values = np.ascontiguousarray(values, dtype=np.float64)
        if not self._q_last_made:
            _new_dataset(group, "q_last", values, shape=(self.ndof,), dtype="f8",
                         units=COORDINATE_UNITS,
                         compact=8 * self.ndof <= COMPACT_BYTES)
            self._q_last_made = True
        elif values is not None:
            h5py.h5d.open(group.id, b"q_last").write(h5py.h5s.ALL, h5py.h5s.ALL, values)

    def _unmade(self) -> bool:
        """Some series (or q_last) is not in the file yet."""
        return len(self._made) < len(self._series) or (self._q_last
                                                       and not self._q_last_made)

    def __call__(self, chunk) -> None:
        if self.store_q and not self.write_q and getattr(chunk, "q", None) is not None:
            chunk = self._thinned(chunk)
        self._pending.append(chunk)
        self._pending_rows += len(chunk.time)
        self._pending_bytes += self._waiting_bytes(chunk)
        since = time.monotonic() - self._last_write
        if (self._pending_rows >= self.flush_rows or since >= FLUSH_SECONDS
                or (self._pending_bytes >= FLUSH_BYTES and since >= FLUSH_MIN_SECONDS)):
            self.flush()

    def _waiting_bytes(self, chunk) -> int:
        """About :func:`_chunk_bytes` of a waiting chunk: its rows times the bytes of a row
        of the run's first chunk after the initial row (the stepper's rows have one layout;
        an interval of cut or adaptive steps counts its steps in int64: 12 bytes a row
        more), and its frames' points. A single step under step control is a chunk: the
        ten attribute reads of :func:`_chunk_bytes` would cost ~1 us of its ~60."""
        rows = len(chunk.time)
        if self._row_bytes is None:
            exact = _chunk_bytes(chunk)
            if rows and self.rows + self._pending_rows > rows:   # not the initial row
                frames = getattr(chunk, "frames", None)
                self._row_bytes = (exact - (frames[1].nbytes if frames else 0)) // rows
            return exact
        frames = getattr(chunk, "frames", None)
        return rows * self._row_bytes + (frames[1].nbytes if frames else 0)

    def _thinned(self, chunk):
        """The chunk as it waits for the next flush when /dynamic/q is not written
        (:func:`thinned_chunk`), its frame rows' q turned into the XDMF frames' points now
        (row by row as the flush would). The kernel's row buffer, mostly q, is then
        released at once instead of waiting up to FLUSH_SECONDS (issue 23: at 2052 unknowns
        ~16 kB per step waited, and the flush's merge copied it again). The file is the
        same."""
        out, frame = thinned_chunk(chunk, self.rows + self._pending_rows, self.stride,
                                   self.last_row, bool(self.nnodes))
        out.frames = None if frame is None else (
            frame[0], self.layout.positions(self.model, frame[1]))
        return out

    #: set by :meth:`flush_last` while it flushes: no rows follow
    _last = False

    def flush_last(self) -> None:
        """The run has ended: :meth:`flush` the rest, no rows follow. The series this
        flush makes (all of them in a run that ends before its first flush deadline, e.g.
        any run shorter than FLUSH_SECONDS) are not extendable: compact up to
        COMPACT_BYTES, else contiguous (less to allocate and index than a chunked one)."""
        self._last = True
        try:
            self.flush()
        finally:
            self._last = False

    def flush(self) -> None:
        """Write every buffered chunk (one open of the file)."""
        if not self._pending:
            if self._unmade():  # no row at all: the empty series
                with _open_write(self.path) as h5:
                    self._groups = {}
                    self._make_rest(h5["dynamic"])
            return
        # a full disk or file-size limit: refused before HDF5 writes (a write failing
        # inside HDF5 can crash it), the rows written before stay readable
        pending = sum(_chunk_bytes(chunk) for chunk in self._pending)
        try:
            check_room(self.path, 2 * pending + self.chunk_bytes)
        except OSError:
            rest = self._pending[1:]
            if self.rows == 0 and rest:  # the run's initial row alone, if it fits, is kept
                self._pending = self._pending[:1]
                last, self._last = self._last, False   # rows follow: extendable series
                try:
                    self.flush()
                finally:  # the other rows still wait (a later flush meets the error again)
                    self._last = last
                    self._pending = self._pending + rest
                    self._pending_rows = sum(len(chunk.time) for chunk in self._pending)
                    self._pending_bytes = sum(_chunk_bytes(chunk) for chunk in self._pending)
            raise
        with _open_write(self.path) as h5:
            group = h5["dynamic"]
            self._groups = {}  # the subgroups found in this opening of the file
            first = self.frames
            # the waiting chunks as one: one HDF5 write per series and flush (each write
            # costs ~0.2 ms, whatever its rows)
            self._append(group, self._merged(group) if len(self._pending) > 1
                         else self._pending[0])
            if self._unmade():
                self._make_rest(group)
            _attrs(group.attrs, {"rows": np.int64(self.rows)})
        if self.views and self.frames > first:
            _add_views(self.path, first, self.frames)
        self._pending, self._pending_rows, self._pending_bytes = [], 0, 0
        self._last_write = time.monotonic()

    def _merged(self, group: h5py.Group):
        """The waiting chunks as one chunk (their rows in order; the step sizes, substeps
        and cuts of chunks without them as :func:`_steps` gives them)."""
        from types import SimpleNamespace
        chunks = self._pending
        before = group["time"][self.rows - 1] if self.rows else None
        steps = []
        for chunk in chunks:
            steps.append(_steps(chunk, before))
            if len(chunk.time):
                before = chunk.time[-1]

        def joined(field: str):
            parts = [getattr(c, field, None) for c in chunks]
            if any(p is None for p in parts):
                return None
            return np.concatenate(parts)
        merged = SimpleNamespace(**{f: joined(f) for f in (
            "time", "probes", "deflections", "lam", "energy", "constraint", "stats", "q",
            "contact")})
        merged.step_size, merged.substeps, merged.cuts = (
            np.concatenate([s[k] for s in steps]) for k in range(3))
        if any(hasattr(c, "q_last") for c in chunks):   # thinned chunks (:meth:`_thinned`)
            lasts = [c.q_last for c in chunks if getattr(c, "q_last", None) is not None]
            merged.q_last = lasts[-1] if lasts else None
            # the frames stay the chunks' parts, written a bounded group at a time
            # (:meth:`_append`): joined whole, with their displacements, they were three
            # copies of a second's frames (6 MB at the 512-element cantilever's 1539 points)
            merged.frames = None
            merged.frame_parts = [c.frames for c in chunks
                                  if getattr(c, "frames", None) is not None]
        return merged

    def _append(self, group: h5py.Group, chunk) -> None:
        n = len(chunk.time)
        total0 = group["energy/total"][0] if self.rows else chunk.energy[0, 4]
        before = group["time"][self.rows - 1] \
            if self.rows and getattr(chunk, "step_size", None) is None else None
        for name, values in row_series(chunk, self.names, self.npoints, total0, before):
            self._put(group, name, values)
        if self.store_q and getattr(chunk, "q_last", None) is not None:   # thinned
            self._put_q_last(group, chunk.q_last)
            parts = getattr(chunk, "frame_parts", None)
            if parts is None:
                parts = [] if chunk.frames is None else [chunk.frames]
            for rows, nodes in _frame_groups(parts, FRAME_GROUP_BYTES):
                self._write_frames(group, rows, nodes)
        elif self.store_q and chunk.q is not None:
            if self.write_q:
                self._put(group, "q", chunk.q)
            elif n:
                self._put_q_last(group, chunk.q[-1])
            if self.nnodes:
                self._append_frames(group, chunk.q)
        self.rows += n

    def _append_frames(self, group: h5py.Group, q: np.ndarray) -> None:
        """The points' positions at the chunk's frame rows (every stride-th and the last)."""
        rows = self.rows + np.arange(len(q))
        pick = (rows % self.stride == 0) | (rows == self.last_row)
        if not pick.any():
            return
        self._write_frames(group, rows[pick], self.layout.positions(self.model, q[pick]))

    def _write_frames(self, group: h5py.Group, rows: np.ndarray, nodes: np.ndarray) -> None:
        """Append frames: the rows of /dynamic/time they show and their points."""
        for name, values in (("mesh_nodes", nodes),
                             ("mesh_displacement", nodes - self.layout.points[None, :, :]),
                             ("mesh_rows", rows)):
            _append_rows(group.id, name, self.frames, values)
        self.frames += len(nodes)


def write_dynamic_attrs(path: Path, attrs: dict[str, Any], stages: dict[str, float]) -> None:
    """Integrator statistics and the per-stage summary (attributes of /dynamic)."""
    with _open_write(path) as h5:
        group = h5["dynamic"]
        _attrs(group.attrs, attrs)
        if stages:
            stage_group = group.require_group("stages")
            _attrs(stage_group.attrs, stages)


def write_support_deflections(path: Path, analysis: str, deflections: dict[str, np.ndarray],
                              frames: dict, reference: str, displacement: str) -> None:
    """/<analysis>/deflection_support/<probe> (the probes' deflection relative to the rigid
    motion of their beam's supports, :mod:`ancfdrv.system.supports`), with the attribute
    ``reference`` saying what it is, each probe's ``frame`` (beam and joints), and the
    attribute ``reference`` of /<analysis>/deflection saying what that one is
    (``displacement``)."""
    with _open_write(path) as h5:
        group = h5[analysis]
        if "deflection" in group:
            group["deflection"].attrs["reference"] = displacement
        if not deflections:
            return
        if "deflection_support" in group:
            del group["deflection_support"]
        support = _subgroup(group, "deflection_support")
        support.attrs["reference"] = reference
        for name, values in deflections.items():
            data = _dataset(support, name, values, "m")
            frame = frames.get(name)
            if frame is not None:
                data.attrs["frame"] = frame


# -- engineering answers (SPEC section 10) -----------------------------------------------------
def _reaction_group(group: h5py.Group, name: str, force, moment, axial, kind: str) -> None:
    """/<phase>/reactions/<name>; ``kind``: 'joint' or 'force element' (what ``ancf info``
    calls it)."""
    sub = _subgroup(group, name)
    _dataset(sub, "force", np.asarray(force, dtype=float), "N")
    _dataset(sub, "moment", np.asarray(moment, dtype=float), "N m")
    if axial is not None:
        _dataset(sub, "axial", np.asarray(axial, dtype=float), "N")
    _attrs(sub.attrs, {"kind": kind,
                       "description": "what body1 exerts on body2, global axes; moment "
                                      "about the joint's point on body2; axial: tension "
                                      "positive"}, fresh=True)


def _reaction_kind(name: str, force_elements: set[str]) -> str:
    return "force element" if name in force_elements else "joint"


def _section_group(group: h5py.Group, name: str, forces) -> None:
    sub = _subgroup(group, name)
    _dataset(sub, "s", forces.s, "m")
    for key, units in (("N", "N"), ("T", "N m"), ("Q", "N"), ("M", "N m")):
        _dataset(sub, key, getattr(forces, key), units)
    _attrs(sub.attrs, {"description": "what the part beyond s exerts on the part before it; "
                                      "Q and M: components along the section's height and "
                                      "width axes"}, fresh=True)


def write_static_answers(path: Path, model: Model, e: np.ndarray, lam: np.ndarray,
                         stations: int = 3, answers=None) -> None:
    """/static/reactions/<joint>, /static/sections/<beam>, /static/stress/<beam> of the
    static state (ancfdrv.system.answers), and /model/constraint_joints (the joint of each
    row of lambda). ``answers``: the state's :func:`~ancfdrv.system.answers.static_answers`
    when already computed (a run kept in memory, saved after its model's kernel was
    released), else computed here."""
    from ..system.answers import constraint_joints, static_answers
    if answers is None:
        answers = static_answers(model, e, lam, stations)
    found, forces, stress = answers.reactions, answers.sections, answers.stress
    with _open_write(path) as h5:
        group = _subgroup(h5, "static")
        for key in ("reactions", "sections", "stress"):
            if _has(group, key):
                del group[key]
        if found:
            reactions_group = _subgroup(group, "reactions")
            elements = {f.name for f in getattr(model, "force_elements", ())}
            for name, r in found.items():
                _reaction_group(reactions_group, name, r.force, r.moment, r.axial,
                                _reaction_kind(name, elements))
        if forces:
            sections_group = _subgroup(group, "sections")
            stress_group = _subgroup(group, "stress")
            for name, f in forces.items():
                _section_group(sections_group, name, f)
                sub = _subgroup(stress_group, name)
                _dataset(sub, "s", f.s, "m")
                _dataset(sub, "sigma_x", stress[name].sigma_x, "Pa")
                _dataset(sub, "von_mises", stress[name].von_mises, "Pa")
                k = int(np.argmax(stress[name].von_mises))
                _attrs(sub.attrs, {"max": float(stress[name].von_mises[k]),
                                   "s_max": float(f.s[k])})
        if _has(h5, "model") and len(model.constraints):
            model_group = _subgroup(h5, "model")
            if _has(model_group, "constraint_joints"):
                del model_group["constraint_joints"]
            names = _dataset(model_group, "constraint_joints",
                             np.array(constraint_joints(model), dtype="S"), "name")
            _attrs(names.attrs, {"description": "the joint each row of lambda belongs to "
                                                "(empty: a body's own constraint)"}, fresh=True)


def write_dynamic_answers(path: Path, recorder) -> None:
    """/dynamic/reactions/<joint> (leading time axis), /dynamic/sections/<beam> (when the
    recorder keeps them), /dynamic/tension/<cable> (min and max along it per row) and the
    stress envelope /dynamic/stress/<beam> (von_mises_max,
    t_max per station; attributes max, s_max, t_max) of a DynamicAnswers recorder (a
    chunk still waiting in it recorded first: ``recorder.complete()``; when that fails,
    as when a chunk fails in the runner's sink, the answers are not written and the
    model's warnings say why)."""
    if not complete_answers(recorder) or not recorder.time:
        return
    with _open_write(path) as h5:
        group = _subgroup(h5, "dynamic")
        for key in ("reactions", "sections", "stress", "tension"):
            if _has(group, key):
                del group[key]
        if any(recorder.tension.values()):
            tension_group = _subgroup(group, "tension")
            _attrs(tension_group.attrs, {"description": (
                "each cable's axial force along it (tension positive; a rope's is never "
                "negative, 0 where it is slack): min and max over its integration points "
                "at each row of /dynamic/time")}, fresh=True)
            for name, chunks in recorder.tension.items():
                if chunks:
                    sub = _subgroup(tension_group, name)
                    _dataset(sub, "min", np.concatenate([c[0] for c in chunks]), "N")
                    _dataset(sub, "max", np.concatenate([c[1] for c in chunks]), "N")
        if recorder.reactions:
            reactions_group = _subgroup(group, "reactions")
            elements = {f.name for f in recorder.force_elements}
            for name, chunks in recorder.reactions.items():
                if not chunks:
                    continue
                axial = None if chunks[0][2] is None else np.concatenate([c[2] for c in chunks])
                _reaction_group(reactions_group, name, np.concatenate([c[0] for c in chunks]),
                                np.concatenate([c[1] for c in chunks]), axial,
                                _reaction_kind(name, elements))
        if recorder.sections:
            sections_group = _subgroup(group, "sections")
            for name, chunks in recorder.sections.items():
                sub = _subgroup(sections_group, name)
                _dataset(sub, "s", chunks[0].s, "m")
                for key, units in (("N", "N"), ("T", "N m"), ("Q", "N"), ("M", "N m")):
                    _dataset(sub, key, np.concatenate([getattr(c, key) for c in chunks]), units)
        if recorder.envelope:
            stress_group = _subgroup(group, "stress")
            for name, (s, best, when) in recorder.envelope.items():
                sub = _subgroup(stress_group, name)
                _dataset(sub, "s", s, "m")
                _dataset(sub, "von_mises_max", best, "Pa")
                _dataset(sub, "t_max", when, "s")
                k = int(np.argmax(best))
                _attrs(sub.attrs, {"max": float(best[k]), "s_max": float(s[k]),
                                   "t_max": float(when[k])})
            _stress_points(h5, group, recorder)


def _stress_points(h5: h5py.File, group: h5py.Group, recorder) -> None:
    """/dynamic/mesh_von_mises_max: the von Mises envelope at the XDMF mesh's
    points (/model/mesh; a beam node takes the larger value of the two element ends that
    meet there; other points 0), the node field ParaView colours the beams by."""
    if "model/mesh" not in h5:
        return
    mesh = h5["model/mesh"]
    values = np.zeros(len(mesh["points"]))
    ranges = {name: (points[0], points[-1]) for name, (kind, points)
              in mesh_parts(str(mesh.attrs.get("bodies", ""))).items() if kind == "beam"}
    for name, (_, best, _) in recorder.envelope.items():
        if name not in ranges:
            continue
        first, last = ranges[name]
        nodes = last - first + 1
        per = len(best) // max(nodes - 1, 1)
        ends = best.reshape(nodes - 1, per)
        node_values = np.zeros(nodes)
        node_values[:-1] = ends[:, 0]
        node_values[1:] = np.maximum(node_values[1:], ends[:, -1])
        values[first:last + 1] = node_values
    if "mesh_von_mises_max" in group:
        del group["mesh_von_mises_max"]
    _dataset(group, "mesh_von_mises_max", values, "Pa")
# -- modal analysis and linear buckling (SPEC section 10) -----------------------------------

def _write_eigen(path: Path, model: Model, name: str, shapes: np.ndarray,
                 full_shapes: np.ndarray, state: np.ndarray, series: dict[str, tuple],
                 attrs: dict[str, Any], drawn_on: np.ndarray | None = None) -> None:
    """/<name>: the eigenvalue series (name -> (values, units)), shapes[N, ndof] (solver
    coordinates, as solved), full_shapes[N, nfull], the state the analysis linearized about
    (static_q), and for XDMF and plots the mesh points at ``drawn_on`` (default: that
    state; mesh_static) with each shape on them (mesh_shapes[N, npoints, 3], scaled to a
    largest displacement of 1)."""
    from .xdmf import MeshLayout
    layout = MeshLayout.from_model(model)
    # a full disk or ``ulimit -f``: refused before HDF5 writes (a write that fails inside
    # HDF5 left a file no reader could open: the model and the statics lost)
    check_room(path, _eigen_bytes(model, layout, [shapes, full_shapes, state] +
                                  [np.asarray(v) for v, _ in series.values()]))
    with _open_write(path) as h5:
        if name in h5:
            del h5[name]
        group = _subgroup(h5, name)
        for key, (values, units) in series.items():
            _dataset(group, key, np.asarray(values), units)
        data = _dataset(group, "shapes", shapes, COORDINATE_UNITS)
        data.attrs["description"] = "mode shapes (rows) in the solver coordinates e"
        _dataset(group, "full_shapes", full_shapes, COORDINATE_UNITS)
        _dataset(group, "static_q", state, COORDINATE_UNITS)
        _attrs(group.attrs, attrs)
        if layout is not None:
            if "model/mesh" not in h5:
                write_layout(h5, layout)
            static = layout.positions(model, (state if drawn_on is None
                                              else drawn_on)[None, :])[0]
            mesh = (layout.map @ np.atleast_2d(full_shapes).T).T.reshape(
                len(full_shapes), layout.npoints, 3)
            peak = np.abs(mesh).reshape(len(mesh), -1).max(axis=1, initial=0.0)
            mesh = mesh / np.where(peak > 0, peak, 1.0)[:, None, None]
            _dataset(group, "mesh_static", static, "m")
            shapes_ds = _dataset(group, "mesh_shapes", mesh, "1")
            shapes_ds.attrs["description"] = ("each shape at the mesh points, scaled to a "
                                              "largest displacement of 1")
            for k in range(len(mesh)):  # plain datasets for the XDMF attributes
                _dataset(group, f"xdmf/mode_{k + 1}", mesh[k], "1")


#: HDF5's own bytes per dataset (object header, attributes, link) counted by the room check
#: of an eigen write on top of the data: an object header with a few attributes takes well
#: under 1 kB, the rest is slack for the B-tree and heap entries of the groups
DATASET_BYTES = 2048


def _eigen_bytes(model: Model, layout, arrays: list[np.ndarray]) -> int:
    """An upper estimate of what an eigen write adds to the file: its arrays, the mesh
    datasets (the points at the state, each shape twice: mesh_shapes and xdmf/mode_k, the
    layout when the file has none), and DATASET_BYTES per dataset."""
    data = sum(np.asarray(a).nbytes for a in arrays)
    datasets = len(arrays)
    if layout is not None:
        count = len(np.atleast_2d(arrays[1]))
        data += 8 * 3 * layout.npoints * (2 * count + 1) + layout.points.nbytes + \
            8 * (layout.quads.size + 3 * len(layout.quads) + 3 * layout.lines.size)
        datasets += count + 4
    return data + DATASET_BYTES * datasets


def write_modal(path: Path, model: Model, result) -> None:
    """/modal from a :class:`~ancfdrv.solvers.modal.ModalResult`: frequency[N] (Hz,
    ascending, rigid-body modes 0), damping_ratio[N] and damped_frequency[N] when damping
    (or a steady spin) is on, omega_squared[N], rigid[N], shapes[N, ndof]."""
    series: dict[str, tuple] = {"frequency": (result.frequency, "Hz"),
                                "omega_squared": (result.omega_squared, "rad^2/s^2"),
                                "rigid": (result.rigid.astype(np.int8), "1")}
    if result.damping_ratio is not None:
        series["damping_ratio"] = (result.damping_ratio, "1")
        series["damped_frequency"] = (result.damped_frequency, "Hz")
    attrs = {"method": result.method, "modes": len(result.frequency),
             "wall_time_s": result.wall_time_s,
             **{f"time_{k}_s": v for k, v in result.timing.items()},
             **{k: v for k, v in result.extra.items() if np.isscalar(v)}}
    write_static(path, model, result.static)  # first: kept when /modal finds no room
    _write_eigen(path, model, "modal", result.shapes, result.full_shapes, result.static.e,
                 series, attrs)


def write_buckling(path: Path, model: Model, result) -> None:
    """/buckling from a :class:`~ancfdrv.solvers.buckling.BucklingResult`:
    load_factor[N] (multiples of the reference loads; ascending, positive) and shapes[N, ndof]
    (largest component 1); /static holds the scene's static state (load factor 1), on which
    the shapes are drawn (mesh_static: the state at the limit, static_q, is folded far
    beyond anything the structure carries, 739 times the crane's loads)."""
    attrs = {"method": result.extra.get("method", ""), "solver": result.method,
             "fixed_loads": ",".join(result.fixed_loads), "modes": len(result.load_factor),
             "wall_time_s": result.wall_time_s,
             **{f"time_{k}_s": v for k, v in result.timing.items()},
             **{k: v for k, v in result.extra.items() if np.isscalar(v)}}
    state = result.reference.e if result.reference is not None else model.e0
    if result.base is not None:  # first: kept when /buckling finds no room
        write_static(path, model, result.base)
    _write_eigen(path, model, "buckling", result.shapes, result.full_shapes, state,
                 {"load_factor": (result.load_factor, "1")}, attrs,
                 drawn_on=result.base.e if result.base is not None else None)


def eigen_summary(h5: h5py.File) -> dict[str, Any]:
    """The figures of /modal and /buckling for ``ancf info``: every frequency (and damping
    ratio), every load factor, the first of them, and the group's attributes."""
    out: dict[str, Any] = {}
    for name, key in (("modal", "frequency"), ("buckling", "load_factor")):
        if name not in h5 or key not in h5[name]:
            continue
        group = h5[name]
        out.update({f"{name}.{k}": _text(v) for k, v in group.attrs.items()})
        out[f"{name}.{key}"] = group[key][()]
        if "damping_ratio" in group:
            out[f"{name}.damping_ratio"] = group["damping_ratio"][()]
        if len(group[key]):
            out[f"{name}.first_{key}"] = float(group[key][0])
    return out
