"""The doors of the package (issue 35, items 3 and 4): the namelist reader refuses a group
that starts before the previous one ended; every file door of the Python API validates
like the namelist (an InputError naming the argument and the problem, never a raw
TypeError, AttributeError or OSError); a write that fails leaves what the file held
readable; the kernel's failure texts are whole (not cut by its message buffer).

References: the exact words of each message (no digits), exit statuses 2 and 3, and the
content of the files read back.
"""
from __future__ import annotations

import numpy as np
import pytest

import ancfdrv.io.scene as scene_module
from ancfdrv.cli import main
from ancfdrv.errors import InputError
from ancfdrv.io.scene import load_scene

from conftest import INPUTS
from helpers import beam_model

CANTILEVER = (INPUTS / "cantilever.nml").read_text()


def _without_end_of(group: str) -> str:
    """The cantilever scene with the '/' that ends ``&group`` removed."""
    lines = CANTILEVER.split("\n")
    start = lines.index("&" + group)
    end = next(k for k in range(start, len(lines)) if lines[k] == "/")
    return "\n".join(lines[:end] + lines[end + 1:])


# -- the namelist reader: a group inside another (a missing '/') ---------------------------

@pytest.mark.parametrize("group, after", [("scene", "beam"), ("beam", "material"),
                                          ("material", "cantilever"), ("cantilever", "loads"),
                                          ("loads", "solver")])
def test_a_missing_slash_names_both_groups_and_the_line(tmp_path, group, after, capsys):
    """f90nml drops the group after a missing '/' without a word (the run went on without
    it); the reader refuses it, exit 2, naming the line where the dropped group starts."""
    text = _without_end_of(group)
    lines = text.split("\n")
    first, line = lines.index("&" + group) + 1, lines.index("&" + after) + 1
    path = tmp_path / "scene.nml"
    path.write_text(text)
    assert main(["run", str(path), "-o", str(tmp_path / "out.h5")]) == 2
    err = capsys.readouterr().err
    assert (f"{path}: line {line}: group &{after} starts before group &{group} (line {first}) "
            "ended (missing '/')") in err
    assert "Traceback" not in err
    assert not (tmp_path / "out.h5").exists()


@pytest.mark.parametrize("reader", ["fast", "f90nml"])
def test_the_refusal_holds_on_every_reading_path(tmp_path, monkeypatch, reader):
    """The same refusal whether the scene's own reader or f90nml parses the text."""
    if reader != "fast":
        monkeypatch.setattr(scene_module, "fast_reads", lambda text: None)
    path = tmp_path / "scene.nml"
    path.write_text(_without_end_of("loads"))
    with pytest.raises(InputError, match=r"line 25: group &solver starts before group &loads "
                       r"\(line 23\) ended \(missing '/'\)"):
        load_scene(path)


def test_a_group_the_file_ends_inside(tmp_path):
    """The last group without its '/': the message names it and its line (f90nml's own
    text names neither)."""
    path = tmp_path / "scene.nml"
    path.write_text(CANTILEVER.rstrip().removesuffix("/"))
    with pytest.raises(InputError, match=r"line 26: group &solver has no '/' before the end "
                       r"of the file"):
        load_scene(path)


def test_slashes_in_strings_and_comments_and_other_ends_are_no_group_ends(tmp_path):
    """A '/' or '&name' inside a quoted string or a comment neither ends nor starts a group;
    '&end', '$end' and a lone '&' end a group as they do for f90nml (the scene loads with
    every group's values)."""
    text = (CANTILEVER
            .replace("title = 'Cantilever under a tip force'",
                     "title = 'a / b &beam \"/\"'  ! a comment / &solver")
            .replace("  nodes = 9\n/", "  nodes = 9\n&end")
            .replace("  density = 7850.0\n/", "  density = 7850.0 $end")
            .replace("  tip_force = 0.0, -100.0, 0.0\n/", "  tip_force = 0.0, -100.0, 0.0 &"))
    path = tmp_path / "scene.nml"
    path.write_text(text)
    scene = load_scene(path)
    assert scene["scene"]["title"] == "a / b &beam \"/\""
    assert scene["beam"]["nodes"] == 9 and scene["material"]["density"] == 7850.0
    assert scene["loads"]["tip_force"] == [0.0, -100.0, 0.0]
    assert scene["solver"]["static_method"] == "newton"


