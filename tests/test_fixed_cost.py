"""The fixed cost of a run outside the stepping (issue 23 item 4): what got cheaper must
store what the plain way stores, and keep the crash-safety contract.

References: h5py's high-level attribute assignment (the types and values the low-level
path must reproduce), the row-major sums of the joint reactions (bitwise), a writer that
wrote rows (the series an empty writer must hold), and the contract itself: the result
file is closed whenever the run computes (a killed run keeps a closed file, a reader is
never locked out for long), and a stale lock record is replaced whole."""
from __future__ import annotations

import json
import os

import h5py
import numpy as np
import pytest

from conftest import INPUTS
from ancfdrv import runner
from ancfdrv.results import hdf5 as results
from ancfdrv.results.lock import OutputLock, lock_path

TINY = ["beam.nodes=4", "solver.t_end=0.05", "output.xdmf=.false."]


def _open_files() -> int:
    return h5py.h5f.get_obj_count(h5py.h5f.OBJ_ALL, h5py.h5f.OBJ_FILE)


def test_result_file_is_closed_while_the_run_computes(tmp_path, monkeypatch):
    """The static solve and the stepping run with no HDF5 file open (what a SIGKILL or a
    reader meets then is a closed file), and the run opens its file a few times only (it
    was opened once per write: 10 times for this run)."""
    seen = {}

    def watched(name, real):
        def call(*args, **kwargs):
            seen[name] = _open_files()
            return real(*args, **kwargs)
        return call
    monkeypatch.setattr(runner, "solve_static", watched("static", runner.solve_static))
    monkeypatch.setattr(runner, "integrate", watched("dynamic", runner.integrate))
    opens = []
    real_open = results._open_file

    def counted(path, mode="a"):
        opens.append(mode)
        return real_open(path, mode)
    monkeypatch.setattr(results, "_open_file", counted)
    out = tmp_path / "boom.h5"
    runner.run_scene(INPUTS / "boom_luffing.nml", TINY, out, progress=False)
    assert seen == {"static": 0, "dynamic": 0}
    assert _open_files() == 0
    # create; static results + the dynamic set-up; the rows, attributes and status
    assert opens == ["w-", "a", "a"]
    with h5py.File(out, "r") as h5:
        assert h5.attrs["status"] == "ok" and len(h5["dynamic/time"]) == 51
        assert h5["dynamic"].attrs["steps"] == 50 and "reactions" in h5["dynamic"]


@pytest.mark.parametrize("value", ["text", "", "ü and ß", 3, True, np.int32(-4), 2.5,
                                   np.float32(1.25), np.float64(-0.0),
                                   np.array([1.0, 2.0, 3.0]), np.arange(4, dtype=np.int32),
                                   [1, 2], b"bytes"],
                         ids=lambda v: type(v).__name__)
def test_attributes_as_h5py_writes_them(tmp_path, value):
    """An attribute written by the low-level path has the HDF5 type (class, size, character
    set, variable length), shape and value h5py's ``attrs[key] = value`` gives (bool and
    integers as int64, as before), also when it replaces an attribute."""
    path = tmp_path / "a.h5"
    plain = np.int64(value) if isinstance(value, (bool, int, np.integer)) else value
    with h5py.File(path, "w") as h5:
        h5.create_group("ours").attrs["x"] = "old value"
        h5.create_group("h5py")
        results._attrs(h5["ours"].attrs, {"x": value})
        h5["h5py"].attrs["x"] = plain
    with h5py.File(path, "r") as h5:
        def describe(group):
            attr = h5py.h5a.open(h5[group].id, b"x")
            kind = attr.get_type()
            text = kind.get_class() == h5py.h5t.STRING
            return (kind.get_class(), kind.get_size(), text and kind.get_cset(),
                    text and kind.is_variable_str(), attr.shape)
        assert describe("ours") == describe("h5py")
        ours, theirs = h5["ours"].attrs["x"], h5["h5py"].attrs["x"]
        assert type(ours) is type(theirs)
        assert np.asarray(ours).tobytes() == np.asarray(theirs).tobytes()


