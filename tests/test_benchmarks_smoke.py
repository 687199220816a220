"""Smoke runs of the benchmark scripts on the smallest settings: each runs over the current
API and writes the JSON its docstring documents, with finite positive measurements and the
exact expectations that do not depend on timing (mesh sizes, convergence, the identical
histories of a version compared with itself). Nothing here asserts a time."""
from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
BENCHMARKS = ROOT / "benchmarks"


def run_script(name: str, *args: str, timeout: float = 120.0) -> None:
    done = subprocess.run([sys.executable, str(BENCHMARKS / name), *args], cwd=ROOT,
                          capture_output=True, text=True, timeout=timeout)
    assert done.returncode == 0, done.stderr[-3000:]


def positive(x) -> bool:
    return isinstance(x, (int, float)) and math.isfinite(x) and x > 0


def test_static_scaling_smoke(tmp_path):
    out = tmp_path / "static.json"
    run_script("static_scaling.py", "--nodes", "4", "--min-time", "0", "--min-repeats", "1",
               "--output", str(out))
    report = json.loads(out.read_text())
    assert report["benchmark"] == "static_scaling"
    (record,) = report["records"]
    assert record["nodes"] == 4 and record["ndof"] == 4 * 12
    assert record["nconstraints"] == 7   # the boom's supports, eqs. 30-36
    for method in ("newton", "split"):
        static = record["static"][method]
        assert static["converged"] and static["converged_at_requested_tol"]
        assert static["residual_norm"] <= 1e-10
        assert positive(static["timing"]["best_s"])
    for key in ("build_model", "stiffness_assembly"):
        assert positive(record[key]["best_s"])
    assert all(positive(v) for v in record["floor"].values())
    # MUMPS and SuperLU solve the same saddle-point system
    assert record["saddle_solution_check"]["relative_difference"] < 1e-8


def test_dynamic_scaling_smoke(tmp_path):
    out = tmp_path / "dynamic.json"
    run_script("dynamic_scaling.py", "--nodes", "4", "--min-time", "0.01", "--repeats", "1",
               "--run-nodes", "0", "--output", str(out))
    report = json.loads(out.read_text())
    (record,) = report["records"]
    assert record["nodes"] == 4 and record["ndof"] == 48 and record["elements"] == 3
    assert record["jacobian_policy"] == "constant"          # the FFR boom
    # the luffing stage starts after the 1 s smooth start (SPEC section 5)
    assert abs(record["window"][0] - 1.0) < 1e-9
    steps = record["steps"]
    assert positive(steps["step_s"]) and steps["newton_min"] >= 1
    assert positive(record["floor"]["bulk_s"]) and positive(record["floor"]["single_s"])
    assert positive(record["call"]["one_step_call_s"])
    assert record["setup"]["integrator_setup_solves"] > 0   # S^-1 E_c of the constant policy
    assert report["run_scene"] is None


def test_before_after_same_version(tmp_path):
    """A version against itself: the machinery runs both sides and finds identical
    histories and counts (the runs are deterministic)."""
    out = tmp_path / "ba.json"
    python = sys.executable
    run_script("before_after.py", "--before", python, "--before-dir", str(ROOT), "--after",
               python, "--after-dir", str(ROOT), "--quick", "--cases", "boom_static",
               "pendulum", "--dispatch-steps", "20", "--dispatch-repeats", "1",
               "--output", str(out), timeout=300.0)
    report = json.loads(out.read_text())
    static, pendulum = report["cases"]["boom_static"], report["cases"]["pendulum"]
    for case in (static, pendulum):
        for side in ("before", "after"):
            assert "error" not in case[side], case[side]
            assert positive(case[side]["solve_s"]) and positive(case[side]["run_scene_s"])
        assert case["history"]["max_abs_difference"] == 0.0
        assert positive(case["speedup"])
    assert static["history"]["kind"] == "static"
    assert static["before"]["static_iterations"] == static["after"]["static_iterations"]
    h = pendulum["history"]
    assert h["kind"] == "dynamic" and h["same_times"] and h["moving"]
    # quick: 0.2 s at the scene's dt = 5e-4
    assert pendulum["before"]["steps"] == pendulum["after"]["steps"] == 400
    assert pendulum["before"]["newton_iterations"] == pendulum["after"]["newton_iterations"]
    for side in ("before", "after"):
        d = report["dispatch"][side]
        assert d["new_api"] is True and positive(d["per_step_us"])
        assert set(d["overhead_per_call_us"]) == {"calls_of_10", "calls_of_1", "raw_calls_of_1"}
        # a run split into kernel calls gives the same state
        assert all(v == 0.0 for v in d["final_state_max_difference"].values())
    table = out.with_suffix(".md").read_text()
    assert "| boom_static |" in table and "| pendulum |" in table


