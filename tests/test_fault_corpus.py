"""The fault corpus of issue 24: the Python API misused, numeric traps, absurd but finite
drives and loads, damaged and hostile files (a file-size limit, planted symbolic links,
corrupted results), and signals to a sweep's parent.

Every case has one expected, documented outcome, and each test can fail: a case that
raises anything but the package's documented exceptions (a traceback), that is accepted
when it must be refused (a silent acceptance), that does not end within its guard (a
hang), that ends by a signal (a crash) or that leaves a file outside the output area
changed or a written result unreadable (data lost) fails its test.

The hangs of unreachable Newton tolerances (``tol = 1e-300``) are not in this corpus: the
stagnation test of the Newton loops belongs to issue 26's stepper work.
"""
from __future__ import annotations

import os
import resource
import shutil
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

from conftest import INPUTS
from ancfdrv import System
from ancfdrv.errors import AncfError, InputError
from ancfdrv.results.lock import OutputLock
from ancfdrv.io.validate import PHYSICAL_BOUNDS

GUARD_S = 60  # a bound against hanging, not a measurement
CANTILEVER = INPUTS / "cantilever.nml"


# --- helpers ---------------------------------------------------------------------------

def steel(s: System) -> System:
    s.material("steel", youngs_modulus=2.1e11, density=7850.0)
    return s


def arm(s: System | None = None) -> System:
    s = steel(System("arm")) if s is None else s
    s.beam("arm", material="steel", start=(0, 0, 0), end=(1, 0, 0), nodes=3,
           formulation="nonlinear")
    s.joint("root", "weld", "ground", "arm", point=(0, 0, 0))
    return s


def outcome(call) -> tuple[str, str]:
    """('refused', message) for a documented exception, ('accepted', '') when the call
    returns, ('traceback', type: message) for anything else."""
    try:
        call()
    except AncfError as exc:
        return "refused", str(exc)
    except Exception as exc:  # noqa: BLE001 - the class the corpus counts
        return "traceback", f"{type(exc).__name__}: {exc}"
    return "accepted", ""


def main(*args: str) -> tuple[int, str, str]:
    """The command in this process (no interpreter start-up); (exit status, stdout,
    stderr). For the cases that a signal or a resource limit could end, :func:`ancf`."""
    import contextlib
    import io
    from ancfdrv.cli import main as cli_main
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = cli_main(list(args))
    return code, out.getvalue(), err.getvalue()


def ancf(*args: str, cwd: Path | None = None, preexec=None, timeout: float = GUARD_S):
    """The command in a fresh process; (exit status, stdout, stderr). A negative status
    is a death by signal (a crash)."""
    proc = subprocess.run([sys.executable, "-m", "ancfdrv.cli", *args], capture_output=True,
                          text=True, cwd=cwd, preexec_fn=preexec, timeout=timeout)
    return proc.returncode, proc.stdout, proc.stderr


# --- 1. the Python API misused: each a clean InputError naming the item and key ----------

def _drive(**params):
    return lambda: steel(System()).drive("d", params.pop("type"), **params)


