"""A dynamic run imports neither scipy.linalg nor scipy.sparse.linalg (ancfdrv._lazy): they
cost ~9 MB of the run's peak memory (issue 23, benchmarks/peer_cantilever.py) and only the
modal, buckling and FFR-reduction analyses and eliminated joints' reactions use them. The
modules that import them lazily still reach them when they are needed."""
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