def test_peer_cantilever_smoke(tmp_path):
    """benchmarks/peer_cantilever.py on 4 elements, 5 steps, one repeat: the JSON's shape,
    the unknowns of both codes (4 per node), the step counts, a memory record per code
    (fresh interpreters) and the two codes' tip histories agreeing (same physics)."""
    import pytest
    pytest.importorskip("exudyn")
    out = tmp_path / "cantilever.json"
    run_script("peer_cantilever.py", "--elements", "4", "--options", "cable", "--t-end",
               "0.005", "--sample-dt", "0.001", "--repeats", "1", "--output", str(out))
    report = json.loads(out.read_text())
    assert report["benchmark"] == "peer_cantilever" and report["exudyn"]["available"]
    (row,) = report["rows"]
    assert row["elements"] == 4 and set(row["runs"]) == {"ancfdrv/cable", "exudyn"}
    for code, run in row["runs"].items():
        assert run["ok"], run
        assert run["unknowns"] == 4 * 5 and run["steps"] == 5
        assert positive(run["per_step_ms"]) and run["newton_iterations"] >= 5
        memory = row["memory"][code]
        assert memory["ok"], memory
        marks = memory["marks_mb"]
        assert marks["start"] <= marks["after_imports"] <= marks["after_build"] \
            <= marks["after_solve"] == memory["peak_mb"]
    assert positive(row["ratios"]["ancfdrv/cable"])
    assert positive(row["memory_ratios"]["ancfdrv/cable"]["peak"])
    # the like-for-like memory run (results in memory): the same model and steps
    memory = row["memory"]["ancfdrv/cable in memory"]
    assert memory["ok"], memory
    assert memory["unknowns"] == 4 * 5 and memory["steps"] == 5
    marks = memory["marks_mb"]
    assert marks["start"] <= marks["after_imports"] <= marks["after_build"] \
        <= marks["after_solve"] == memory["peak_mb"]
    assert positive(row["memory_ratios"]["ancfdrv/cable in memory"]["peak"])
    # 5 steps of the drop: the tip has fallen g t^2 / 2 ~ 1.2e-4 m; the codes agree far closer
    same = row["comparison"]["cable_vs_exudyn"]
    assert 5e-5 < same["tip_y_range_m"] < 5e-4
    assert same["max_abs_dy_m"] < 1e-3 * same["tip_y_range_m"]
    assert out.with_suffix(".md").read_text().startswith("# Nonlinear cantilever")


def test_make_bench_lists_every_benchmark_script(monkeypatch):
    """`make bench` (benchmarks/run_all.py) runs every benchmark or says why not: each
    script of benchmarks/ (not a helper module, _*.py) has its entry."""
    import importlib.util
    spec = importlib.util.spec_from_file_location("run_all", BENCHMARKS / "run_all.py")
    run_all = importlib.util.module_from_spec(spec)
    monkeypatch.setitem(sys.modules, "run_all", run_all)  # (its dataclasses look it up)
    spec.loader.exec_module(run_all)
    scripts = {p.stem for p in BENCHMARKS.glob("*.py") if not p.stem.startswith("_")}
    assert scripts - {"run_all"} == {b.name for b in run_all.BENCHES}