API_MISUSE = {
    "E as a string": (lambda: System().material("m", youngs_modulus="2e11", density=1.0),
                      "&material[m] youngs_modulus: expected a number, got '2e11'"),
    "E as a list": (lambda: System().material("m", youngs_modulus=[1.0], density=1.0),
                    "youngs_modulus"),
    "E as None": (lambda: System().material("m", youngs_modulus=None, density=1.0),
                  "youngs_modulus"),
    "density True": (lambda: System().material("m", youngs_modulus=1.0, density=True),
                     "expected a number, got True"),
    "Poisson 0.5 (np.float64)": (lambda: System().material(
        "m", youngs_modulus=1.0, density=1.0, poisson_ratio=np.float64(0.5)),
        "0.5 must lie in [0.0, 0.5)"),
    "nodes as a string": (lambda: steel(System()).beam(
        "b", material="steel", start=(0, 0, 0), end=(1, 0, 0), nodes="9"),
        "&beam[b] nodes: expected an integer, got '9'"),
    "nodes 2.5": (lambda: steel(System()).beam(
        "b", material="steel", start=(0, 0, 0), end=(1, 0, 0), nodes=2.5), "nodes"),
    "start with a string": (lambda: steel(System()).beam(
        "b", material="steel", start=("0", 0, 0), end=(1, 0, 0), nodes=3), "start"),
    "end of two numbers": (lambda: steel(System()).beam(
        "b", material="steel", start=(0, 0, 0), end=(1, 0), nodes=3),
        "must be three numbers"),
    "formulation 42": (lambda: steel(System()).beam(
        "b", material="steel", start=(0, 0, 0), end=(1, 0, 0), nodes=3, formulation=42),
        "formulation"),
    "plate nx as a float string": (lambda: steel(System()).plate(
        "p", material="steel", thickness=0.01, corner=(0, 0, 0), edge_x=(1, 0, 0),
        edge_y=(0, 1, 0), nx="4", ny=4), "&plate[p] nx"),
    "rigid body mass '5'": (lambda: System().rigid_body(
        "r", mass="5", inertia=(1, 1, 1, 0, 0, 0), position=(0, 0, 0)), "mass"),
    "rigid body planar 'yes'": (lambda: System().rigid_body(
        "r", mass=1.0, inertia=(1, 1, 1, 0, 0, 0), position=(0, 0, 0), planar="yes"),
        "planar"),
    "drive NaN amplitude": (_drive(type="sine", amplitude=float("nan"), frequency=1.0),
                            "&drive[d] amplitude: expected a finite number, got nan"),
    "drive infinite omega": (_drive(type="spinup", omega=float("inf"), period=1.0),
                             "omega: expected a finite number"),
    "drive omega as a string": (_drive(type="spinup", omega="6", period=1.0), "omega"),
    "drive unknown parameter": (_drive(type="spinup", omgea=6.0, period=1.0),
                                "does not take omgea"),
    "drive table times with NaN": (_drive(type="table", times=(0.0, float("nan")),
                                          values=(0.0, 1.0)), "times"),
    "drive type 3": (_drive(type=3), "type 3 must be one of"),
    "point mass True": (lambda: arm().load("m", "point_mass", body="arm", point=(1, 0, 0),
                                           mass=True), "&load[m] mass: expected a number, "
                        "got True"),
    "point mass '5'": (lambda: arm().load("m", "point_mass", body="arm", point=(1, 0, 0),
                                          mass="5"), "expected a number, got '5'"),
    "force vector with inf": (lambda: arm().load("f", "force", body="arm", point=(1, 0, 0),
                                                 vector=(0, float("inf"), 0)), "vector"),
    "load effect unknown": (lambda: arm().load("g", "gravity", vector=(0, -9.81, 0),
                                               effect="gravitee"), "unknown effect"),
    "System effects unknown": (lambda: System("x", effects=["gravity", "wind"]),
                               "unknown effect 'wind'"),
    "System effects a number": (lambda: System("x", effects=3), "effect"),
    "effect listed that nothing uses, strict": (lambda: _unused_effect("refuse"),
                                                "'gravity' is listed but no item of the "
                                                "system belongs to it"),
    "probe point NaN": (lambda: arm().probe("p", "arm", (np.nan, 0, 0)), "point"),
    "probe name with a slash": (lambda: arm().probe("a/b", "arm", (1, 0, 0)),
                                "must not contain '/'"),
    "name with a newline": (lambda: System().material("a\nb", youngs_modulus=1.0,
                                                      density=1.0), "control characters"),
    "title not a string": (lambda: System(title=5), "title"),
    "contact points 2.5": (lambda: _two_plates().contact("c", "p1", "p2", stiffness=1e5,
                                                         points=2.5), "points"),
    "solve_newton max_iter=0": (lambda: _newton(max_iter=0), "max_iter = 0 must be at least 1"),
    "solve_newton load_steps=0": (lambda: _newton(load_steps=0), "load_steps = 0"),
    "solve_newton tol=NaN": (lambda: _newton(tol=float("nan")), "tol"),
    "solve_newton max_iter='5'": (lambda: _newton(max_iter="5"), "max_iter"),
    "integrate with a wrong-length state": (lambda: _integrate(e0=np.zeros(5)),
                                            "expected a vector of the model's 36 coordinates"),
    "integrate with dt=0": (lambda: _integrate(dt=0.0), "dt"),
    "integrate with max_newton=0": (lambda: _integrate(max_newton=0), "max_newton"),
    # issue 35: the eigen analyses and the file doors
    "modes('3')": (lambda: arm().modes("3"), "&modal modes: expected an integer, got '3'"),
    "modes(None)": (lambda: arm().modes(None), "&modal modes: expected an integer"),
    "modes(3.5)": (lambda: arm().modes(3.5), "&modal modes: expected an integer, got 3.5"),
    "modes unknown keyword": (lambda: arm().modes(2, shfit=1.0),
                              "unknown keyword argument 'shfit'"),
    "modes rigid_tol=-1": (lambda: arm().modes(2, rigid_tol=-1), "&modal rigid_tol: -1.0 must "
                           "lie in (0, 1e-3)"),
    "buckling rtol=0": (lambda: arm().buckling(1, rtol=0), "&buckling rtol: 0.0 must lie in"),
    "buckling('3')": (lambda: arm().buckling("3"), "&buckling modes: expected an integer"),
    "static(output=5)": (lambda: arm().static(output=5), "output: expected a file path"),
    "open(bytes)": (lambda: __import__("ancfdrv").open(b"r.h5"),
                    "open(path): expected a file path (a str or pathlib.Path), got bytes"),
    "open(None)": (lambda: __import__("ancfdrv").open(None), "open(path): expected a file "
                   "path (a str or pathlib.Path), got None"),
}


