"""Plots people would rather look at than read: a run's deflection line, and a sweep's
result-against-parameter curves and error-against-wall-time (Pareto) chart."""
from __future__ import annotations

from pathlib import Path

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .sweep import static_value  # noqa: E402


STAGE_COLOURS = {"start": "#dbe9f6", "luffing": "#fdf1d6", "braking": "#f8dcdc",
                 "vibration": "#e2f2df"}


def plot_result(h5_path: str | Path, png: str | Path | None = None) -> Path:
    """A result file: the dynamic histories when there are any, else the static
    deflection line."""
    h5_path = Path(h5_path)
    with h5py.File(h5_path, "r") as h5:
        dynamic = "dynamic" in h5 and len(h5["dynamic/time"]) > 1
        plate = "nodes" in h5["model"]
    if plate:
        return plot_plate_dynamic(h5_path, png) if dynamic else plot_plate_static(h5_path, png)
    return plot_dynamic(h5_path, png) if dynamic else plot_static(h5_path, png)


def plot_plate_dynamic(h5_path: Path, png: str | Path | None = None) -> Path:
    """Plate or leaf run: displacement of each probe (x, y, z) and the energy balance
    (kinetic, strain, potential of the loads, and the total's drift)."""
    png = Path(png) if png else h5_path.with_suffix(".png")
    with h5py.File(h5_path, "r") as h5:
        dyn = h5["dynamic"]
        t = dyn["time"][()]
        probes = {name: dyn[f"deflection/{name}"][()] for name in dyn["deflection"]}
        energy = {k: dyn[f"energy/{k}"][()] for k in dyn["energy"]}
        title, status = h5.attrs["title"], h5.attrs["status"]
        nel = h5["model"].attrs["nelements"]
    fig, axes = plt.subplots(len(probes) + 1, 1, figsize=(9, 2.6 * (len(probes) + 1)),
                             sharex=True, constrained_layout=True)
    for ax, (name, d) in zip(axes, probes.items()):
        for k, label in enumerate("xyz"):
            ax.plot(t, 1e3 * d[:, k], lw=1.0, label=f"u_{label}")
        ax.set_ylabel(f"{name} displacement (mm)")
        ax.legend(fontsize=8, ncol=3)
    axes[0].set_title(f"{title}: {nel} elements ({status})", fontsize=9)
    ax = axes[-1]
    for key in ("kinetic", "strain", "gravity"):
        ax.plot(t, energy[key], lw=1.0, label=key if key != "gravity" else "load potential")
    drift = energy["total"] - energy["total"][0]
    ax.plot(t, drift, "k--", lw=1.0, label="E - E(0)")
    scale = max(np.abs(energy["kinetic"]).max(), np.abs(energy["strain"]).max(), 1e-300)
    ax.set_title(f"max |E - E(0)| = {np.abs(drift).max() / scale:.2e} of the largest kinetic "
                 "or strain energy", fontsize=9)
    ax.set_ylabel("energy (J)")
    ax.set_xlabel("time (s)")
    ax.legend(fontsize=8, ncol=4)
    fig.savefig(png, dpi=120)
    plt.close(fig)
    return png


def plot_plate_static(h5_path: Path, png: str | Path | None = None) -> Path:
    """Plate or leaf equilibrium: the out-of-plane displacement over the initial mid-surface."""
    png = Path(png) if png else h5_path.with_suffix(".png")
    with h5py.File(h5_path, "r") as h5:
        _require_static(h5, h5_path)
        nodes = h5["model/nodes"][()]
        elements = h5["model/elements"][()]
        q = h5["static/q"][()].reshape(len(nodes), -1)[:, :3]
        title = h5.attrs["title"]
    w = q[:, 2] - nodes[:, 2]
    triangles = np.concatenate([elements[:, [0, 1, 2]], elements[:, [0, 2, 3]]])
    fig, ax = plt.subplots(figsize=(7, 4.5), constrained_layout=True)
    span = max(np.ptp(w), 1e-300)
    levels = 1e3 * np.linspace(w.min() - 1e-6 * span, w.max() + 1e-6 * span, 21)
    art = ax.tricontourf(nodes[:, 0], nodes[:, 1], triangles, 1e3 * w, levels=levels,
                         cmap="viridis")
    ax.plot(nodes[:, 0], nodes[:, 1], "k.", ms=2)
    fig.colorbar(art, ax=ax, label="displacement along r3 (mm)")
    ax.set_aspect("equal")
    ax.set_xlabel("r1 (m)")
    ax.set_ylabel("r2 (m)")
    ax.set_title(f"{title}\nextreme displacement {1e3 * w[np.argmax(np.abs(w))]:.4g} mm",
                 fontsize=9)
    fig.savefig(png, dpi=120)
    plt.close(fig)
    return png


