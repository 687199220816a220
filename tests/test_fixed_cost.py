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
    monkeypatch.setattr(runner, "solve_static_path", watched("static", runner.solve_static_path))
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
    """_dataset stores what h5py's create_dataset stores: values, type (class, size,
    character set, padding), shape (a scalar stays scalar), layout, times tracked or not,
    the units attribute; names with a group path make the groups. Also for a strided
    column (a reaction's force) and fixed-length byte strings (the constraints' joints)."""
    path = tmp_path / "d.h5"
    data = {"a": np.linspace(0, 1, 7), "b/c": np.arange(6).reshape(2, 3),
            "d": np.array([True, False]), "e": np.zeros((0, 3)),
            "f": np.arange(12.0).reshape(4, 3)[:, 1], "g": np.asarray(-2.5),
            "h": np.array(["A1", "", "joint_b"], dtype="S")}
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
            ta, tb = a.id.get_type(), b.id.get_type()
            assert (ta.get_class(), ta.get_size()) == (tb.get_class(), tb.get_size())
            if ta.get_class() == h5py.h5t.STRING:
                assert (ta.get_cset(), ta.get_strpad(), ta.is_variable_str()) == \
                    (tb.get_cset(), tb.get_strpad(), tb.is_variable_str())
            assert a.id.get_space().get_simple_extent_type() == \
                b.id.get_space().get_simple_extent_type()
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


def _series(path):
    """{name: (values, dtype, attributes, layout, maxshape)} of every /dynamic dataset."""
    found = {}
    with h5py.File(path, "r") as h5:
        def visit(name, obj):
            if isinstance(obj, h5py.Dataset):
                found[name] = (obj[()], obj.dtype, dict(obj.attrs),
                               obj.id.get_create_plist().get_layout(), obj.maxshape)
        h5["dynamic"].visititems(visit)
        found["@rows"] = h5["dynamic"].attrs["rows"]
    return found


@pytest.mark.parametrize("flush_rows", [10**6, 4])
def test_last_flush_writes_what_extendable_series_hold(tmp_path, flush_rows):
    """The writer's last flush (a run that ended) makes the series it writes not
    extendable (compact when small, else contiguous), with the values, types, units and
    row count of the extendable series a plain flush writes (the reference: the same
    chunks through ``flush``; /dynamic/q, 51 rows of 48 numbers, is larger than
    COMPACT_BYTES). With flush_rows = 4 the series are made by earlier flushes
    during the run: they stay extendable (chunked) and the last flush appends to them."""
    from test_lean_output import _chunks, cantilever
    from ancfdrv.results.hdf5 import COMPACT_BYTES, DynamicWriter
    from ancfdrv.solvers.dynamic import DynamicSettings
    model = cantilever().assemble()
    try:
        chunks = _chunks(model, DynamicSettings(dt=1e-3, t_end=0.05, store_q=True),
                         [3, 17, 30])
        files = {}
        for label in ("plain", "last"):
            path = files[label] = tmp_path / f"{label}.h5"
            with h5py.File(path, "w"):
                pass
            writer = DynamicWriter(path, model, True, flush_rows, xdmf=False, total_rows=51)
            for chunk in chunks:
                writer(chunk)
            writer.flush() if label == "plain" else writer.flush_last()
        plain, last = _series(files["plain"]), _series(files["last"])
        assert plain.keys() == last.keys() and len(plain) > 15
        assert int(last.pop("@rows")) == int(plain.pop("@rows")) == 51
        layouts = set()
        for name, (values, dtype, attrs, layout, maxshape) in last.items():
            ref = plain[name]
            assert values.shape == ref[0].shape and values.tobytes() == ref[0].tobytes(), name
            assert dtype == ref[1] and attrs == ref[2], name
            assert ref[3] == h5py.h5d.CHUNKED and ref[4][0] is None
            if flush_rows < 51:   # made while the run went on: extendable, appended to
                assert layout == h5py.h5d.CHUNKED and maxshape[0] is None, name
            else:
                assert maxshape == values.shape, name
                assert layout == (h5py.h5d.COMPACT if values.nbytes <= COMPACT_BYTES
                                  else h5py.h5d.CONTIGUOUS), name
            layouts.add(layout)
        assert layouts == ({h5py.h5d.CHUNKED} if flush_rows < 51 else
                           {h5py.h5d.COMPACT, h5py.h5d.CONTIGUOUS})
    finally:
        model.close()