def _unused_effect(mode: str | None = None):
    s = arm(steel(System("x", effects=["gravity"])))
    return s.assemble(unused_effects=mode)


def test_an_effect_nothing_uses_is_a_warning_by_default():
    """Not silent: the model's warnings (printed by ancf run) and a UserWarning say it; no
    gravity is computed (its counter stays 0)."""
    with pytest.warns(UserWarning, match="'gravity' is listed but no item"):
        model = _unused_effect()
    assert any("'gravity' is listed" in w for w in model.warnings)
    assert model.counters["gravity"] == 0


def _two_plates() -> System:
    s = steel(System())
    for name, z in (("p1", 0.0), ("p2", -0.01)):
        s.plate(name, material="steel", thickness=0.005, corner=(0, 0, z), edge_x=(1, 0, 0),
                edge_y=(0, 0.1, 0), nx=2, ny=1)
    return s


def _loaded_arm():
    s = arm()
    s.load("f", "force", body="arm", point=(1, 0, 0), vector=(0, -100.0, 0))
    return s.assemble()


def _newton(**kwargs):
    from ancfdrv.solvers.static import solve_newton
    solve_newton(_loaded_arm(), **kwargs)


def _integrate(e0=None, **kwargs):
    from ancfdrv.solvers.dynamic import DynamicSettings, integrate
    model = _loaded_arm()
    settings = DynamicSettings(**{"dt": 1e-3, "t_end": 2e-3, **kwargs})
    integrate(model, settings, model.e0 if e0 is None else e0)


@pytest.mark.parametrize("case", list(API_MISUSE))
def test_api_misuse_is_refused(case):
    call, fragment = API_MISUSE[case]
    kind, message = outcome(call)
    assert kind == "refused", (case, kind, message)
    assert fragment in message, message
    assert "np.float" not in message  # plain numbers in messages