# -- the kernel's failure texts fit its message buffer ------------------------------------

def test_the_floor_stall_text_is_whole_at_its_longest():
    """The static Newton's round-off floor stall with 10-digit load step counts and a
    3-digit exponent (its longest form) ends with its whole advice: the text was one
    character longer than the kernel's 200-character buffer even at 'load step 1 of 1'
    and ended in 'raise solver.to'."""
    free = beam_model(4, gravity=(0.0, 0.0, -9.81))  # rigid modes: the residual stays
    big = 2**31 - 1
    out = free.kernel.static_solve(
        t=0.0, load_factor=1.0, e0=free.e0, rows=free.pattern.rows,
        cols=free.pattern.col_index, e=free.e0.copy(), lam=np.zeros(len(free.constraints)),
        guesses=free.contact_guesses, counts=free.contact_counts, tol=1e-300,
        length_scale=free.length_scale, max_iter=50, check_start=False, force_scale=-1.0,
        load_step=big, load_steps=big)
    message = out["message"].strip()
    free.close()
    assert message.startswith(f"static Newton stalled at the round-off floor at load step "
                              f"{big} of {big}: the relative residual stays at ")
    assert message.endswith("above solver.tol = 1.000e-300, beyond double precision; "
                            "raise solver.tol")


# -- a write that fails leaves what the file held readable --------------------------------

_LIMITED_RUN = """
import resource, signal, sys
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
resource.setrlimit(resource.RLIMIT_FSIZE, (int(sys.argv[1]), resource.RLIM_INFINITY))
from ancfdrv.cli import main
sys.exit(main(sys.argv[2:]))
"""


def _run_limited(limit: int, *argv: str):
    import subprocess
    import sys
    return subprocess.run([sys.executable, "-c", _LIMITED_RUN, str(limit), *argv],
                          capture_output=True, text=True, timeout=120)


def test_a_modal_result_beyond_the_file_size_limit_keeps_model_and_statics(tmp_path):
    """``ulimit -f`` reached by the modal write (the limit leaves room for the model and
    the statics, not for the 100 modes' 0.5 MB): exit 3 naming the limit, and the file
    opens with /model, /static and status 'failed' (HDF5 failing inside its write left a
    file no reader could open, or crashed the process)."""
    import h5py
    from ancfdrv.io.safe_write import ROOM_MARGIN_BYTES
    out = tmp_path / "modes.h5"
    ndof = 204   # the crane boom: 17 nodes of 12 coordinates
    limit = ROOM_MARGIN_BYTES + 16 * ndof * 8 + 4096   # what the file's creation asks for
    done = _run_limited(limit, "run", str(INPUTS / "crane_boom_modes.nml"), "-o", str(out),
                        "--set", "modal.modes=100", "--set", "modal.solver=dense")
    assert done.returncode == 3, done.stderr
    assert "file-size limit" in done.stderr and "Traceback" not in done.stderr
    with h5py.File(out, "r") as h5:
        assert h5["model"].attrs["ndof"] == ndof
        assert "static/q" in h5 and "modal" not in h5
        assert h5.attrs["status"] == "failed" and "file-size limit" in h5.attrs["message"]
    assert not list(tmp_path.glob("*.tmp"))


def test_a_file_size_limit_below_any_result_leaves_no_unreadable_file(tmp_path):
    """A limit below what even the final status needs: exit 3, and no file (the status
    written into a new file beyond the limit left one that HDF5 could not open)."""
    out = tmp_path / "modes.h5"
    done = _run_limited(8000, "run", str(INPUTS / "crane_boom_modes.nml"), "-o", str(out))
    assert done.returncode == 3 and "file-size limit" in done.stderr, done.stderr
    assert not out.exists()


# -- System.modes and System.buckling: the namelist's rules -------------------------------