def test_datasets_as_h5py_writes_them(tmp_path):
    """_dataset stores what h5py's create_dataset stores: values, type, layout, times
    tracked or not, the units attribute; names with a group path make the groups."""
    path = tmp_path / "d.h5"
    data = {"a": np.linspace(0, 1, 7), "b/c": np.arange(6).reshape(2, 3),
            "d": np.array([True, False]), "e": np.zeros((0, 3))}
    with h5py.File(path, "w") as h5:
        for name, values in data.items():
            results._dataset(h5.require_group("ours"), name, values, "m")
            theirs = h5.require_group("h5py").create_dataset(
                name, data=np.asarray(values).astype(np.int64)
                if np.asarray(values).dtype.kind in "iub" else values)
            theirs.attrs["units"] = "m"
    with h5py.File(path, "r") as h5:
        for name in data:
            a, b = h5["ours"][name], h5["h5py"][name]
            assert a.dtype == b.dtype and a.shape == b.shape and a.chunks == b.chunks
            assert a[()].tobytes() == b[()].tobytes()
            pa, pb = a.id.get_create_plist(), b.id.get_create_plist()
            assert pa.get_layout() == pb.get_layout()
            assert pa.get_obj_track_times() == pb.get_obj_track_times()
            assert a.attrs["units"] == b.attrs["units"] == "m"


def test_an_empty_dynamic_writer_holds_every_series(tmp_path):
    """The series are made by the first flush with its rows; a run that stops before any
    row still gets every series (no rows), the ones a run with rows gets."""
    from test_lean_output import _chunks, cantilever
    from ancfdrv.results.hdf5 import DynamicWriter
    from ancfdrv.solvers.dynamic import DynamicSettings
    model = cantilever().assemble()
    try:
        names = {}
        for label, chunks in (("empty", []), ("rows", _chunks(
                model, DynamicSettings(dt=1e-3, t_end=0.003, store_q=True), [3]))):
            path = tmp_path / f"{label}.h5"
            with h5py.File(path, "w"):
                pass
            writer = DynamicWriter(path, model, True, 10**6, xdmf=False)
            for chunk in chunks:
                writer(chunk)
            writer.flush()
            with h5py.File(path, "r") as h5:
                found = {}
                h5["dynamic"].visititems(lambda n, o: found.update({n: (o.shape[1:], o.dtype,
                                                                        o.chunks, o.maxshape[1:],
                                                                        dict(o.attrs))})
                                         if isinstance(o, h5py.Dataset) else None)
                lengths = {h5["dynamic"][n].shape[0] for n in found}
                assert lengths == ({0} if label == "empty" else {4})
                names[label] = found
        assert names["empty"] == names["rows"] and len(names["rows"]) > 15
    finally:
        model.close()


def test_lock_record_replaces_a_stale_one(tmp_path):
    """The lock file written over a longer stale record (a killed run's) holds exactly
    the new record."""
    out = tmp_path / "run.h5"
    lock = lock_path(out)
    lock.write_text(json.dumps({"pid": 1, "host": "x" * 500, "command": "y" * 500}) + "\n")
    with OutputLock(out):
        text = lock.read_text()
        assert text.endswith("\n") and text.count("\n") == 1
        assert json.loads(text)["pid"] == os.getpid()
    assert not lock.exists()


def test_a_full_disk_keeps_the_initial_row(tmp_path, monkeypatch):
    """The initial row waits for the rows after it; when their write is refused (disk or
    file-size limit), the initial row alone is written if it fits, every series is made,
    the error is raised and the other rows still wait."""
    import errno
    from test_lean_output import _chunks, cantilever
    from ancfdrv.results.hdf5 import DynamicWriter
    from ancfdrv.solvers.dynamic import DynamicSettings
    model = cantilever().assemble()
    try:
        chunks = _chunks(model, DynamicSettings(dt=1e-3, t_end=0.02, store_q=True), [10, 10])
        path = tmp_path / "full.h5"
        with h5py.File(path, "w"):
            pass
        writer = DynamicWriter(path, model, True, 10**6, xdmf=False, total_rows=21)
        small = writer.chunk_bytes + 2 * sum(
            getattr(chunks[0], f).nbytes for f in ("time", "probes", "deflections", "lam",
                                                  "energy", "constraint", "stats", "q"))

        def room(target, nbytes):
            if nbytes > small:
                raise OSError(errno.ENOSPC, "No space left on device")
        monkeypatch.setattr(results, "check_room", room)
        monkeypatch.setattr(results, "FLUSH_SECONDS", 1e9)  # every row waits for flush()
        for chunk in chunks:
            writer(chunk)
        with pytest.raises(OSError):
            writer.flush()
        assert writer.rows == 1 and writer._pending_rows == 20
        with h5py.File(path, "r") as h5:
            lengths = set()
            h5["dynamic"].visititems(lambda n, o: lengths.add(o.shape[0])
                                     if isinstance(o, h5py.Dataset) else None)
            assert lengths == {1} and h5["dynamic"].attrs["rows"] == 1
            assert h5["dynamic/time"][0] == 0.0 and "step_size" in h5["dynamic"]
    finally:
        model.close()