def test_api_and_namelist_give_the_same_message(tmp_path):
    """One validation layer: the namelist's &material and System.material say the same."""
    scene = tmp_path / "s.nml"
    scene.write_text(textwrap.dedent("""\
        &scene title = 't' /
        &material name = 'm', youngs_modulus = -1.0, density = 1.0 /
        &beam name = 'b', material = 'm', start = 0,0,0, end = 1,0,0, nodes = 3,
              width = 0.1, height = 0.1 /
        &joint name = 'r', type = 'weld', body1 = 'ground', body2 = 'b', point = 0,0,0 /
        &probe name = 'tip', body = 'b', point = 1,0,0 /
        """))
    from ancfdrv.io.scene import load_scene
    with pytest.raises(InputError) as from_file:
        load_scene(scene)
    with pytest.raises(InputError) as from_api:
        System().material("m", youngs_modulus=-1.0, density=1.0)
    assert str(from_api.value) == "&material[m] youngs_modulus: -1.0 must be positive"
    assert str(from_file.value).endswith(str(from_api.value))


# --- 2. numeric traps --------------------------------------------------------------------

def test_float32_material_values_are_accepted():
    """np.float32 is a number: stored as the float it holds (the float32 nearest 2e11 is
    12207031 x 2**14 = 199999995904: float32 numbers near 2**37 are 2**14 apart)."""
    m = System().material("m", youngs_modulus=np.float32(2e11), density=np.float32(7850.0))
    assert m.youngs_modulus == 12207031 * 2**14 == 199999995904.0
    assert type(m.youngs_modulus) is float and m.density == 7850.0


def test_numpy_integer_nodes_are_accepted():
    b = steel(System()).beam("b", material="steel", start=(0, 0, 0), end=(1, 0, 0),
                             nodes=np.int64(5))
    assert b.nodes == 5 and len(b.stations) == 5


_MEMORY_SCRIPT = """
import resource, sys
resource.setrlimit(resource.RLIMIT_AS, ({limit}, {limit}))
from ancfdrv import System
from ancfdrv.errors import InputError
s = System(); s.material("m", youngs_modulus=1e9, density=1e3)
try:
    s.beam("b", material="m", start=(0, 0, 0), end=(1, 0, 0), nodes={nodes})
except InputError as exc:
    print("refused:", exc); sys.exit(2)
except MemoryError:
    print("MemoryError"); sys.exit(5)
print("accepted"); sys.exit(0)
"""


@pytest.mark.parametrize("nodes, fragment", [(10**7, "nodes"), (30_000, "too large")])
def test_a_huge_beam_under_a_memory_limit_is_refused_before_allocating(nodes, fragment):
    """Under ulimit -v 2 GB: 10**7 nodes (MemoryError from numpy before) and 30,000 nodes
    (about 4 GB by the estimate: 360,000 coordinates x 36 nonzeros x 300 bytes, which the
    machine could hold but the limit cannot) are refused by the memory estimate."""
    limit = 2 * 2**30
    proc = subprocess.run([sys.executable, "-c", _MEMORY_SCRIPT.format(limit=limit,
                                                                      nodes=nodes)],
                          capture_output=True, text=True, timeout=GUARD_S)
    assert proc.returncode == 2, proc.stdout + proc.stderr
    assert fragment in proc.stdout and "&beam[b] nodes" in proc.stdout


def test_the_memory_limit_lowers_the_available_memory():
    from ancfdrv.io import validate
    script = ("import resource; resource.setrlimit(resource.RLIMIT_AS, (2**31, 2**31)); "
              "from ancfdrv.io.validate import limit_memory; print(limit_memory())")
    room = int(subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                              timeout=GUARD_S).stdout)
    assert 0 < room < 2**31  # the limit less what the interpreter maps already
    assert validate.limit_memory() >= room


# --- 3. absurd but finite drives and loads -------------------------------------------

