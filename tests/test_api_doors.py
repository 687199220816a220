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


@pytest.mark.parametrize("reader", ["fast", "f90nml", "f90nml-namelists"])
def test_the_refusal_holds_on_every_reading_path(tmp_path, monkeypatch, reader):
    """The same refusal whether the scene's own reader or f90nml parses the text, and with
    f90nml's own Namelists (FAST_NAMELIST off)."""
    if reader != "fast":
        monkeypatch.setattr(scene_module, "fast_reads", lambda text: None)
    if reader == "f90nml-namelists":
        monkeypatch.setattr(scene_module, "FAST_NAMELIST", False)
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
