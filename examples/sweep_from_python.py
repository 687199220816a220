"""A convergence sweep driven from Python: what accuracy costs in time.

The shipped general scene ``inputs/general/cantilever.nml`` (a cantilever with a tip force)
is run through :func:`ancfdrv.simulate` with ``--set``-style overrides, exactly as
``ancf run`` would, its results kept in memory (a parameter study needs no file per case:
the timed call writes none); each case is then saved to the HDF5 file ``ancf run`` would
have written (``Simulation.save``), outside the timing. The overrides turn it into the large-deflection
benchmark of the elastica: a slender steel beam (1 m, 5 x 5 mm), formulation
'nonlinear', under a dead tip load P = k EI / L^2 with k = 10 (the tip drops by 0.81 L),
solved by Newton in 10 load steps.

The loop runs both bending options of the beam ('continuum' and 'cubic') on meshes of
5 ... 129 nodes (5 ... 17 with --quick), timing each run (the shortest of three), and
compares the tip's transverse and axial displacements w/L, u/L with the elastica of the
inextensible Euler-Bernoulli beam (``ancfdrv.reference.analytic.elastica_tip_load``: a boundary-value
solve; Mattiasson 1981 tabulates w/L = 0.81061, u/L = 0.55500 for k = 10). The error is
max(|w - w_ref| / w_ref, |u - u_ref| / u_ref). The beam model shears and stretches a
little, the elastica does not: that leaves a floor of a few 1e-5 on the finest meshes.
No mesh of 3 nodes: there the two-element 'cubic' model's equilibrium is unstable (its
tangent has a negative out-of-plane eigenvalue, -1.05 where 5 nodes give +0.94 and every
finer mesh stays positive), and the run refuses it with exit 3 (docs/theory.md, "The
stability of a load-controlled state").

Prints the table, writes results/examples/sweep_from_python.{md,csv} and the plot
sweep_from_python.png (error against nodes and against the wall time of a run), and one
result file per case in results/examples/sweep/ (saved after the timed in-memory run).

    python examples/sweep_from_python.py [--quick] [--out DIR]
"""
from __future__ import annotations

import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np

from example_utils import arguments, write_table

import ancfdrv
from ancfdrv.reference.analytic import elastica_tip_load

SCENE = Path(__file__).resolve().parents[1] / "inputs" / "general" / "cantilever.nml"
LENGTH, SIDE, E = 1.0, 0.005, 2.1e11
LOAD_PARAMETER = 10.0  # k = P L^2 / EI


def overrides(bending: str, nodes: int, k: float = LOAD_PARAMETER) -> list[str]:
    """The scene's changes for one case (the same strings ``ancf run --set`` takes)."""
    ei = E * SIDE**4 / 12.0
    force = k * ei / LENGTH**2
    return [f"beam[arm].nodes={nodes}", f"beam[arm].end={LENGTH},0,0",
            f"beam[arm].width={SIDE}", f"beam[arm].height={SIDE}",
            "beam[arm].formulation=nonlinear", f"beam[arm].bending={bending}",
            f"load[tip force].vector=0,{-force},0", f"probe[tip].point={LENGTH},0,0",
            f"load[tip force].point={LENGTH},0,0",
            "solver.static_method=newton", "solver.load_steps=10", "solver.max_newton=40"]


@dataclass
class Case:
    bending: str
    nodes: int
    ndof: int
    w: float            # transverse tip displacement / L
    u: float            # axial tip displacement (shortening) / L
    error: float
    wall_time: float    # the whole in-memory call (ancfdrv.simulate) [s]
    solve_time: float   # the static solve as the run records it (timing static_total) [s]


def run_case(bending: str, nodes: int, out: Path, reference: tuple[float, float],
             repeats: int = 1) -> Case:
    """One case, run ``repeats`` times: the shortest time counts (the others met a busier
    machine); the last run saved to its file after the timing."""
    wall = solve = np.inf
    for _ in range(repeats):
        start = time.perf_counter()
        sim = ancfdrv.simulate(SCENE, overrides(bending, nodes), progress=False)
        wall = min(wall, time.perf_counter() - start)
        solve = min(solve, sim.timing["static_total"])
    sim.save(out / f"cantilever_{bending}_{nodes}.h5", replace=True)
    tip = sim.static_probe("tip")
    w, u = -tip[1] / LENGTH, (LENGTH - tip[0]) / LENGTH
    error = max(abs(w - reference[0]) / reference[0], abs(u - reference[1]) / reference[1])
    return Case(bending, nodes, int(sim.summary["ndof"]), w, u, error, wall, solve)


def sweep(meshes: Sequence[int], out: Path,
          repeats: int = 1) -> tuple[list[Case], tuple[float, float]]:
    """Every bending option on every mesh (after one untimed warm-up run)."""
    out.mkdir(parents=True, exist_ok=True)
    reference = elastica_tip_load(LOAD_PARAMETER)
    run_case("cubic", 5, out, reference)   # warm-up: imports, first kernel calls
    cases = [run_case(b, n, out, reference, repeats) for b in ("continuum", "cubic")
             for n in meshes]
    return cases, reference


def plot(cases: list[Case], path: Path) -> None:
    import matplotlib.pyplot as plt
    from matplotlib.ticker import NullFormatter
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.5))
    for bending, marker in (("continuum", "o"), ("cubic", "s")):
        rows = [c for c in cases if c.bending == bending]
        nodes = [c.nodes for c in rows]
        errors = [c.error for c in rows]
        ax1.loglog(nodes, errors, marker + "-", label=f"bending = '{bending}'")
        ax2.loglog([c.wall_time for c in rows], errors, marker + "-", label=f"'{bending}'")
        for c in rows:
            ax2.annotate(str(c.nodes), (c.wall_time, c.error), fontsize=7,
                         textcoords="offset points", xytext=(4, 4))
    ax1.set(xlabel="beam nodes", ylabel="relative error of the tip (w, u)",
            title=f"elastica, k = PL^2/EI = {LOAD_PARAMETER:g}")
    ax2.set(xlabel="wall time of the run [s]", ylabel="relative error of the tip (w, u)",
            title="what accuracy costs in time (labels: nodes)")
    for ax in (ax1, ax2):
        ax.grid(True, which="both", lw=0.3)
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


@dataclass
class Report:
    cases: list[Case]
    reference: tuple[float, float]
    files: list[Path]


def run(quick: bool, out: Path) -> Report:
    meshes = (5, 9, 17) if quick else (5, 9, 17, 33, 65, 129)
    cases, reference = sweep(meshes, out / "sweep", repeats=1 if quick else 3)
    rows = [[c.bending, c.nodes, c.ndof, c.w, c.u, c.error, c.wall_time, c.solve_time]
            for c in cases]
    print(write_table(out / "sweep_from_python",
                      ["bending", "nodes", "ndof", "w/L", "u/L", "relative error",
                       "wall time of the run [s]", "static solve [s]"], rows,
                      f"Cantilever elastica (k = {LOAD_PARAMETER:g}): accuracy against time",
                      f"Reference (elastica): w/L = {reference[0]:.6f}, u/L = "
                      f"{reference[1]:.6f}. Times: the shortest of {1 if quick else 3} runs "
                      "on this machine, each the whole in-memory call (ancfdrv.simulate)."))
    plot(cases, out / "sweep_from_python.png")
    return Report(cases, reference, [out / "sweep_from_python.md",
                                     out / "sweep_from_python.png"])


def main(argv: Sequence[str] | None = None) -> int:
    args = arguments(__doc__, argv)
    run(args.quick, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