BOUND_CASES = {
    "spin-up at 1e6 rad/s": (lambda s: s.drive("d", "spinup", omega=1e6, period=1.0),
                             "omega = 1e+06 rad/s", "angular rate"),
    "sine at 1e7 Hz": (lambda s: s.drive("d", "sine", amplitude=1.0, frequency=1e7),
                       "frequency = 1e+07 Hz", "frequency"),
    "gravity of 1e6 m/s^2": (lambda s: s.load("g", "gravity", vector=(0, -1e6, 0)),
                             "|vector| = 1e+06 m/s^2", "acceleration"),
    "force of 1e20 N": (lambda s: s.load("f", "force", body="arm", point=(1, 0, 0),
                                         vector=(0, 1e20, 0)), "|vector| = 1e+20 N", "force"),
    "moment of 1e15 N m": (lambda s: s.load("m", "moment", body="arm", point=(1, 0, 0),
                                            vector=(0, 0, 1e15)), "1e+15 N m", "moment"),
    "point mass of 1e12 kg": (lambda s: s.load("m", "point_mass", body="arm",
                                               point=(1, 0, 0), mass=1e12), "1e+12 kg",
                              "mass"),
}


@pytest.mark.parametrize("case", list(BOUND_CASES))
def test_absurd_drives_and_loads_are_refused_unless_lifted(case):
    add, value, quantity = BOUND_CASES[case]
    s = arm()
    add(s)
    kind, message = outcome(s.assemble)
    assert kind == "refused", (case, kind, message)
    assert value in message and quantity in message and "bounds" in message
    limit = PHYSICAL_BOUNDS[quantity.replace(" ", "_")][0]
    assert f"{limit:g}" in message  # the message says which bound failed
    lifted = arm(steel(System(bounds="off")))
    add(lifted)
    assert outcome(lifted.assemble)[0] == "accepted"


def test_a_spinup_scene_at_1e6_rad_per_s_needs_force(tmp_path):
    scene = tmp_path / "spin.nml"
    scene.write_text(textwrap.dedent("""\
        &scene title = 'spin', analysis = 'dynamic', formulation = 'nonlinear' /
        &beam length = 10, width = 0.1, height = 0.1, nodes = 3 /
        &material youngs_modulus = 2.1e11, density = 7850 /
        &spinup omega = 1e6, period = 15 /
        &solver dt = 0.01, t_end = 0.02 /
        """))
    code, _, err = main("run", str(scene), "-o", str(tmp_path / "a.h5"))
    assert code == 2 and "omega = 1e+06 rad/s" in err and "--force" in err, err
    assert not (tmp_path / "a.h5").exists()
    code, out, err = main("run", str(scene), "-o", str(tmp_path / "b.h5"), "--force")
    assert code == 0, err
    with h5py.File(tmp_path / "b.h5", "r") as h5:
        assert h5.attrs["status"] == "ok" and len(h5["dynamic/time"]) == 3


# --- 4. files and faults ------------------------------------------------------------------

def _fsize_limit(limit: int):
    def apply() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
    return apply


def test_a_file_size_limit_ends_the_run_with_exit_3_and_a_readable_file(tmp_path):
    """ulimit -f 1.5 MB on a dynamic run that needs more (SIGSEGV in HDF5 before): exit 3,
    the message says the limit is full, the file says 'failed' and keeps its first rows."""
    out = tmp_path / "full.h5"
    code, _, err = ancf("run", str(INPUTS / "boom_luffing.nml"), "-o", str(out), "--set",
                        "output.q=.true.", "--set", "solver.t_end=2.0",
                        preexec=_fsize_limit(1500 * 1024))
    assert code == 3, (code, err)
    assert "file-size limit" in err
    with h5py.File(out, "r") as h5:
        assert h5.attrs["status"] == "failed"
        assert "file-size limit" in h5.attrs["message"]
        assert len(h5["dynamic/time"]) >= 1
    code, out_text, _ = main("info", str(out))
    assert code == 0 and out_text.startswith(f"{out}: failed")


