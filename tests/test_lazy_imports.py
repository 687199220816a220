"""A dynamic run imports no scipy at all (ancfdrv._lazy, ancfdrv.csr): scipy.linalg and
scipy.sparse.linalg cost ~9 MB of the run's peak memory and scipy.sparse's import chain
(numpy.testing, unittest, numpy.f2py) ~19 MB (issue 23, benchmarks/peer_cantilever.py);
only the static, modal, buckling and FFR-reduction analyses and eliminated joints'
reactions use them. Nor does a run import matplotlib or the plots. The modules that import
them lazily still reach them when they are needed.

Issue 38 (a command's start): ``ancf --help`` imports neither numpy, h5py nor the package's
system (the package's names are imported on first use), and ``ancf run`` of a dynamic scene
imports neither the Python analyses (ancfdrv.analyses, the Results reader), the modal and
buckling solvers nor ElementTree (the XDMF is written as text); System's analyses still
load on its first analysis, however System was imported."""
from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from ancfdrv._lazy import LazyModule

ROOT = Path(__file__).resolve().parents[1]


def test_dynamic_run_does_not_import_dense_linear_algebra(tmp_path):
    code = textwrap.dedent(f"""
        import sys
        import ancfdrv, ancfdrv.runner
        from ancfdrv.runner import run_scene
        run_scene({str(ROOT / "inputs/hard/cantilever_drop.nml")!r},
                  ["beam.nodes=5", "solver.t_end=0.01"], {str(tmp_path / "r.h5")!r},
                  progress=False)
        print(sorted(m for m in sys.modules
                     if m.startswith(("scipy.linalg", "scipy.sparse.linalg"))))
    """)
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.strip().splitlines()[-1] == "[]"
    assert (tmp_path / "r.h5").exists()


def test_dynamic_runs_import_no_scipy(tmp_path):
    """Shipped scenes through run_scene (model build, initial acceleration, stepping, HDF5
    with answers and XDMF): a beam with its clamp eliminated (a selection B), the planar
    cable pendulum (B with the plane's fixes), the FFR luffing boom (constant policy: the
    solver-frame check) and the plate pendulum; each must also leave its file."""
    runs = [("inputs/hard/cantilever_drop.nml", ["beam.nodes=5", "solver.t_end=0.01"]),
            ("inputs/hard/pendulum.nml", ["beam.nodes=5", "beam.bending=cable",
                                          "scene.planar=xy", "solver.t_end=0.01"]),
            ("inputs/boom_luffing.nml", ["beam.nodes=4", "solver.t_end=0.01"]),
            ("inputs/plate_pendulum.nml", ["solver.t_end=0.002"])]
    code = textwrap.dedent(f"""
        import sys
        from ancfdrv.runner import run_scene
        for i, (scene, sets) in enumerate({[(str(ROOT / s), o) for s, o in runs]!r}):
            run_scene(scene, sets, {str(tmp_path)!r} + f"/r{{i}}.h5", progress=False)
        print(sorted(m for m in sys.modules if m == "scipy" or m.startswith(
            ("scipy.", "matplotlib", "ancfdrv.plots", "numpy.testing", "unittest"))))
    """)
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.strip().splitlines()[-1] == "[]"
    assert all((tmp_path / f"r{i}.h5").exists() for i in range(len(runs)))


def test_lazy_module_imports_on_first_use():
    import numpy as np
    import scipy.linalg

    lazy = LazyModule("scipy.linalg")
    assert lazy.solve is scipy.linalg.solve
    assert np.allclose(lazy.solve(np.diag([2.0, 4.0]), np.array([2.0, 4.0])), [1.0, 1.0])
    assert issubclass(lazy.LinAlgError, Exception)
    try:
        lazy.__wrapped__
    except AttributeError:
        pass
    else:
        raise AssertionError("dunder lookups must not import")


def _modules_after(code: str, cwd: Path = ROOT) -> list[str]:
    done = subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True,
                          text=True, timeout=120, cwd=cwd)
    assert done.returncode == 0, done.stderr[-2000:]
    return eval(done.stdout.strip().splitlines()[-1])  # noqa: S307 - our own list literal


def test_help_imports_no_numpy_nor_the_system():
    found = _modules_after("""
        import sys
        import ancfdrv.cli
        for argv in (["--help"], ["run", "--help"]):
            try:
                ancfdrv.cli.main(argv)
            except SystemExit as stop:
                assert stop.code == 0, stop.code
        print(sorted(m for m in sys.modules if m.split(".")[0] in ("numpy", "h5py", "scipy")
                     or m.startswith(("ancfdrv.system", "ancfdrv.results", "ancfdrv.runner"))))
    """)
    assert found == []