def test_a_short_run_is_complete_after_its_one_flush(tmp_path):
    """A run shorter than its first flush deadline writes its rows once, at its end: the
    file is complete (status ok, every row of every series, the rows attribute, the
    reactions), and the same as the file of a run whose writer flushes at every chunk
    (FLUSH_SECONDS = 0: extendable series appended to), values bitwise."""
    out = {}
    for label, seconds in (("short", None), ("every_chunk", 0.0)):
        path = out[label] = tmp_path / f"{label}.h5"
        with pytest.MonkeyPatch.context() as patch:
            if seconds is not None:
                patch.setattr(results, "FLUSH_SECONDS", seconds)
            runner.run_scene(INPUTS / "boom_luffing.nml", TINY, path, progress=False)
    short, every = _series(out["short"]), _series(out["every_chunk"])
    assert short.keys() == every.keys()
    for name in short:
        if name == "@rows":
            assert int(short[name]) == int(every[name]) == 51
            continue
        assert short[name][0].tobytes() == every[name][0].tobytes(), name
        assert short[name][2] == every[name][2], name
        if name in ("time", "probes/tip", "lambda", "energy/total"):
            assert short[name][3] != h5py.h5d.CHUNKED and every[name][3] == h5py.h5d.CHUNKED
    with h5py.File(out["short"], "r") as h5:
        assert h5.attrs["status"] == "ok" and h5["dynamic"].attrs["status"] == "ok"
        assert len(h5["dynamic/time"]) == 51 and h5["dynamic/time"][-1] == pytest.approx(0.05)
        assert len(h5["dynamic/reactions/A1/force"]) == 51


def test_subgroup_is_the_group_h5py_makes(tmp_path):
    """_subgroup (low-level) makes the group h5py's create_group makes: the same times
    tracking, creation order not tracked, an ASCII link; an existing group is returned as
    is, an existing dataset of the name refused."""
    path = tmp_path / "g.h5"
    with h5py.File(path, "w") as h5:
        ours = results._subgroup(h5, "ours")
        theirs = h5.create_group("theirs")
        assert results._subgroup(h5, "ours") == ours
        h5["values"] = np.zeros(2)   # an existing dataset is no group: refused
        with pytest.raises(ValueError, match="not a group"):
            results._subgroup(h5, "values")
        results._subgroup(ours, "inner")
        assert results._has(h5, "ours") and not results._has(h5, "none")
        assert results._has(ours, "inner")
        made = [(p.get_obj_track_times(), p.get_link_creation_order(),
                 p.get_attr_creation_order())
                for p in (ours.id.get_create_plist(), theirs.id.get_create_plist())]
        assert made[0] == made[1] and made[0][1:] == (0, 0)
        info = {name: h5.id.links.get_info(name.encode()).cset for name in ("ours", "theirs")}
        assert info["ours"] == info["theirs"] == h5py.h5t.CSET_ASCII


def _close(x: np.ndarray, y: np.ndarray, floor: float = 0.0) -> bool:
    """Equal shapes and values within 1e-12 of the series' magnitude plus ``floor``: a chunk
    recorded with others runs its matrix products over more rows (BLAS gemm against gemv
    kernels), which may round differently in the last bits; each value is a short sum of
    terms of the series' scale. ``floor``: the rounding of a value that is a small
    difference of large terms (the axial force EA (|r'| - 1))."""
    scale = float(np.max(np.abs(y), initial=0.0))
    return x.shape == y.shape and bool(np.all(np.abs(x - y) <= 1e-12 * scale + floor))