def test_a_file_size_limit_too_small_for_the_model_is_exit_3(tmp_path):
    out = tmp_path / "tiny.h5"
    code, _, err = ancf("run", str(CANTILEVER), "-o", str(out),
                        preexec=_fsize_limit(64 * 1024))
    assert code == 3 and "file-size limit" in err, (code, err)


def _damage(good: Path, kind: str, path: Path) -> None:
    data = bytearray(good.read_bytes())
    if kind == "truncated":
        path.write_bytes(bytes(data[:3000]))
    elif kind == "scrambled":
        rng = np.random.default_rng(1)
        for i in range(2000, len(data), 97):
            data[i] = int(rng.integers(256))
        path.write_bytes(bytes(data))
    elif kind == "zeroed header":
        data[100:4000] = bytes(3900)
        path.write_bytes(bytes(data))
    elif kind == "no static group":
        shutil.copy(good, path)
        with h5py.File(path, "a") as h5:
            del h5["static"]
    elif kind == "scalar where a series was":
        shutil.copy(good, path)
        with h5py.File(path, "a") as h5:
            del h5["static/deflection"]
            h5["static/deflection"] = 1.0
    elif kind == "empty HDF5":
        h5py.File(path, "w").close()
    elif kind == "text":
        path.write_text("not a result\n")


DAMAGE = ["truncated", "scrambled", "zeroed header", "no static group",
          "scalar where a series was", "empty HDF5", "text"]


