"""Repeatable runs (issue 35 item 2): the same scene run twice on the same machine, each time
in a fresh process (``python -m ancfdrv.cli run``: a random eigen-solver start or an
uninitialized array would differ between processes, not within one), gives the same HDF5
file bit for bit: every dataset (values with NaN positions, dtype, shape) and every
attribute, except the few that record the time of day or a measured wall time:

* the root attributes ``created`` and ``finished`` (UTC time stamps of the run);
* every attribute of ``/timing`` (seconds spent per phase);
* ``wall_time_s`` and ``time_<phase>_s`` of the analysis groups (seconds measured).

Both runs get the same command line in their own directory (relative paths), so the
provenance (``command``, ``scene_file``, ``overrides``, ``scene``) must repeat too.
One tiny model per analysis kind: the split static iteration with fixed steps, Newton with
adaptive steps on a general scene with a tension-only rope and a spring-damper, sparse
(ARPACK) modes, and linear and nonlinear buckling with the sparse eigen-solver (the linear
one started ARPACK from OS entropy: its factors changed in the last digits run to run)."""
from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

CLOCK = frozenset({"/@created", "/@finished"})
WALL = re.compile(r"(wall_time_s|time_[a-z_]+_s)$")

CANTILEVER = """
&scene  title = 'repeat: {title}', analysis = '{analysis}', formulation = 'nonlinear' /
&material  name = 'steel', youngs_modulus = 2.1e11, density = 7850.0 /
&beam  name = 'arm', material = 'steel', start = 0, 0, 0, end = 1.0, 0, 0, nodes = 5,
       section = 'rectangle', width = 0.02, height = 0.03, height_axis = 0, 1, 0 /
&joint  name = 'root', type = 'weld', body1 = 'ground', body2 = 'arm', point = 0, 0, 0 /
&load  name = 'g', type = 'gravity', vector = -9.81, -1.0, 0 /
&load  name = 'push', type = 'force', body = 'arm', point = 1.0, 0, 0, vector = -100, 0, 0 /
&probe  name = 'tip', body = 'arm', point = 1.0, 0, 0 /
&modal  modes = 3, solver = 'sparse' /
&buckling  modes = 2, solver = 'sparse', fixed_loads = 'g', method = '{method}' /
&solver  static_method = 'newton' /
"""

SCENES = {
    # an 'ffr' cantilever shaken at its tip by a driven force: the split static iteration,
    # then fixed steps
    "split_fixed_steps": """
&scene  title = 'repeat: split, fixed steps', analysis = 'static+dynamic', formulation = 'ffr' /
&material  name = 'steel', youngs_modulus = 2.1e11, density = 7850.0 /
&drive  name = 'wave', type = 'sine', amplitude = 1.0, frequency = 20.0, offset = 1.0 /
&beam  name = 'arm', material = 'steel', start = 0, 0, 0, end = 1.0, 0, 0, nodes = 4,
       section = 'rectangle', width = 0.02, height = 0.03, height_axis = 0, 1, 0 /
&joint  name = 'root', type = 'weld', body1 = 'ground', body2 = 'arm', point = 0, 0, 0 /
&load  name = 'g', type = 'gravity', vector = 0, -9.81, 0 /
&load  name = 'shake', type = 'force', body = 'arm', point = 1.0, 0, 0, vector = 0, 20, 50,
       drive = 'wave' /
&probe  name = 'tip', body = 'arm', point = 1.0, 0, 0 /
&solver  static_method = 'split', dt = 1e-3, t_end = 0.02 /
""",
    # a hinged arm held by a spring-damper, a payload on a tension-only rope from its tip,
    # pulled sideways: Newton statics, then adaptive steps (some rejected)
    "newton_adaptive_rope_spring": """
&scene  title = 'repeat: newton, adaptive steps', analysis = 'static+dynamic',
        formulation = 'nonlinear' /
&material  name = 'steel', youngs_modulus = 2.1e11, density = 7850.0 /
&material  name = 'wire', youngs_modulus = 1.0e11, density = 5000.0 /
&drive  name = 'pull', type = 'sine', amplitude = 1.0, frequency = 5.0, offset = 0.0 /
&beam  name = 'arm', material = 'steel', start = 0, 0, 0, end = 1.0, 0, 0, nodes = 3,
       section = 'rectangle', width = 0.02, height = 0.03, height_axis = 0, 1, 0 /
&cable  name = 'rope', material = 'wire', start = 1.0, 0, 0, end = 1.0, -0.5, 0, nodes = 3,
        section = 'circle', diameter = 0.004, tension_only = .true., bending_stiffness = 0.1 /
&joint  name = 'pin', type = 'revolute', body1 = 'ground', body2 = 'arm', point = 0, 0, 0,
        axis = 0, 0, 1 /
&joint  name = 'hook', type = 'spherical', body1 = 'arm', body2 = 'rope', point = 1.0, 0, 0 /
&force_element  name = 'spring', type = 'spring_damper', body1 = 'ground', body2 = 'arm',
        point1 = 0.5, 0.5, 0, point2 = 0.5, 0, 0, stiffness = 2e5, damping = 50.0 /
&load  name = 'g', type = 'gravity', vector = 0, -9.81, 0 /
&load  name = 'payload', type = 'point_mass', body = 'rope', point = 1.0, -0.5, 0, mass = 5.0 /
&load  name = 'side', type = 'force', body = 'rope', point = 1.0, -0.5, 0, vector = 5.0, 0, 0,
       drive = 'pull' /
&probe  name = 'hook', body = 'rope', point = 1.0, -0.5, 0 /
&solver  static_method = 'newton', step = 'adaptive', dt = 5e-3, t_end = 0.05 /
""",
    "modal_sparse": CANTILEVER.format(title="modes", analysis="modal", method="linear"),
    "buckling_linear": CANTILEVER.format(title="buckling", analysis="buckling",
                                         method="linear"),
    "buckling_nonlinear": CANTILEVER.format(title="buckling", analysis="buckling",
                                            method="nonlinear"),
}


