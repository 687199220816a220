"""A dynamic run imports no scipy at all (ancfdrv._lazy, ancfdrv.csr): scipy.linalg and
scipy.sparse.linalg cost ~9 MB of the run's peak memory and scipy.sparse's import chain
(numpy.testing, unittest, numpy.f2py) ~19 MB (issue 23, benchmarks/peer_cantilever.py);
only the static, modal, buckling and FFR-reduction analyses and eliminated joints'
reactions use them. Nor does a run import matplotlib or the plots. The modules that import
them lazily still reach them when they are needed."""
from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

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