def test_a_short_chunk_waits_for_the_next_one():
    """The answers recorder records a chunk of 2..WAIT_ROWS rows with the next chunk, the
    initial row with the stepper's first call and the chunk after it (one pass instead of
    three), and a chunk still waiting when the answers are read (``complete``); single
    rows after the initial one (adaptive steps) do not wait: the reactions, section forces
    and stress envelope are those (to rounding) of a recorder that records every chunk at once
    (WAIT_ROWS = 0), for a run that ends after a long chunk, one that ends with a short
    chunk still waiting, one whose only chunk waits, and single-row chunks."""
    from test_lean_output import _chunks, cantilever
    from ancfdrv.solvers.dynamic import DynamicSettings
    from ancfdrv.system.answers import DynamicAnswers
    model = cantilever().assemble()
    try:
        settings = DynamicSettings(dt=1e-3, t_end=0.05, store_q=True)
        for sizes, expected in (([10, 30], [41]), ([10, 30, 5], [41, 5]), ([10], [11]),
                                ([1, 1, 1], [1, 1, 1, 1]), ([1, 10, 30], [1, 1, 40])):
            chunks = _chunks(model, settings, sizes)
            recorded = {}
            for label, wait in (("waiting", DynamicAnswers.WAIT_ROWS), ("each", 0)):
                recorder = DynamicAnswers(model, keep_sections=True)
                recorder.WAIT_ROWS = wait
                passes = []
                real = recorder._record
                recorder._record = lambda chunk: (passes.append(len(chunk.time)),
                                                  real(chunk))
                for chunk in chunks:
                    recorder(chunk)
                recorder.complete()
                recorded[label] = (recorder, passes)
            (ours, ours_passes), (each, each_passes) = recorded["waiting"], recorded["each"]
            assert each_passes == [1, *sizes]
            assert ours_passes == expected
            assert ours.time == each.time and len(ours.time) == 1 + sum(sizes)
            for name in each.reactions:
                a = [np.concatenate([c[k] for c in ours.reactions[name]]) for k in (0, 1)]
                b = [np.concatenate([c[k] for c in each.reactions[name]]) for k in (0, 1)]
                assert all(_close(x, y) for x, y in zip(a, b))
            # N = EA (|r'| - 1): the stretch's rounding, a few eps, times EA (1.05e9 N)
            axial_floor = 16 * np.finfo(float).eps * 2.1e11 * 0.05 * 0.1
            for name in each.sections:
                for key in ("N", "T", "Q", "M"):
                    x = np.concatenate([getattr(c, key) for c in ours.sections[name]])
                    y = np.concatenate([getattr(c, key) for c in each.sections[name]])
                    assert _close(x, y, axial_floor if key == "N" else 0.0), key
            for name, (s, best, when) in each.envelope.items():
                s2, best2, when2 = ours.envelope[name]
                assert _close(best2, best) and np.array_equal(when2, when)
            assert each.reactions and each.envelope
    finally:
        model.close()


def test_a_last_flush_without_rows_makes_every_series(tmp_path):
    """A run that stops before any row (its last flush has nothing to write) still gets
    every series, empty, with the types and units a plain flush gives them."""
    from test_lean_output import cantilever
    from ancfdrv.results.hdf5 import DynamicWriter
    model = cantilever().assemble()
    try:
        found = {}
        for label in ("plain", "last"):
            path = tmp_path / f"{label}.h5"
            with h5py.File(path, "w"):
                pass
            writer = DynamicWriter(path, model, True, 10**6, xdmf=False, total_rows=21)
            writer.flush() if label == "plain" else writer.flush_last()
            found[label] = _series(path)
        assert found["plain"].keys() == found["last"].keys() and len(found["last"]) > 15
        assert int(found["last"].pop("@rows")) == int(found["plain"].pop("@rows")) == 0
        for name, (values, dtype, attrs, _, _) in found["last"].items():
            ref = found["plain"][name]
            assert len(values) == 0 and values.shape == ref[0].shape, name
            assert dtype == ref[1] and attrs == ref[2], name
    finally:
        model.close()


@pytest.mark.parametrize("sizes", [[], [3], [3, 17]], ids=["no rows", "one flush", "two"])
def test_q_last_holds_the_last_row(tmp_path, sizes):
    """/dynamic/q_last (the coordinates carried, not written as /dynamic/q): made by the
    first flush with the last row's q and rewritten by each later one; a writer without
    rows still makes it (zeros, as before: it was made empty by the writer's set-up)."""
    from test_lean_output import _chunks, cantilever
    from ancfdrv.results.hdf5 import DynamicWriter
    from ancfdrv.solvers.dynamic import DynamicSettings
    model = cantilever().assemble()
    try:
        chunks = _chunks(model, DynamicSettings(dt=1e-3, t_end=0.02, store_q=True),
                         sizes) if sizes else []
        path = tmp_path / "q.h5"
        with h5py.File(path, "w"):
            pass
        writer = DynamicWriter(path, model, True, 4, xdmf=False, total_rows=21,
                               write_q=False)
        expected = np.zeros(model.ndof) if not chunks else np.array(chunks[-1].q[-1])
        for chunk in chunks:
            writer(chunk)
        writer.flush_last()
        with h5py.File(path, "r") as h5:
            assert "q" not in h5["dynamic"]
            q_last = h5["dynamic/q_last"]
            assert q_last.attrs["units"] == results.COORDINATE_UNITS
            assert q_last[()].tobytes() == expected.tobytes()
            assert len(h5["dynamic/time"]) == (1 + sum(sizes) if sizes else 0)
    finally:
        model.close()
