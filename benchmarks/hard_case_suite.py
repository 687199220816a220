"""The hard-case suite of record (issue 39 item 5): the grid of the issue, each run
classified correct / refused / ok and wrong (benchmarks/_hard_case_grid.py) against a
converged reference of the same model (the same mesh at a quarter of the step, rho_inf 0.8).

* the flexible pendulum (inputs/hard/pendulum.nml), 9 and 17 nodes x dt 5e-4 .. 5e-3 x
  rho_inf 0.8, 0.9, 1, to t_end (10 s; --quick 1 s), the tip within 1 % of the length over
  the first second, the energy balance within 1 % of its scale over the run;
* the flexible double pendulum (inputs/hard/double_pendulum.nml, 34 nodes) at dt 1e-3 and
  2.5e-4, rho_inf 1, to 10 s (--quick 1 s), the tip within 1 % of its reach (2 m) over the
  first second, the balance as above.

* the rope's throw and drop (inputs/hard/rope_throw.nml, rope_drop.nml: 100 kg on a 9-node
  nylon rope) at dt 1e-3 and 2e-4 x rho_inf 0, 0.5, 0.8, 1, judged against the closed form
  of the payload's highest (throw) and lowest (drop: the catch) height by the rope's own law
  (_hard_case_grid.rope_throw_top, rope_drop_catch), within 2 mm, the balance as above.

* the driven knuckle crane with its hoist rope and 500 kg payload (inputs/knuckle_crane_rope.nml:
  joints, a rigid and a compliant cylinder, the jib cylinder's stroke drive, a tension-only
  rope) to 100 s (--quick 10 s) at dt 5e-3 (the scene's) and 1e-2 x rho_inf 0.8, 1: the hook
  within 1 % of its motion's range (0.40 m: 4 mm) over the whole run (the payload's swing is
  damped and not chaotic), the balance as above.

Writes benchmarks/results/hard_case_suite.json and prints the table of benchmarks/README.md.
Usage: python benchmarks/hard_case_suite.py [--quick] [--only pendulum,double,rope,crane] [--output JSON]
"""
from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from _common import json_ready, machine_info  # noqa: E402
from _hard_case_grid import Case, classify, rope_drop_catch, rope_throw_top  # noqa: E402


def grid(quick: bool, only: set[str]) -> list[Case]:
    t_end = "1.0" if quick else "10.0"
    cases = []
    if "pendulum" in only:
        cases += [Case(f"pendulum_{n}n_dt{dt:g}_rho{rho:g}", "pendulum.nml",
                       (f"beam.nodes={n}", f"solver.rho_inf={rho}", f"solver.t_end={t_end}"),
                       "tip", 0.012, dt)
                  for n in (9, 17) for dt in (5e-4, 1e-3, 2e-3, 5e-3) for rho in (0.8, 0.9, 1.0)]
    if "double" in only:
        cases += [Case(f"double_pendulum_dt{dt:g}_rho1", "double_pendulum.nml",
                       (f"solver.t_end={t_end}",), "tip", 0.02, dt)
                  for dt in (1e-3, 2.5e-4)]
    if "crane" in only:
        crane_end = "10.0" if quick else "100.0"
        cases += [Case(f"crane_rope_dt{dt:g}_rho{rho:g}", "../knuckle_crane_rope.nml",
                       (f"solver.rho_inf={rho}", f"solver.t_end={crane_end}"), "hook", 4e-3,
                       dt, horizon=float(crane_end))
                  for dt in (5e-3, 1e-2) for rho in (0.8, 1.0)]
    if "rope" in only:
        for scene, t_end, extreme in (("rope_throw", "0.5", ("max", rope_throw_top())),
                                      ("rope_drop", "1.2", ("min", rope_drop_catch()))):
            cases += [Case(f"{scene}_dt{dt:g}_rho{rho:g}", f"{scene}.nml",
                           (f"solver.rho_inf={rho}", f"solver.t_end={t_end}"), "payload",
                           2e-3, dt, closed_form=extreme)
                      for dt in (1e-3, 2e-4) for rho in (0.0, 0.5, 0.8, 1.0)]
    return cases


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--only", default="pendulum,double,rope,crane")
    parser.add_argument("--output", type=Path, default=HERE / "results" / "hard_case_suite.json")
    args = parser.parse_args()
    records = []
    references: dict = {}
    with tempfile.TemporaryDirectory() as tmp:
        for case in grid(args.quick, set(args.only.split(","))):
            start = time.perf_counter()
            record = classify(case, Path(tmp), references)
            record["wall_s"] = round(time.perf_counter() - start, 2)
            records.append(record)
            error = "-" if record["error_m"] is None else f"{record['error_m']:.2e}"
            print(f"| {record['case']} | {record['class']} | {record['exit']} | {error} | "
                  f"{'-' if record['balance'] is None else format(record['balance'], '.1e')} | "
                  f"{'-' if record['dissipated'] is None else format(record['dissipated'], '.1e')} | "
                  f"{record['corrections']} | {record['cuts']} | {record['wall_s']} |",
                  flush=True)
    out = args.output
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(json_ready({"machine": machine_info(), "quick": args.quick,
                                          "runs": records}), indent=1))
    wrong = [r["case"] for r in records if r["class"] not in ("correct", "refused")]
    print("ok and wrong or error:", wrong or "none")


if __name__ == "__main__":
    main()