def test_peer_harness_levels_smoke(tmp_path):
    """benchmarks/peer_harness.py --quick --only levels (the boom for 2 s): every grid run
    takes its own step count, the errors are measured against the converged reference, the
    level table picks a run within each level it fills; with Exudyn, its 3-element cable at
    dt 1e-2 runs at the fair settings and lands within 10 % of ancfdrv's 4-node cable's error
    at the same step (the same model), and both codes' picks are timed from the command
    line. Each run's Newton tolerance follows the one rule of both codes: after the tight
    run, the settings tried loosest first all moved the history by more than 0.004 % of its
    range but the last, which is the one used unless it did too (then the tight one).
    Without Exudyn the peer's runs are absent and its picks empty."""
    import importlib.util
    out = tmp_path / "levels.json"
    run_script("peer_harness.py", "--quick", "--only", "levels", "--repeats", "1",
               "--output", str(out))
    report = json.loads(out.read_text())
    with_exudyn = importlib.util.find_spec("exudyn") is not None
    assert report["exudyn"]["available"] is with_exudyn
    rec = report["problems"]["levels"]["masses"]["50"]
    assert rec["references"]["ancfdrv"]["ok"] and rec["sag_range_m"] > 0
    def key(run):
        c = run["config"]
        return c["code"], c["nodes"] or c["per_segment"], c["dt"]

    runs = {key(r): r for r in rec["runs"]}
    steps = {("ancfdrv", 4, 1e-3): 2000, ("ancfdrv", 4, 1e-2): 200}
    if with_exudyn:
        steps[("exudyn", 1, 1e-2)] = 200
    assert set(runs) == set(steps)
    for k, run in runs.items():
        assert run["ok"], run["message"]
        assert run["counts"]["steps"] == steps[k]
        # one rule for both codes' Newton tolerance: the tight run first, then loosest
        # first until one keeps the history within 0.004 % of its range; that one is used
        tight, *tried = run["newton_tried"]
        assert tight["change"] == 0.0 and tried
        assert all(t["change"] is None or t["change"] > 4e-5 for t in tried[:-1])
        chosen = run["config"]["newton_tol"] if k[0] == "ancfdrv" else \
            run["config"]["newton"]["label"]
        if tried[-1]["change"] is not None and tried[-1]["change"] <= 4e-5:
            assert tried[-1]["setting"] == chosen
        else:
            assert tight["setting"] == chosen
        assert positive(run["whole_s"]) and positive(run["solve_s"])
        assert run["solve_s"] <= run["whole_s"]
        assert 0 < run["error_common_percent"] < 3.0
    for entry in rec["levels"]:
        pick = entry["common"]["whole"]["ancfdrv"]
        if pick is not None:
            assert pick["error_percent"] <= entry["level_percent"]
    three_percent = rec["levels"][0]["common"]["whole"]
    assert three_percent["ancfdrv"]["label"] in {r["label"] for r in rec["runs"]}
    assert positive(three_percent["ancfdrv"]["command_s"])
    if with_exudyn:
        a = runs[("ancfdrv", 4, 1e-2)]["error_common_percent"]
        x = runs[("exudyn", 1, 1e-2)]["error_common_percent"]
        assert abs(x - a) < 0.1 * a
        assert positive(three_percent["exudyn"]["command_s"])
        assert positive(three_percent["exudyn_over_ancfdrv"])
    else:
        assert three_percent["exudyn"] is None


def test_leaf_spring_time_same_version(tmp_path, monkeypatch):
    """benchmarks/leaf_spring_time.py over 20 ms of the leaf spring, in this process but for
    one worker: that worker (a fresh process, the script's --worker protocol) reports 20
    steps of 1 ms and writes the 21-row chassis history; the script's main, its workers
    replaced by the same runs in this process, compares this build with itself (identical
    histories and counters, the iteration matrix by the envelope LU) and finds the shipped
    step's error against the 0.125 ms reference at the 6 output times 0, 4, ..., 20 ms
    positive (the steps differ) and small against the run's range."""
    monkeypatch.syspath_prepend(str(BENCHMARKS))
    import leaf_spring_time as script

    record = script.run_worker(sys.executable, tmp_path / "worker.npz", 0.02)
    assert record["steps"] == 20 and record["newton_iterations"] >= 20
    assert positive(record["process_cpu_s"]) and positive(record["integrate_cpu_s"])
    with np.load(tmp_path / "worker.npz") as h:
        assert len(h["t"]) == len(h["z"]) == 21 and abs(h["t"][-1] - 0.02) < 1e-12

    def in_process(python, history, t_end, setting=None, answers=False):
        assert python == sys.executable
        record = script.one_run(history, t_end, setting, answers)
        return dict(record, process_cpu_s=record["integrate_cpu_s"])

    monkeypatch.setattr(script, "run_worker", in_process)
    stem = tmp_path / "leaf"
    assert script.main(["--baseline", sys.executable, "--rounds", "1", "--t-end", "0.02",
                        "--accuracy", "--grid", "1e-3/1e-8", "-o", str(stem)]) == 0
    report = json.loads(stem.with_suffix(".json").read_text())
    builds = report["builds"]
    assert builds["history_max_abs_diff_m"] == 0.0 and builds["counters_equal"]
    assert builds["history_max_diff_over_range"] == {"x": 0.0, "z": 0.0}
    for side in ("baseline", "current"):
        summary = builds["summary"][side]
        assert summary["steps"] == 20 and summary["newton_iterations"] >= 20
        assert positive(summary["integrate_cpu_best_s"])
        assert positive(summary["integrate_wall_best_s"])
        assert summary["solver"].endswith("(envelope LU)")
    (row,) = report["accuracy"]["rows"]
    assert row["shipped"] and row["compared_times"] == 6
    assert 0.0 < row["z_error"] < 0.05
    assert stem.with_suffix(".md").is_file() and stem.with_suffix(".png").is_file()