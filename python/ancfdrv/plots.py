"""Plots people would rather look at than read: a run's deflection line, and a sweep's
result-against-parameter curves and error-against-wall-time (Pareto) chart."""
from __future__ import annotations

from pathlib import Path

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def plot_result(h5_path: str | Path, png: str | Path | None = None) -> Path:
    """Static result: deflection of the neutral axis along the beam, in the rigid frame."""
    h5_path = Path(h5_path)
    png = Path(png) if png else h5_path.with_suffix(".png")
    with h5py.File(h5_path, "r") as h5:
        if "static" not in h5:
            raise ValueError(f"{h5_path}: no /static group to plot (status: "
                             f"{h5.attrs.get('status')})")
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
    nodes_key = "beam.nodes" if "beam.nodes" in keys else None
    others = [k for k in keys if k not in ("beam.nodes", "solver.dt")]
    x_key = others[0] if others else None
    panel_keys = others[1:]
    panels = sorted({tuple(r[k] for k in panel_keys) for r in ok}, key=lambda t: [float(v) if
                    _isnum(v) else v for v in t])
    if x_key:
        fig, axes = plt.subplots(1, len(panels), figsize=(5.5 * len(panels), 4), squeeze=False,
                                 constrained_layout=True)
        for ax, panel in zip(axes[0], panels):
            members = [r for r in ok if tuple(r[k] for k in panel_keys) == panel]
            curves = sorted({r.get(nodes_key, "") for r in members}, key=_num)
            for curve in curves:
                pts = sorted(((float(r[x_key]), r["tip_transverse"]) for r in members
                              if r.get(nodes_key, "") == curve))
                ax.plot([p[0] for p in pts], [1e3 * p[1] for p in pts], "o-", ms=3,
                        label=f"{curve} nodes" if nodes_key else "model")
            ref = sorted({(float(r[x_key]), r["tip_transverse_closed_form"]) for r in members
                          if "tip_transverse_closed_form" in r})
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
        for g in groups:
            sel = [r for r in pts if r.get(nodes_key, "") == g]
            ax.loglog([r["total_time_s"] for r in sel], [r[err_key] for r in sel], "o", ms=5,
                      label=f"{g} nodes" if nodes_key else None)
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


def _isnum(v) -> bool:
    try:
        float(v)
        return True
    except (TypeError, ValueError):
        return False


def _num(v):
    return float(v) if _isnum(v) else 0.0