#: attributes that show each run took the path it is there for
PATHS = {
    "split_fixed_steps": {"/static@method": "split", "/dynamic@step_control": "fixed"},
    "newton_adaptive_rope_spring": {"/static@method": "newton",
                                    "/dynamic@step_control": "adaptive"},
    "modal_sparse": {"/modal@method": "sparse"},  # ARPACK, not LAPACK
    "buckling_linear": {"/buckling@solver": "sparse", "/buckling@method": "linear"},
    "buckling_nonlinear": {"/buckling@solver": "sparse", "/buckling@method": "nonlinear"},
}


def _content(path: Path) -> dict[str, object]:
    """Every dataset and attribute of a result file by its path (attributes as
    ``group@name``), without the clock and wall-time attributes of the module doc."""
    out: dict[str, object] = {}

    def keep(owner: str, obj) -> None:
        for key, value in obj.attrs.items():
            name = f"{owner}@{key}"
            if name not in CLOCK and not owner.startswith("/timing") and not WALL.match(key):
                out[name] = value

    with h5py.File(path, "r") as h5:
        keep("/", h5)

        def visit(name: str, obj) -> None:
            if isinstance(obj, h5py.Dataset):
                out[f"/{name}"] = obj[()]
            keep(f"/{name}", obj)
        h5.visititems(visit)
    return out


def _same(x, y) -> bool:
    """Bit for bit: the same dtype and shape, equal values and NaN in the same places
    (floats compared as bytes: -0.0 and 0.0 differ, as in the file)."""
    a, b = np.asarray(x), np.asarray(y)
    if a.dtype != b.dtype or a.shape != b.shape:
        return False
    if a.dtype.kind in "fc":
        return a.tobytes() == b.tobytes()
    return bool(np.array_equal(a, b))


def _run_twice(directory: Path, text: str) -> tuple[Path, Path]:
    """The scene run in two fresh processes at once, each in its own directory with the
    same (relative) command line; their files."""
    runs = []
    for name in ("first", "second"):
        where = directory / name
        where.mkdir()
        (where / "scene.nml").write_text(text)
        runs.append(subprocess.Popen(
            [sys.executable, "-m", "ancfdrv.cli", "run", "scene.nml", "-o", "out.h5"],
            cwd=where, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True))
    for proc in runs:
        out, err = proc.communicate(timeout=120)
        assert proc.returncode == 0, out + err
    return directory / "first" / "out.h5", directory / "second" / "out.h5"


@pytest.mark.parametrize("kind", SCENES)
def test_the_same_input_gives_the_same_file(tmp_path, kind):
    first, second = (_content(p) for p in _run_twice(tmp_path, SCENES[kind]))
    for name, value in PATHS[kind].items():
        assert first[name] == value, name
    if kind == "newton_adaptive_rope_spring":
        assert first["/dynamic@steps_rejected"] > 0  # the step size did adapt
    assert sorted(first) == sorted(second)
    differ = [name for name in first if not _same(first[name], second[name])]
    assert differ == []