def test_a_command_line_run_imports_only_what_it_runs(tmp_path):
    found = _modules_after(f"""
        import sys
        from ancfdrv.cli import main
        assert main(["run", "inputs/boom_luffing.nml", "-o", {str(tmp_path / "b.h5")!r},
                     "--set", "beam.nodes=4", "--set", "solver.t_end=0.05"]) == 0
        assert "ancfdrv.runner" in sys.modules and "ancfdrv.results.xdmf" in sys.modules
        print(sorted(m for m in sys.modules if m in (
            "ancfdrv.analyses", "ancfdrv.results.reader", "ancfdrv.simulation",
            "ancfdrv.solvers.modal", "ancfdrv.solvers.buckling", "xml.etree.ElementTree")))
    """)
    assert found == []
    assert (tmp_path / "b.h5").exists() and (tmp_path / "b.xdmf").exists()


def test_system_analyses_load_on_first_use():
    """System imported from its own module (not through ``ancfdrv``): its first analysis
    loads ancfdrv.analyses, and the static sag of a cantilever under its tip force is
    P L^3 / 3 E I (Euler-Bernoulli, within 2e-3 as in tests/test_results_api.py: the
    beam's shear flexibility adds ~1e-3)."""
    found = _modules_after("""
        import sys
        from ancfdrv.system import Rectangle, System
        assert "ancfdrv.analyses" not in sys.modules
        s = System("cantilever")
        steel = s.material("steel", youngs_modulus=2.1e11, density=7850.0)
        s.beam("arm", material=steel, start=(0, 0, 0), end=(2.0, 0, 0), nodes=5,
               section=Rectangle(0.05, 0.1), height_axis=(0, 1, 0), formulation="nonlinear",
               bending="cubic")
        s.joint("root", "weld", "ground", "arm", point=(0, 0, 0))
        s.load("tip", "force", body="arm", point=(2.0, 0, 0), vector=(0, -100.0, 0))
        s.probe("end", "arm", (2.0, 0, 0))
        res = s.static()
        import ancfdrv
        assert ancfdrv.System is System and ancfdrv.open is ancfdrv.open_results
        print([float(res.deflection["end"][1]), "ancfdrv.analyses" in sys.modules])
    """)
    sag = 100.0 * 2.0**3 / (3 * 2.1e11 * 0.05 * 0.1**3 / 12)
    assert found[1] is True
    assert found[0] == pytest.approx(-sag, rel=2e-3)


def test_the_reader_alone_reads_a_general_scene():
    """io.scene.load_scene in a fresh interpreter, before anything imported the kinds or the
    general builder: a general scene with two &rigid_body groups (repeatable only once the
    kinds have registered their groups) reads, with its effects from the builder. Two test
    files failed when run alone ('group given twice', 'import ancfdrv (the package)') and
    passed only after another file had imported the builders."""
    root = Path(__file__).resolve().parent.parent
    found = _modules_after(f"""
        import sys
        from ancfdrv.io.scene import load_scene
        assert "ancfdrv.builders.general" not in sys.modules
        scene = load_scene({str(root / "inputs" / "general" / "cardan_shaft.nml")!r})
        print([sum(g == "rigid_body" for g, _ in scene.items), len(scene.items),
               sorted(scene.values["scene"]["effects"])])
    """)
    from ancfdrv.io.scene import load_scene  # here, where the suite has imported them
    here = load_scene(root / "inputs" / "general" / "cardan_shaft.nml")
    assert found[0] >= 2
    assert found[1:] == [len(here.items), sorted(here.values["scene"]["effects"])]


def test_a_small_cable_run_imports_no_numpy_extras_nor_starts_a_process(tmp_path):
    """The accuracy-matched boom of issue 38 (nonlinear planar cable, Newton statics) through
    ``ancf run``: numpy.ma (np.unique, np.setdiff1d) and numpy.polynomial (leggauss) stay
    unimported; an installed package's provenance starts no git nor gfortran (here: with
    the checkout's git and the build's record hidden, not one subprocess); the collector
    is on again after the command's imports."""
    found = _modules_after(f"""
        import gc, subprocess, sys
        from ancfdrv.cli import main
        from ancfdrv.results import hdf5
        started = []
        real = subprocess.Popen.__init__
        def popen(self, args, *rest, **kwargs):
            started.append(args)
            return real(self, args, *rest, **kwargs)
        subprocess.Popen.__init__ = popen
        hdf5._source_tree = lambda: None
        assert main(["run", "inputs/boom_luffing.nml", "-o", {str(tmp_path / "c.h5")!r},
                     "--set", "scene.formulation=nonlinear", "--set", "solver.static_method=newton",
                     "--set", "beam.bending=cable", "--set", "scene.planar=xy",
                     "--set", "beam.nodes=4", "--set", "solver.dt=0.02",
                     "--set", "solver.t_end=0.5", "--set", "output.xdmf=.false."]) == 0
        assert gc.isenabled()
        print(sorted(m for m in sys.modules if m.split(".")[:2] in (
            ["numpy", "ma"], ["numpy", "polynomial"]) or m.split(".")[0] in (
            "scipy", "matplotlib")) + [str(a) for a in started])
    """)
    assert found == []
    assert (tmp_path / "c.h5").exists()
