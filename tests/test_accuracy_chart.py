"""The accuracy-versus-time chart of a sweep (issue 37 item 6): its time axis is the run's
own computing time from the file's /timing (model build, assembly, factorization and solve
of every analysis: static, settling, stepping, modal, buckling), not the process's wall
time, which counts the interpreter's start-up and the imports in the first case of each
worker (a 3-node run plotted as the slowest); the chart draws each family's Pareto front.

No test times anything: they check what is summed and where it is read from."""
from __future__ import annotations

import csv
from pathlib import Path

import h5py
import pytest

from ancfdrv.plots import pareto_front
from ancfdrv.results.hdf5 import phase_times
from ancfdrv.sweep import run_sweep

COLUMN = """
&scene  title = 'steel column', analysis = '{analysis}', formulation = 'nonlinear' /
&material  name = 'steel', youngs_modulus = 2.1e11, density = 7850.0 /
&beam  name = 'arm', material = 'steel', start = 0, 0, 0, end = 2.0, 0, 0, nodes = 5,
       section = 'rectangle', width = 0.02, height = 0.03, height_axis = 0, 1, 0,
       bending = 'cubic' /
&joint  name = 'root', type = 'weld', body1 = 'ground', body2 = 'arm', point = 0, 0, 0 /
&load  name = 'push', type = 'force', body = 'arm', point = 2.0, 0, 0, vector = -100, 0, 0 /
&probe  name = 'tip', body = 'arm', point = 2.0, 0, 0 /
&modal  modes = 3 /
&buckling  modes = 2, method = 'linear' /
&solver  static_method = 'newton' /
"""


def test_the_pareto_front_keeps_the_cheapest_run_for_each_accuracy():
    points = [(1.0, 5.0), (2.0, 3.0), (3.0, 4.0), (4.0, 1.0), (0.5, 9.0), (5.0, 1.0)]
    assert pareto_front(points) == [(0.5, 9.0), (1.0, 5.0), (2.0, 3.0), (4.0, 1.0)]
    assert pareto_front([]) == []


def test_every_analysis_counts_in_the_computing_time():
    timing = {"model": 1.0, "static_assembly": 2.0, "static_factorization": 4.0,
              "static_solve": 8.0, "settle_solve": 16.0, "dynamic_setup": 32.0,
              "dynamic_stepping": 64.0, "dynamic_output": 128.0, "output": 256.0,
              "modal_static": 512.0, "modal_assembly": 1024.0, "modal_eigen": 2048.0,
              "buckling_total": 4096.0, "total": 10000.0}
    phases = phase_times(timing)
    assert phases["assembly"] == 1.0 + 2.0 + 1024.0
    assert phases["factorization"] == 4.0 + 32.0
    assert phases["solve"] == 8.0 + 16.0 + 64.0 + 512.0 + 2048.0 + 4096.0
    assert phases["output"] == 128.0 + 256.0
    assert phases["compute"] == phases["assembly"] + phases["factorization"] + phases["solve"]
    assert phases["total"] == 10000.0


@pytest.mark.parametrize("analysis", ["static", "modal", "buckling"])
def test_a_sweep_tabulates_the_files_computing_time(tmp_path, analysis):
    path = tmp_path / f"{analysis}.nml"
    path.write_text(COLUMN.format(analysis=analysis))
    out = tmp_path / "sweep"
    rows = run_sweep(str(path), ["beam.nodes=3,5"], out, workers=1, progress=False)
    assert [r["status"] for r in rows] == ["ok", "ok"]
    for row in rows:
        with h5py.File(out / f"nodes-{row['beam.nodes']}.h5", "r") as h5:
            timing = dict(h5["timing"].attrs)
        own = timing["assembly"] + timing["factorization"] + timing["solve"]
        assert row["compute_time_s"] == pytest.approx(own, rel=1e-12)
        assert row["compute_time_s"] == pytest.approx(timing["compute"], rel=1e-12)
        # the analysis itself is inside (a modal or buckling run was 0 s before)
        analysis_time = timing[f"{analysis}_total"]
        assert analysis_time > 0 and row["compute_time_s"] >= 0.99 * analysis_time
        assert row["compute_time_s"] <= row["total_time_s"]
    table = (out / "summary.md").read_text()
    assert "| compute (s) | case time (s) |" in table
    assert {r["compute_time_s"] for r in csv.DictReader(open(out / "summary.csv"))} != {""}
    if analysis != "static":  # (the column's axial shortening is exact at any mesh)
        assert (out / "error_vs_time.png").stat().st_size > 0