def _column():
    """A 1 m steel column clamped at its foot, pushed down its axis (nonlinear: buckling
    needs the geometric stiffness)."""
    from ancfdrv import Rectangle, System
    s = System("column")
    steel = s.material("steel", youngs_modulus=2.1e11, density=7850.0)
    s.beam("arm", material=steel, start=(0, 0, 0), end=(1, 0, 0), nodes=3,
           section=Rectangle(0.05, 0.05), formulation="nonlinear")
    s.joint("root", "weld", "ground", "arm", point=(0, 0, 0))
    s.load("push", "force", body="arm", point=(1, 0, 0), vector=(-100.0, 0, 0))
    return s


@pytest.mark.parametrize("call, args, kwargs, words", [
    ("modes", ("3",), {}, "&modal modes: expected an integer, got '3'"),
    ("modes", (None,), {}, "&modal modes: expected an integer, got no value"),
    ("modes", (3.5,), {}, "&modal modes: expected an integer, got 3.5"),
    ("modes", (True,), {}, "&modal modes: expected an integer"),
    ("modes", (0,), {}, "&modal modes: 0 must be at least 1"),
    ("modes", (2,), {"foo": 1}, "unknown keyword argument 'foo'; it takes load_steps"),
    ("modes", (2,), {"modes": 3}, "unknown keyword argument 'modes'"),
    ("modes", (2,), {"rigid_tol": -1}, "&modal rigid_tol: -1.0 must lie in (0, 1e-3)"),
    ("modes", (2,), {"solver": 3}, "&modal solver: expected a string, got 3"),
    ("modes", (2,), {"solver": "lapack"}, "&modal solver: 'lapack' must be one of"),
    ("modes", (2,), {"spin_axis": 1}, "&modal spin_axis: [1.0] must be three numbers"),
    ("modes", (2,), {"tol": 0}, "&solver tol: 0.0 must lie in (0, 1)"),
    ("modes", (2,), {"max_iter": "50"}, "&solver max_iter: expected an integer"),
    ("modes", (2,), {"linear_joints": "x"}, "&solver linear_joints: 'x' must be one of"),
    ("buckling", ("3",), {}, "&buckling modes: expected an integer, got '3'"),
    ("buckling", (None,), {}, "&buckling modes: expected an integer, got no value"),
    ("buckling", (1,), {"rtol": 0}, "&buckling rtol: 0.0 must lie in (0, 0.1)"),
    ("buckling", (1,), {"method": "exact"}, "&buckling method: 'exact' must be one of"),
    ("buckling", (1,), {"reference_factor": -1}, "&buckling reference_factor: -1.0 must be "
     "positive"),
    ("buckling", (1,), {"fixed_loads": None}, "&buckling fixed_loads: expected a list of "
     "strings, got no value"),
    ("buckling", (1,), {"fixed_loads": [3]}, "&buckling fixed_loads: expected a list of "
     "strings"),
    ("buckling", (1,), {"foo": 1}, "unknown keyword argument 'foo'; it takes load_steps"),
    ("buckling", (1,), {"rigid_tol": 1e-9}, "unknown keyword argument 'rigid_tol'"),
])
def test_modes_and_buckling_arguments_pass_the_namelist_rules(call, args, kwargs, words):
    """Each bad argument is an InputError naming the call, the namelist key it stands for
    and the namelist's words (raw TypeErrors before; rigid_tol = -1 and rtol = 0 ran)."""
    with pytest.raises(InputError) as err:
        getattr(_column(), call)(*args, **kwargs)
    assert f"System 'column': {call}(): " in str(err.value)
    assert words in str(err.value)


def test_modes_and_buckling_take_what_a_scene_takes():
    """The checked arguments run: numpy integers, a tuple axis, a load name as a string
    for fixed_loads (one name, as the namelist's fixed_loads = 'push')."""
    s = _column()
    modes = s.modes(np.int64(2), solver="dense", rigid_tol=1e-8, spin_axis=(0, 0, 1))
    assert len(modes.frequency) == 2 and np.all(modes.frequency > 0)
    with pytest.raises(InputError, match="fixed_loads names unknown load"):
        s.buckling(1, fixed_loads="pull")


