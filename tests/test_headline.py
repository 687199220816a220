"""What ``ancf run`` ends with and what ``ancf info`` answers (SPEC section 2, issues 37
item 5 and 38 item 2): the plot only when asked (--plot or output.plot), the headline of
the analysis (every static reaction in a table, the largest stress and where, the largest
probe displacement; the dynamic run's end, reaction peaks, stress envelope and energy
balance; every frequency and load factor), and ``ancf info --json``. Every printed number
is parsed back and compared with the file's own datasets, read here with h5py."""
from __future__ import annotations

import json
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import h5py
import numpy as np
import pytest

from ancfdrv.cli import main

ROOT = Path(__file__).resolve().parents[1]
CANTILEVER = ROOT / "inputs" / "cantilever.nml"
CRANE = ROOT / "inputs" / "knuckle_crane_rope.nml"

MODAL = """
&scene  title = 'cantilever modes', analysis = '{analysis}', formulation = 'nonlinear' /
&material  name = 'steel', youngs_modulus = 2.1e11, density = 7850.0 /
&beam  name = 'arm', material = 'steel', start = 0, 0, 0, end = 2.0, 0, 0, nodes = 9,
       section = 'rectangle', width = 0.02, height = 0.03, height_axis = 0, 1, 0,
       bending = 'cubic' /
&joint  name = 'root', type = 'weld', body1 = 'ground', body2 = 'arm', point = 0, 0, 0 /
&load  name = 'g', type = 'gravity', vector = -9.81, 0, 0 /
&load  name = 'push', type = 'force', body = 'arm', point = 2.0, 0, 0, vector = -100, 0, 0 /
&solver  static_method = 'newton' /
{extra}
"""


def blocks(text: str) -> dict[str, list[str]]:
    """The headline's blocks by their first word ('static', 'dynamic', 'modal',
    'buckling'): the indented lines under each heading."""
    out: dict[str, list[str]] = {}
    current = None
    for line in text.splitlines():
        heading = re.match(r"^(static|dynamic|modal|buckling) answers", line)
        if heading:
            current = out.setdefault(heading.group(1), [])
        elif current is not None and line.startswith(" "):
            current.append(line)
        else:
            current = None
    return out


def table_rows(lines: list[str]) -> dict[str, tuple[str, list[float | None]]]:
    """Rows of a reaction table: name -> (kind, numbers; '-' is None)."""
    rows = {}
    for line in lines:
        match = re.match(r"^ {4}'(.+?)'\s+(joint|force element)\s+(.*)$", line)
        if match:
            rows[match.group(1)] = (match.group(2), [None if v == "-" else float(v)
                                                     for v in match.group(3).split()])
    return rows


def numbers_after(lines: list[str], label: str) -> list[float]:
    """The values of a wrapped value list ('  frequencies (Hz): 1 2 ...' and its
    continuation lines)."""
    values: list[float] = []
    inside = False
    for line in lines:
        if line.startswith(f"  {label}:"):
            inside = True
            values += [float(v) for v in line.split(":", 1)[1].split()]
        elif inside and line.startswith("   ") and ":" not in line:
            values += [float(v) for v in line.split()]
        else:
            inside = False
    return values


def first_float(pattern: str, lines: list[str]) -> tuple[float, ...]:
    for line in lines:
        match = re.search(pattern, line)
        if match:
            return tuple(float(g) if re.fullmatch(r"[-+.\deE]+", g) else g
                         for g in match.groups())
    raise AssertionError(f"no line matches {pattern!r} in {lines}")


def test_plain_run_writes_no_plot_and_imports_no_matplotlib(tmp_path):
    """Without --plot nor output.plot: no PNG beside the result, and neither matplotlib
    nor the plots module is imported (issue 38: 0.5-1 s per run)."""
    out = tmp_path / "c.h5"
    code = textwrap.dedent(f"""
        import sys
        from ancfdrv.cli import main
        status = main(["run", {str(CANTILEVER)!r}, "-o", {str(out)!r}])
        print(status, sorted(m for m in sys.modules
                             if m.startswith(("matplotlib", "ancfdrv.plots"))))
    """)
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.strip().splitlines()[-1] == "0 []"
    assert out.exists() and not out.with_suffix(".png").exists()
    assert "written      " + str(out) + "\n" in done.stdout  # names the result alone