def plot_dynamic(h5_path: Path, png: str | Path | None = None) -> Path:
    """Tip deflection in the rigid frame (stages shaded) and the energy balance."""
    png = Path(png) if png else h5_path.with_suffix(".png")
    with h5py.File(h5_path, "r") as h5:
        dyn = h5["dynamic"]
        t = dyn["time"][()]
        sag = dyn["deflection/tip"][:, 1]
        energy = {k: dyn[f"energy/{k}"][()] for k in dyn["energy"]}
        stages = dict(dyn["stages"].attrs) if "stages" in dyn else {}
        title = h5.attrs["title"]
        nodes = h5["model"].attrs["nnodes"]
        status = h5.attrs["status"]
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(9, 6.5), sharex=True, constrained_layout=True)
    for stage, colour in STAGE_COLOURS.items():
        if f"{stage}_t0" in stages:
            for ax in (ax1, ax2):
                ax.axvspan(stages[f"{stage}_t0"], stages[f"{stage}_t1"], color=colour, lw=0)
            ax1.text(0.5 * (stages[f"{stage}_t0"] + stages[f"{stage}_t1"]), 1.0, stage,
                     transform=ax1.get_xaxis_transform(), ha="center", va="bottom", fontsize=8)
    ax1.plot(t, 1e3 * sag, lw=1.0)
    ax1.set_ylabel("tip deflection, transverse (mm)")
    ax1.set_title(f"{title}: {nodes} nodes ({status})\n", fontsize=9)
    scale = max(np.abs(energy["drive_work"]).max(), np.abs(energy["kinetic"]).max(), 1e-300)
    ax2.plot(t, energy["total"] - energy["total"][0], label="E - E(0)")
    ax2.plot(t, energy["drive_work"], "--", label="drive work")
    ax2.set_ylabel("energy (J)")
    twin = ax2.twinx()
    twin.plot(t, energy["balance"] / scale, color="C3", lw=0.8, label="balance / scale")
    twin.set_ylabel("balance / max(|W|, kinetic)", color="C3")
    ax2.set_xlabel("time (s)")
    ax2.legend(loc="upper left", fontsize=8)
    fig.savefig(png, dpi=120)
    plt.close(fig)
    return png


def plot_static(h5_path: Path, png: str | Path | None = None) -> Path:
    """Static result: deflection of the neutral axis along the beam, in the rigid frame."""
    png = Path(png) if png else h5_path.with_suffix(".png")
    with h5py.File(h5_path, "r") as h5:
        _require_static(h5, h5_path)
        s = h5["model/node_s"][()]
        e0 = h5["model/e0"][()].reshape(-1, 12)
        q = h5["static/q"][()].reshape(-1, 12)
        title = h5.attrs["title"]
        tip = h5["static/deflection/tip"][()]
        axis = e0[1, 0:3] - e0[0, 0:3]
        axis /= np.linalg.norm(axis)
        normal = np.cross([0.0, 0.0, 1.0], axis)
        method = h5["static"].attrs["method"]
    disp = q[:, 0:3] - e0[:, 0:3]
    fig, ax = plt.subplots(figsize=(7, 3.5), constrained_layout=True)
    ax.plot(s, 1e3 * disp @ normal, "o-", ms=3, label="transverse")
    ax.plot(s, 1e3 * disp @ axis, "s--", ms=3, label="axial")
    ax.axhline(0.0, color="0.6", lw=0.8)
    ax.set_xlabel("arc length s (m)")
    ax.set_ylabel("displacement (mm)")
    ax.set_title(f"{title}\n{len(s)} nodes, {method}: tip sag {1e3 * tip[1]:.3f} mm", fontsize=9)
    ax.legend()
    fig.savefig(png, dpi=120)
    plt.close(fig)
    return png