def test_the_solver_functions_check_their_own_arguments():
    """modal_analysis and buckling_analysis, called directly, refuse with the same rules
    (a bad-input error, exit 2, not a solver failure)."""
    from ancfdrv.solvers.buckling import buckling_analysis
    from ancfdrv.solvers.modal import modal_analysis
    model = _column().assemble()
    try:
        with pytest.raises(InputError, match=r"modal analysis: &modal modes: 0 must be at "
                           r"least 1"):
            modal_analysis(model, 0)
        with pytest.raises(InputError, match=r"buckling: &buckling method: 'exact' must be "
                           r"one of"):
            buckling_analysis(model, 1, method="exact")
    finally:
        model.close()


# -- the file doors ---------------------------------------------------------------------

@pytest.fixture(scope="module")
def result():
    """A small static result (its file in a temporary directory)."""
    return _column().static()


@pytest.mark.parametrize("value, words", [
    (5, "expected a file path (a str or pathlib.Path), got int 5"),
    (None, "expected a file path (a str or pathlib.Path), got None"),
    (b"out.h5", "got bytes b'out.h5' (decode it"),
    (3.5, "got float 3.5"),
    ("", "the file name is empty"),
    ("a\x00b.h5", "contains a NUL character"),
])
def test_path_arguments_name_the_argument_and_the_problem(result, value, words):
    """output= of a run (where None is the default: a temporary file), Results.save and
    ancfdrv.open: an InputError naming the argument and what it got (raw TypeErrors and
    ValueErrors before)."""
    import ancfdrv
    doors = [(lambda: result.save(value), "Results.save(path)"),
             (lambda: ancfdrv.open(value), "open(path)")]
    if value is not None:
        doors.append((lambda: _column().static(output=value), "System 'column': output"))
    for door, label in doors:
        with pytest.raises(InputError) as err:
            door()
        assert f"{label}: " in str(err.value) and words in str(err.value)


def test_open_refuses_what_is_no_result_file(tmp_path, result):
    """A missing file, a directory, a text file and a truncated copy of a result: each an
    InputError naming the path and what it is."""
    import ancfdrv
    text = tmp_path / "notes.h5"
    text.write_text("not a result\n")
    data = result.path.read_bytes()
    truncated = tmp_path / "cut.h5"
    truncated.write_bytes(data[:len(data) // 2])
    for path, words in ((tmp_path / "missing.h5", "result file not found"),
                        (tmp_path, "a directory, not a result file"),
                        (text, "not an HDF5 file"),
                        (truncated, "the HDF5 file is truncated")):
        with pytest.raises(InputError) as err:
            ancfdrv.open(path)
        assert str(err.value) == f"{path}: {words}" or str(err.value).startswith(
            f"{path}: {words} (")


def test_save_where_no_file_can_be_made_is_refused_cleanly(result):
    """/proc takes no new file (not even as root, for whom the permission check passes):
    an InputError naming the directory, not a raw FileNotFoundError."""
    with pytest.raises(InputError, match=r"/proc/version: save: cannot write a file in /proc"):
        result.save("/proc/version")


_LIMITED_SAVE = """
import resource, signal, sys
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
import ancfdrv
from ancfdrv.errors import SolverError
result = ancfdrv.open(sys.argv[2])
resource.setrlimit(resource.RLIMIT_FSIZE, (int(sys.argv[1]), resource.RLIM_INFINITY))
try:
    result.save(sys.argv[3], plot=False)
except SolverError as exc:
    print(exc)
    sys.exit(3)
"""


def test_a_save_beyond_the_file_size_limit_leaves_the_previous_file(tmp_path, result):
    """Results.save stopped by ``ulimit -f``: a SolverError naming the limit, and the file
    it was to replace still the previous result (byte for byte), no temporary file left."""
    import subprocess
    import sys
    import ancfdrv
    target = tmp_path / "kept.h5"
    result.save(target, plot=False)
    before = target.read_bytes()
    size = len(result.path.read_bytes())
    done = subprocess.run([sys.executable, "-c", _LIMITED_SAVE, str(size // 2),
                           str(result.path), str(target)], capture_output=True, text=True,
                          timeout=60)
    assert done.returncode == 3, done.stderr
    assert "the disk or the file-size limit is full" in done.stdout
    assert f"{target} is left as it was" in done.stdout
    assert target.read_bytes() == before
    assert ancfdrv.open(target).status == "ok"
    # (the first save wrote the static state's XDMF beside it)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["kept.h5", "kept.xdmf"]