@pytest.mark.parametrize("ask", [["--plot"], ["--set", "output.plot=.true."]])
def test_plot_when_asked(tmp_path, capsys, ask):
    out = tmp_path / "c.h5"
    assert main(["run", str(CANTILEVER), "-o", str(out), *ask]) == 0
    png = out.with_suffix(".png")
    assert png.stat().st_size > 1000
    assert f"written      {out}, {png}" in capsys.readouterr().out


@pytest.fixture(scope="module")
def crane(tmp_path_factory) -> tuple[Path, str]:
    """The knuckle crane with its rope (joints and a force element), statics and 10 steps
    of dynamics: (result file, what ancf run printed)."""
    import contextlib
    import io
    out = tmp_path_factory.mktemp("crane") / "crane.h5"
    text = io.StringIO()
    with contextlib.redirect_stdout(text):
        assert main(["run", str(CRANE), "-o", str(out), "--set", "solver.t_end=0.05"]) == 0
    return out, text.getvalue()


def test_static_headline_lists_every_reaction_with_the_file_values(crane):
    out, printed = crane
    static = blocks(printed)["static"]
    rows = table_rows(static)
    with h5py.File(out) as h5:
        group = h5["static/reactions"]
        assert set(rows) == set(group) == {"column pin", "main cylinder", "knuckle",
                                           "jib cylinder", "rope top"}
        scale = max(np.abs(group[n][w][()]).max() for n in group for w in ("force", "moment"))
        for name, (kind, values) in rows.items():
            # the scene: 'jib cylinder' is the &force_element, the others &joint groups
            assert kind == ("force element" if name == "jib cylinder" else "joint"), name
            expected = [*group[name]["force"][()], *group[name]["moment"][()]]
            np.testing.assert_allclose(values[:6], expected, rtol=0, atol=1e-5 * scale)
            if "axial" in group[name]:
                assert values[6] == pytest.approx(float(group[name]["axial"][()]), rel=1e-5)
            else:
                assert values[6] is None
        # the largest von Mises stress over the beams' stations, where it is
        best = max(((sub["von_mises"][()].max(), name, sub["s"][np.argmax(
            sub["von_mises"][()])]) for name, sub in h5["static/stress"].items()))
        stress, beam, s = first_float(r"largest von Mises stress (\S+) MPa in beam '(.+?)' "
                                      r"at s = (\S+) m", static)
        assert stress * 1e6 == pytest.approx(best[0], rel=1e-5)
        assert beam == best[1] and s == pytest.approx(best[2], abs=1e-9)
        # the largest probe displacement (file basis) and where
        sizes = {n: np.linalg.norm(d[()]) for n, d in h5["static/deflection"].items()}
        probe = max(sizes, key=sizes.get)
        size, name = first_float(r"largest probe displacement (\S+) mm at probe '(.+?)'",
                                 static)
        assert name == probe and size * 1e-3 == pytest.approx(sizes[probe], rel=1e-5)


def test_dynamic_headline_end_peaks_envelope_and_energy(crane):
    out, printed = crane
    dynamic = blocks(printed)["dynamic"]
    with h5py.File(out) as h5:
        group = h5["dynamic"]
        time = group["time"][()]
        t, steps = first_float(r"reached t = (\S+) s in (\d+) steps", dynamic)
        assert t == pytest.approx(time[-1], rel=1e-6) and steps == group.attrs["steps"] == 10
        rows = table_rows(dynamic)
        assert set(rows) == set(group["reactions"])
        for name, (kind, values) in rows.items():
            force = np.linalg.norm(group["reactions"][name]["force"][()], axis=1)
            assert values[0] == pytest.approx(force.max(), rel=1e-5)
            assert values[1] == pytest.approx(time[np.argmax(force)], abs=1e-9)
        envelope = {n: sub["von_mises_max"][()] for n, sub in group["stress"].items()}
        beam = max(envelope, key=lambda n: envelope[n].max())
        k = int(np.argmax(envelope[beam]))
        stress, where, s, when = first_float(
            r"largest von Mises stress (\S+) MPa in beam '(.+?)' at s = (\S+) m, t = (\S+) s",
            dynamic)
        assert stress * 1e6 == pytest.approx(envelope[beam][k], rel=1e-5) and where == beam
        assert s == pytest.approx(group["stress"][beam]["s"][k], abs=1e-9)
        assert when == pytest.approx(group["stress"][beam]["t_max"][k], abs=1e-9)
        balance = group["energy/balance"][()]
        largest, final = first_float(r"energy balance E - E0 - W: largest (\S+) J.*final "
                                     r"(\S+) J", dynamic)
        assert abs(largest) == pytest.approx(np.abs(balance).max(), rel=1e-5)
        assert final == pytest.approx(balance[-1], rel=1e-5)