def plot_sweep(rows: list[dict], keys: list[str], outdir: Path) -> list[Path]:
    """Tip sag against the first non-resolution key (one curve per node count, one panel
    per value of the remaining keys), and error against wall time."""
    ok = [r for r in rows if r["status"] == "ok"]
    if not ok:
        return []
    out = []
    if any(r.get("dynamic") for r in ok):
        out += plot_histories(ok, keys, outdir)
    from .sweep import is_resolution
    mesh_keys = [k for k in keys if is_resolution(k) and k != "solver.dt"]
    nodes_key = mesh_keys[0] if mesh_keys else None
    others = [k for k in keys if not is_resolution(k)]
    numeric = [k for k in others if all(_isnum(r[k]) for r in ok)]
    x_key = numeric[0] if numeric else None  # the x axis; string keys become panels
    panel_keys = [k for k in others if k != x_key]
    panels = sorted({tuple(r[k] for k in panel_keys) for r in ok}, key=lambda t: [float(v) if
                    _isnum(v) else v for v in t])
    if x_key and not any(r.get("dynamic") for r in ok):  # static sweeps: Figs. 4-5
        fig, axes = plt.subplots(1, len(panels), figsize=(5.5 * len(panels), 4), squeeze=False,
                                 constrained_layout=True)
        for ax, panel in zip(axes[0], panels):
            members = [r for r in ok if tuple(r[k] for k in panel_keys) == panel]
            curves = sorted({r.get(nodes_key, "") for r in members}, key=_num)
            for curve in curves:
                pts = sorted(((float(r[x_key]), static_value(r)) for r in members
                              if r.get(nodes_key, "") == curve))
                ax.plot([p[0] for p in pts], [1e3 * p[1] for p in pts], "o-", ms=3,
                        label=_mesh_label(nodes_key, curve))
            ref = sorted({(float(r[x_key]), r.get("tip_transverse_closed_form",
                                                  r.get("response_closed_form")))
                          for r in members if "tip_transverse_closed_form" in r
                          or "response_closed_form" in r})
            if ref:
                ax.plot([p[0] for p in ref], [1e3 * p[1] for p in ref], "k--", lw=1.2,
                        label="closed form")
            ax.set_xlabel(x_key)
            ax.set_ylabel("tip sag (mm)")
            ax.set_title(", ".join(f"{k} = {v}" for k, v in zip(panel_keys, panel)) or "")
            ax.grid(alpha=0.3)
            ax.legend(fontsize=8)
        path = outdir / "tip_deflection.png"
        fig.savefig(path, dpi=120)
        plt.close(fig)
        out.append(path)
    err_key = "err_vs_closed_form" if any("err_vs_closed_form" in r for r in ok) else "err_vs_finest"
    pts = [r for r in ok if r.get(err_key, 0) > 0]
    if pts:
        fig, ax = plt.subplots(figsize=(6, 4.2), constrained_layout=True)
        groups = sorted({r.get(nodes_key, "") for r in pts}, key=_num)
        markers = {dt: m for dt, m in zip(sorted({r.get("solver.dt", "") for r in pts},
                                                 key=_num), "osD^v<>p*")}
        for g in groups:
            for dt, marker in markers.items():
                sel = [r for r in pts if r.get(nodes_key, "") == g and r.get("solver.dt", "") == dt]
                if not sel:
                    continue
                label = (_mesh_label(nodes_key, g) if nodes_key else "") + (
                    f", dt {dt}" if len(markers) > 1 else "")
                ax.loglog([r["total_time_s"] for r in sel], [r[err_key] for r in sel], marker,
                          ms=5, color=f"C{groups.index(g) % 10}", label=label or None)
        ax.set_xlabel("wall time per case (s)")
        ax.set_ylabel(err_key.replace("_", " "))
        ax.set_title("what accuracy costs in time")
        ax.grid(alpha=0.3, which="both")
        if nodes_key:
            ax.legend(fontsize=8)
        path = outdir / "error_vs_time.png"
        fig.savefig(path, dpi=120)
        plt.close(fig)
        out.append(path)
    return out


