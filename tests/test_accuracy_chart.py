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


def test_the_chart_orders_the_runs_by_their_computing_time(tmp_path, monkeypatch):
    """The demo's error_vs_time.png (a node sweep): the first case's process time counts
    the interpreter's start-up (case time 3 s for 3 nodes), its computing time does not;
    the chart places each run at its computing time on logarithmic axes, so the runs read
    from 3 nodes (cheapest) to 9, each labelled by its node count."""
    import ancfdrv.plots as plots
    drawn = []
    real = plots.save_figure

    def keep(fig, path, **kw):
        drawn.append((Path(path).name, fig))
        real(fig, path, **kw)
    monkeypatch.setattr(plots, "save_figure", keep)
    monkeypatch.setattr(plots.plt, "close", lambda fig=None: None)
    rows = [dict(case=f"nodes-{n}", status="ok", **{"beam.nodes": str(n)},
                 err_vs_finest=err, compute_time_s=compute, total_time_s=total)
            for n, err, compute, total in ((3, 1e-2, 0.001, 3.0), (5, 1e-3, 0.002, 0.4),
                                           (9, 1e-4, 0.004, 0.5))]
    plots.plot_sweep(rows, ["beam.nodes"], tmp_path)
    ((name, fig),) = [d for d in drawn if d[0] == "error_vs_time.png"]
    ax = fig.axes[0]
    assert ax.get_xscale() == ax.get_yscale() == "log"
    assert ax.get_xlabel() == plots.COMPUTE_LABEL
    (front,) = [line for line in ax.get_lines() if len(line.get_xdata()) == 3]
    assert list(front.get_xdata()) == [0.001, 0.002, 0.004]
    assert list(front.get_ydata()) == [1e-2, 1e-3, 1e-4]
    labels = {t.get_text(): t.xy[0] for t in ax.texts}
    assert labels == {"nodes 3": 0.001, "nodes 5": 0.002, "nodes 9": 0.004}
    assert (tmp_path / "error_vs_time.png").stat().st_size > 0