def test_info_json_is_the_file(crane, capsys):
    """ancf info --json parses, and its answers are the file's values in full."""
    out, _ = crane
    capsys.readouterr()
    assert main(["info", str(out), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["verdict"] == "ok" and data["file"] == str(out)
    with h5py.File(out) as h5:
        assert data["summary"]["model.ndof"] == h5["model"].attrs["ndof"]
        np.testing.assert_array_equal(data["summary"]["static.deflection.hook"],
                                      h5["static/deflection/hook"][()])
        reactions = data["answers"]["static"]["reactions"]
        assert set(reactions) == set(h5["static/reactions"])
        for name, r in reactions.items():
            np.testing.assert_array_equal(r["force"], h5["static/reactions"][name]["force"])
            np.testing.assert_array_equal(r["moment"], h5["static/reactions"][name]["moment"])
        assert reactions["jib cylinder"]["kind"] == "force element"
        peaks = data["answers"]["dynamic"]["reactions"]
        force = np.linalg.norm(h5["dynamic/reactions/knuckle/force"][()], axis=1)
        assert peaks["knuckle"]["force_max"] == force.max()
        assert data["answers"]["dynamic"]["energy_balance"]["final"] == \
            h5["dynamic/energy/balance"][-1]


def test_info_text_lists_every_reaction(crane, capsys):
    out, _ = crane
    capsys.readouterr()
    assert main(["info", str(out)]) == 0
    text = capsys.readouterr().out
    with h5py.File(out) as h5:
        names = set(h5["static/reactions"])
    assert set(table_rows(blocks(text)["static"])) == names
    assert ": ok:" in text.splitlines()[0]


@pytest.mark.parametrize("analysis, extra, group, key, label", [
    ("modal", "&modal modes = 11 /", "modal", "frequency", "frequencies (Hz)"),
    ("buckling", "&buckling modes = 9, fixed_loads = 'g' /", "buckling", "load_factor",
     "load factors")])
def test_eigen_headline_lists_every_value(tmp_path, capsys, analysis, extra, group, key,
                                          label):
    """Every frequency / load factor in ancf run's headline and in ancf info --json (more
    than the six the old summary showed); ancf info's figure list cuts the array and says
    how many values it left out."""
    scene = tmp_path / f"{analysis}.nml"
    scene.write_text(MODAL.format(analysis=analysis, extra=extra))
    out = tmp_path / f"{analysis}.h5"
    assert main(["run", str(scene), "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    with h5py.File(out) as h5:
        values = h5[group][key][()]
    assert len(values) > 8
    shown = numbers_after(blocks(printed)[group], label)
    np.testing.assert_allclose(shown, values, rtol=1e-5)
    assert main(["info", str(out), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["answers"][group][key] == values.tolist()
    assert data["summary"][f"{group}.{key}"] == values.tolist()
    assert main(["info", str(out)]) == 0
    text = capsys.readouterr().out
    line = next(x for x in text.splitlines() if x.startswith(f"{group}.{key} "))
    assert line.endswith(f"... {len(values) - 8} more")
    np.testing.assert_allclose(numbers_after(blocks(text)[group], label), values, rtol=1e-5)


def test_reaction_names_with_a_slash(tmp_path, capsys):
    """The simply supported plate's joints 'support dw/dx' and 'support dw/dy' are nested
    groups in HDF5: the table lists them by their names, with the file's values."""
    out = tmp_path / "plate.h5"
    assert main(["run", str(ROOT / "inputs" / "plate_pressure.nml"), "-o", str(out),
                 "--set", "plate.nx=4", "--set", "plate.ny=4"]) == 0
    rows = table_rows(blocks(capsys.readouterr().out)["static"])
    with h5py.File(out) as h5:
        found = {}
        h5["static/reactions"].visititems(
            lambda name, item: found.update({name: item}) if isinstance(item, h5py.Group)
            and "force" in item else None)
        assert {"support dw/dx", "support dw/dy"} <= set(rows) == set(found)
        scale = max(np.abs(g["force"][()]).max() for g in found.values())
        for name, (kind, values) in rows.items():
            np.testing.assert_allclose(values[:3], found[name]["force"][()], rtol=0,
                                       atol=1e-5 * scale)