def plot_histories(rows: list[dict], keys: list[str], outdir: Path) -> list[Path]:
    """Tip sag histories of every node count (at the finest dt), the whole run and one
    panel per luffing stage (the paper's Figs. 6-15); one figure per value of the other
    varied keys."""
    import h5py as _h5
    from .sweep import is_resolution
    others = [k for k in keys if not is_resolution(k)]
    mesh_keys = [k for k in keys if is_resolution(k) and k != "solver.dt"]
    finest_dt = min((float(r["solver.dt"]) for r in rows if "solver.dt" in r), default=None)
    chosen = [r for r in rows if finest_dt is None or float(r["solver.dt"]) == finest_dt]
    out = []
    for panel in sorted({tuple(r[k] for k in others) for r in chosen}):
        members = sorted([r for r in chosen if tuple(r[k] for k in others) == panel],
                         key=lambda r: _num(r.get(mesh_keys[0], 0)) if mesh_keys else 0)
        stages = [s for s in STAGE_COLOURS if f"stage_{s}_t0" in members[0]]
        fig = plt.figure(figsize=(11, 7.5), constrained_layout=True)
        grid = fig.add_gridspec(2, max(len(stages), 1))
        whole = fig.add_subplot(grid[0, :])
        zooms = [fig.add_subplot(grid[1, i]) for i in range(len(stages))]
        for row in members:
            with _h5.File(row["file"], "r") as h5:
                t = h5["dynamic/time"][()]
                probe = h5.attrs.get("response_probe", "tip")
                component = int(h5.attrs.get("response_component", 1))
                sag = 1e3 * h5[f"dynamic/deflection/{probe}"][:, component]
            label = _mesh_label(mesh_keys[0], row[mesh_keys[0]]) if mesh_keys else "model"
            whole.plot(t, sag, lw=0.9, label=label)
            for ax, stage in zip(zooms, stages):
                mask = (t >= row[f"stage_{stage}_t0"]) & (t <= row[f"stage_{stage}_t1"])
                ax.plot(t[mask], sag[mask], lw=0.9)
        for stage in stages:
            whole.axvspan(members[0][f"stage_{stage}_t0"], members[0][f"stage_{stage}_t1"],
                          color=STAGE_COLOURS[stage], lw=0)
        for ax, stage in zip(zooms, stages):
            ax.set_title(stage, fontsize=9)
            ax.set_facecolor(STAGE_COLOURS[stage])
            ax.set_xlabel("time (s)")
        whole.set_ylabel("tip sag (mm)")
        whole.set_title(", ".join(f"{k} = {v}" for k, v in zip(others, panel))
                        + (f" (dt = {finest_dt:g} s)" if finest_dt else ""), fontsize=9)
        whole.legend(fontsize=8, ncol=len(members))
        name = "histories" + "".join(f"_{k.split('.')[1]}-{v}" for k, v in zip(others, panel))
        path = outdir / f"{name}.png"
        fig.savefig(path, dpi=110)
        plt.close(fig)
        out.append(path)
    return out


def _require_static(h5: h5py.File, h5_path: Path) -> None:
    if "static" not in h5:
        raise ValueError(f"{h5_path}: no /static group to plot (status: "
                         f"{h5.attrs.get('status')})")


def _mesh_label(key: str | None, value) -> str:
    """'28 nodes' for beams, 'nx+ny = 8' for plates."""
    if key is None:
        return "model"
    if key == "beam.nodes":
        return f"{value} nodes"
    return "+".join(part.split(".")[1] for part in key.split("+")) + f" = {value}"


def _isnum(v) -> bool:
    try:
        float(v)
        return True
    except (TypeError, ValueError):
        return False


def _num(v):
    return float(v) if _isnum(v) else 0.0