@pytest.fixture(scope="module")
def good_result(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("good") / "good.h5"
    code, _, err = main("run", str(CANTILEVER), "-o", str(out))
    assert code == 0, err
    return out


@pytest.mark.parametrize("command", ["info", "plot"])
@pytest.mark.parametrize("kind", DAMAGE)
def test_info_and_plot_turn_a_damaged_file_into_exit_2_naming_it(tmp_path, good_result,
                                                                 kind, command):
    path = tmp_path / "damaged.h5"
    _damage(good_result, kind, path)
    code, out, err = main(command, str(path))
    if command == "info" and kind in ("no static group",):
        assert code == 0 and out.startswith(f"{path}: ")  # still a result, read truthfully
        return
    assert code == 2, (kind, code, err)
    assert str(path) in err and "internal error" not in err, err


def test_a_table_drive_at_a_foreign_file_quotes_one_short_token(tmp_path):
    secret = tmp_path / "secret.txt"
    secret.write_text("root:x:0:0:root:/root\nuser:topsecretpassword:1000:1000::/home\n")
    scene = tmp_path / "s.nml"
    scene.write_text(textwrap.dedent(f"""\
        &scene title = 't', analysis = 'dynamic' /
        &solver dt = 0.01, t_end = 0.02 /
        &material name = 'm', youngs_modulus = 2.1e11, density = 7850 /
        &beam name = 'b', material = 'm', start = 0,0,0, end = 1,0,0, nodes = 3,
              width = 0.1, height = 0.1 /
        &drive name = 'd', type = 'table', file = '{secret}' /
        &joint name = 'r', type = 'weld', body1 = 'ground', body2 = 'b', point = 0,0,0 /
        &load name = 'f', type = 'force', body = 'b', point = 1,0,0, vector = 0,-1,0,
              drive = 'd' /
        &probe name = 'tip', body = 'b', point = 1,0,0 /
        """))
    code, _, err = main("run", str(scene), "-o", str(tmp_path / "o.h5"))
    assert code == 2 and "line 2" in err and "'user'" in err, err
    assert "topsecret" not in err and "/home" not in err


@pytest.mark.parametrize("target", ["existing file", "the scene itself"])
def test_sweep_output_onto_a_file_is_exit_2(tmp_path, target):
    scene = tmp_path / "c.nml"
    shutil.copy(CANTILEVER, scene)
    out = tmp_path / "taken.txt" if target == "existing file" else scene
    if target == "existing file":
        out.write_text("keep me\n")
    before = out.read_bytes()
    code, _, err = main("sweep", str(scene), "--vary", "beam.nodes=3,5", "-o", str(out))
    assert code == 2 and str(out) in err and "internal error" not in err, err
    assert out.read_bytes() == before


def test_sweep_workers_beyond_the_machine_are_capped(tmp_path):
    from ancfdrv.sweep_exec import worker_cap
    assert worker_cap(100000, 5) <= min(5, os.cpu_count() or 1)
    assert worker_cap(1, 5) == 1
    code, _, err = main("sweep", str(CANTILEVER), "--vary", "beam.nodes=3,5", "--workers",
                        "100000", "-o", str(tmp_path / "sw"))
    assert code == 0, err
    assert (tmp_path / "sw" / "summary.md").is_file()


def test_the_lock_covers_the_plot(tmp_path):
    """While ``ancf run`` writes its plot (the final phase), the output is still locked: a
    second run on it is refused then."""
    from ancfdrv.runner import run_scene
    out = tmp_path / "o.h5"
    seen = {}

    def second_run(done):
        with pytest.raises(InputError) as exc:
            OutputLock(out).acquire()
        seen["message"] = str(exc.value)
        return "plot"
    outcome_ = run_scene(CANTILEVER, None, out, progress=False, after=second_run)
    assert outcome_.after == "plot"
    assert "being written by another run" in seen["message"]
    OutputLock(out).acquire()  # released after the final phase


# --- 5. planted symbolic links ------------------------------------------------------------

@pytest.mark.parametrize("planted", [".png", ".h5.lock", ".h5", ".xdmf"])
def test_a_planted_symlink_is_never_written_through(tmp_path, planted):
    victim = tmp_path / "victim.txt"
    victim.write_text("secret\n")
    out = tmp_path / "o.h5"
    link = tmp_path / f"o{planted}"
    link.symlink_to(victim)
    args = ["run", str(INPUTS / "plate_pendulum.nml"), "-o", str(out), "--set",
            "solver.t_end=0.004", "--set", "plate.nx=2", "--set", "plate.ny=2"] \
        if planted == ".xdmf" else ["run", str(CANTILEVER), "-o", str(out), "--plot"]
    code, _, err = main(*args)
    assert victim.read_text() == "secret\n"  # nothing written outside the output area
    if planted == ".h5.lock":
        assert code == 2 and "is a symbolic link" in err, err
    elif planted == ".h5":
        assert code == 2 and "not an HDF5 file" in err, err  # refused: it points at text
    else:
        assert code == 0, err
        assert not link.is_symlink() and link.stat().st_size > 0  # replaced, not followed


def test_a_symlink_to_an_old_result_is_replaced_not_followed(tmp_path, good_result):
    target = tmp_path / "elsewhere.h5"
    shutil.copy(good_result, target)
    before = target.read_bytes()
    out = tmp_path / "o.h5"
    out.symlink_to(target)
    code, _, err = main("run", str(CANTILEVER), "-o", str(out))
    assert code == 0, err
    assert target.read_bytes() == before and not out.is_symlink()


@pytest.mark.parametrize("name", ["summary.csv", "summary.md"])
def test_sweep_summaries_replace_planted_symlinks(tmp_path, name):
    victim = tmp_path / "victim.txt"
    victim.write_text("secret\n")
    sweep = tmp_path / "sw"
    sweep.mkdir()
    (sweep / name).symlink_to(victim)
    code, _, err = main("sweep", str(CANTILEVER), "--vary", "beam.nodes=3,5", "-o", str(sweep))
    assert code == 0, err
    assert victim.read_text() == "secret\n"
    assert not (sweep / name).is_symlink() and "nodes" in (sweep / name).read_text()


# --- 6. signals to a sweep's parent -------------------------------------------------------

def _slow_sweep(tmp_path: Path, workers: str) -> tuple[subprocess.Popen, Path]:
    """A sweep whose cases each take seconds; returns once a case has started."""
    out = tmp_path / "sw"
    proc = subprocess.Popen(
        [sys.executable, "-m", "ancfdrv.cli", "sweep", str(INPUTS / "boom_luffing.nml"),
         "--vary", "beam.nodes=22,25,28,31", "--set", "solver.t_end=60", "--workers",
         workers, "-o", str(out)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_IGN))  # as `cmd &` does
    deadline = time.monotonic() + GUARD_S
    while not list(out.glob(".*.part.h5")):
        assert proc.poll() is None and time.monotonic() < deadline, proc.communicate()
        time.sleep(0.05)
    time.sleep(0.5)  # the case is stepping
    return proc, out


def _children(pid: int) -> list[int]:
    out = subprocess.run(["pgrep", "-P", str(pid)], capture_output=True, text=True).stdout
    return [int(p) for p in out.split()]


@pytest.mark.parametrize("signum, code, workers", [(signal.SIGINT, 130, "2"),
                                                    (signal.SIGTERM, 143, "2"),
                                                    (signal.SIGTERM, 143, "1")])
def test_a_signal_to_the_sweep_parent_stops_it_cleanly(tmp_path, signum, code, workers):
    proc, out = _slow_sweep(tmp_path, workers)
    children = _children(proc.pid)
    proc.send_signal(signum)
    _, err = proc.communicate(timeout=GUARD_S)
    assert proc.returncode == code, err
    assert "Traceback" not in err and "ancf sweep: interrupted: " in err, err
    if workers == "2":  # the parent's handler saw it (inline: the running case's handler)
        assert f"stopped by {signal.Signals(signum).name}" in err, err
    summary = (out / "summary.md").read_text()
    assert "cancelled" in summary and "4 cases" in summary
    for child in children:  # no worker outlives the sweep
        assert not Path(f"/proc/{child}").exists() or \
            "zombie" in Path(f"/proc/{child}/status").read_text()


def test_a_killed_sweep_parent_leaves_no_orphans_and_no_traceback(tmp_path):
    proc, out = _slow_sweep(tmp_path, "2")
    children = _children(proc.pid)
    assert children
    proc.kill()
    _, err = proc.communicate(timeout=GUARD_S)
    assert proc.returncode == -signal.SIGKILL
    deadline = time.monotonic() + GUARD_S
    while any(Path(f"/proc/{c}").exists() for c in children):
        assert time.monotonic() < deadline, "orphaned workers"
        time.sleep(0.05)
    assert "Traceback" not in err and "BrokenPipeError" not in err, err
    for part in out.glob(".*.part.h5"):  # what the workers wrote stays readable
        with h5py.File(part, "r") as h5:
            assert h5.attrs["status"] in ("interrupted", "running")


def test_a_general_scene_beyond_a_bound_is_refused_when_read(tmp_path):
    """The namelist door: the bound is checked when the scene is read (a sweep refuses it
    before any case runs), naming the file and the group; bounds = 'off' lifts it."""
    from ancfdrv.io.scene import load_scene
    text = textwrap.dedent("""\
        &scene title = 't'{extra} /
        &material name = 'm', youngs_modulus = 2.1e11, density = 7850 /
        &beam name = 'b', material = 'm', start = 0,0,0, end = 1,0,0, nodes = 3,
              width = 0.1, height = 0.1 /
        &joint name = 'r', type = 'weld', body1 = 'ground', body2 = 'b', point = 0,0,0 /
        &load name = 'f', type = 'force', body = 'b', point = 1,0,0, vector = 0,-1e12,0 /
        &probe name = 'tip', body = 'b', point = 1,0,0 /
        """)
    scene = tmp_path / "s.nml"
    scene.write_text(text.format(extra=""))
    with pytest.raises(InputError) as exc:
        load_scene(scene)
    assert str(exc.value).startswith(f"{scene}: &load[f]: load 'f': |vector| = 1e+12 N")
    scene.write_text(text.format(extra=", bounds = 'off'"))
    assert load_scene(scene)["scene"]["bounds"] == "off"
