"""Plots people would rather look at than read: a run's deflection line, the leaf spring's
histories and load-cycle loop (several runs overlaid), and a sweep's
result-against-parameter curves and error-against-wall-time (Pareto) chart."""
from __future__ import annotations

import textwrap

from pathlib import Path

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .records import record
from .codes import mesh_parts  # noqa: E402
from .io.safe_write import save_figure  # noqa: E402
from .sweep_keys import is_resolution, row_response, static_value  # noqa: E402


STAGE_COLOURS = {"start": "#dbe9f6", "luffing": "#fdf1d6", "braking": "#f8dcdc",
                 "vibration": "#e2f2df"}


def plot_result(h5_path: str | Path, png: str | Path | None = None) -> Path:
    """A result file: the dynamic histories when there are any, else the static
    deflection line. The template plots (leaf spring, plate, the beam's tip and
    deflection line) are drawn when the file holds what they read; any other result
    (any probe names, any number of bodies) gets the general plots
    (:func:`plot_general_dynamic`, :func:`plot_general_static`). The plots of
    :data:`EXTRA_PLOTS` whose group the file holds are written beside it."""
    h5_path = Path(h5_path)
    with h5py.File(h5_path, "r") as h5:
        eigen = [g for g in ("modal", "buckling") if g in h5 and "mesh_shapes" in h5[g]]
    if eigen:
        return plot_modes(h5_path, png, eigen[0])
    with h5py.File(h5_path, "r") as h5:
        dynamic = "dynamic" in h5 and "time" in h5["dynamic"] and len(h5["dynamic/time"]) > 1
        plate = "nodes" in h5["model"]
        kind = _text(h5.attrs.get("kind", ""))
        single_beam = "node_s" in h5["model"]
        group = h5["dynamic"] if dynamic else h5.get("static")
        has_tip = group is not None and "deflection" in group and "tip" in group["deflection"]
        has_energy = dynamic and all(f"energy/{k}" in h5["dynamic"] for k in
                                     ("kinetic", "strain", "gravity", "total",
                                      "drive_work", "balance"))
        extras = [(name, function) for name, function in EXTRA_PLOTS.items()
                  if name in h5]
    if kind == "spring" and dynamic:
        return plot_spring([h5_path], png)
    if plate and kind in ("plate", "leaf", "general", ""):
        try:
            return plot_plate_dynamic(h5_path, png) if dynamic else \
                plot_plate_static(h5_path, png)
        except (KeyError, ValueError, IndexError):
            pass  # a plate among other bodies: the general plot below
    if dynamic:
        out = plot_dynamic(h5_path, png) if has_tip and has_energy and kind != "general" \
            else plot_general_dynamic(h5_path, png)
    elif single_beam and has_tip and kind != "general":
        try:
            out = plot_static(h5_path, png)
        except (KeyError, ValueError, IndexError):  # not the template's layout
            out = plot_general_static(h5_path, png)
    else:
        out = plot_general_static(h5_path, png)
    for name, function in extras:  # e.g. modes, buckling, reactions (other modules)
        function(h5_path, out.with_name(f"{out.stem}_{name}.png"))
    with h5py.File(h5_path, "r") as h5:
        has_path = "static/path" in h5
    if has_path:
        plot_path(h5_path, out.with_name(f"{out.stem}_path.png"))
    return out


def plot_path(h5_path: str | Path, png: str | Path | None = None) -> Path:
    """The arc-length path of /static/path: the load factor against the control probe's
    displacement component that moves most, the limit points marked (triangles) and the
    bifurcation points (squares), the points colored by their stability (negative
    eigenvalues of the tangent: 0 stable)."""
    h5_path = Path(h5_path)
    png = Path(png) if png else h5_path.with_name(f"{h5_path.stem}_path.png")
    with h5py.File(h5_path, "r") as h5:
        group = h5["static/path"]
        factor = group["load_factor"][()]
        disp = group["displacement"][()].reshape(len(factor), -1)
        count = group["negative_eigenvalues"][()]
        attrs = {k: group.attrs[k] for k in ("probe", "limit_points", "bifurcation_points",
                                              "limit_load_factors")}
        title = _text(h5.attrs.get("title", h5_path.stem))
    k = int(np.argmax(np.ptp(disp, axis=0)))
    x = 1e3 * disp[:, k]
    fig, ax = plt.subplots(figsize=(6.4, 4.4), constrained_layout=True)
    ax.plot(x, factor, color="0.5", lw=1.0)
    stable = count == 0
    ax.plot(x[stable], factor[stable], "o", ms=3, color="tab:blue", label="stable")
    ax.plot(x[~stable], factor[~stable], "o", ms=3, color="tab:red",
            label="unstable (negative eigenvalues)")
    limits = np.asarray(attrs["limit_points"], dtype=int)
    for i, value in zip(limits, np.asarray(attrs["limit_load_factors"])):
        ax.plot(x[i], factor[i], "^", ms=8, color="k")
        ax.annotate(f"limit {value:.4g}", (x[i], factor[i]), textcoords="offset points",
                    xytext=(6, 6), fontsize=8)
    for i in np.asarray(attrs["bifurcation_points"], dtype=int):
        ax.plot(x[i], factor[i], "s", ms=7, mfc="none", color="tab:green")
    ax.axhline(0.0, color="0.8", lw=0.8)
    ax.set_xlabel(f"u_{'xyz'[k]} of probe {_text(attrs['probe'])} (mm)")
    ax.set_ylabel("load factor")
    ax.set_title(f"{title}: static path (arc length)", fontsize=9)
    ax.legend(fontsize=8)
    save_figure(fig, png, dpi=110)
    plt.close(fig)
    return png


#: plots of optional result groups: {root group name: function(h5_path, png) -> Path};
#: :func:`plot_result` calls each whose group the file holds (modules that add a group
#: register their plot here)
EXTRA_PLOTS: dict = {}


def _probe_series(group: h5py.Group) -> dict[str, np.ndarray]:
    """The deflection of each probe of a /static or /dynamic group (file order): relative
    to its beam's supports (deflection_support/<name>, general scenes) where the file has
    it, else deflection/<name>."""
    if "deflection" not in group:
        return {}
    support = group.get("deflection_support", {})
    return {name: (support[name] if name in support else group[f"deflection/{name}"])[()]
            for name in group["deflection"]}


def _deflection_label(group: h5py.Group) -> str:
    """What the plotted deflections are: 'relative to the supports' rigid motion' for the
    probes on beams of general scenes, else what the file says (attribute 'reference' of
    the deflection group) or the SPEC section 4 default."""
    if "deflection_support" in group and len(group["deflection_support"]):
        names = list(group["deflection_support"])
        others = [n for n in group.get("deflection", {}) if n not in names]
        text = "relative to the rigid motion of the beam's supports (x chord, y height)"
        return text + (f"; {', '.join(others)}: displacement from t = 0" if others else "")
    if "deflection" in group:
        text = _text(group["deflection"].attrs.get("reference", ""))
        if text:
            return text
    return "displacement from the rigid configuration"


#: at most this many probes get a panel of their own in the general dynamic plot
MAX_PROBE_PANELS = 6


#: a probe or a component whose largest displacement is below this fraction of the model's
#: size (round-off) does not move: not drawn (a probe so is named in the footnote); a
#: reaction whose force changes by less than this fraction of the largest change neither
STILL = 1e-9
#: the reactions drawn by the default dynamic plot: those whose force changes most
MAX_REACTION_CURVES = 4


def _cable_swing(h5: h5py.File) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Each cable's (rope's) swing over the mesh frames: (time, angle in degrees of its
    chord, first to last point, from the chord's direction at t = 0)."""
    if "dynamic/mesh_nodes" not in h5 or "model/mesh" not in h5:
        return {}
    out = {}
    nodes = h5["dynamic/mesh_nodes"]
    times = h5["dynamic/time"][()][h5["dynamic/mesh_rows"][()]]
    for name, (kind, points) in mesh_parts(_text(h5["model/mesh"].attrs.get("bodies",
                                                                         ""))).items():
        if kind != "cable":
            continue
        chord = nodes[:, points[-1], :] - nodes[:, points[0], :]
        chord /= np.maximum(np.linalg.norm(chord, axis=1, keepdims=True), 1e-300)
        cosine = np.clip(chord @ chord[0], -1.0, 1.0)
        out[name] = (times[:len(chord)], np.degrees(np.arccos(cosine)))
    return out


def _rope_tension(dyn: h5py.Group) -> dict[str, np.ndarray]:
    """Each cable's (rope's) largest axial force along it per row (kN), as the run wrote it
    (/dynamic/tension, the cable kind's law)."""
    if "tension" not in dyn:
        return {}
    return {name: group["max"][()] / 1e3 for name, group in dyn["tension"].items()
            if "max" in group}


def _changing_reactions(dyn: h5py.Group) -> dict[str, np.ndarray]:
    """The reactions whose force magnitude (kN) changes most over the run."""
    if "reactions" not in dyn:
        return {}
    found = {name: np.linalg.norm(group["force"][()], axis=1) / 1e3
             for name, group in dyn["reactions"].items() if "force" in group}
    ranges = {name: float(np.ptp(v)) if len(v) else 0.0 for name, v in found.items()}
    largest = max(ranges.values(), default=0.0)
    ranked = sorted((n for n in found if ranges[n] > STILL * largest and largest > 0),
                    key=lambda n: -ranges[n])
    return {n: found[n] for n in ranked[:MAX_REACTION_CURVES]}


def plot_general_dynamic(h5_path: Path, png: str | Path | None = None) -> Path:
    """Any dynamic result, the quantities that move: each probe's deflection components
    (in its frame, the basis named once in the title; probes and components that do not
    move are left out and named below), each rope's swing angle and tension, the reactions
    whose force changes most, and the energies the file holds."""
    h5_path = Path(h5_path)
    png = Path(png) if png else h5_path.with_suffix(".png")
    with h5py.File(h5_path, "r") as h5:
        dyn = h5["dynamic"]
        t = dyn["time"][()]
        probes = _probe_series(dyn)
        energy = {k: dyn[f"energy/{k}"][()] for k in dyn["energy"]} if "energy" in dyn else {}
        title = _text(h5.attrs.get("title", h5_path.stem))
        status = _text(h5.attrs.get("status", ""))
        label = _deflection_label(dyn)
        beam_frame = set(dyn.get("deflection_support", {}))
        swing = _cable_swing(h5)
        tension = _rope_tension(dyn)
        reactions = _changing_reactions(dyn)
        size = float(h5["model"].attrs.get("length_scale", 1.0)) if "model" in h5 else 1.0
    peaks = {n: float(np.abs(d).max(initial=0.0)) for n, d in probes.items()}
    still = [n for n in probes if peaks[n] <= STILL * size]
    moving = sorted((n for n in probes if n not in still), key=lambda n: -peaks[n])
    left_out = [n for n in moving[MAX_PROBE_PANELS:]]
    probes = {n: probes[n] for n in moving[:MAX_PROBE_PANELS]}
    panels = len(probes) + (1 if swing else 0) + (1 if tension else 0) + \
        (1 if reactions else 0) + (1 if energy else 0)
    fig, axes = plt.subplots(max(panels, 1), 1, figsize=(9, 2.2 * max(panels, 1) + 0.9),
                             sharex=True, constrained_layout=True, squeeze=False)
    axes = list(axes[:, 0])
    for ax, (name, d) in zip(axes, probes.items()):
        for k, component in enumerate(_components(name in beam_frame)):
            if np.abs(d[:, k]).max(initial=0.0) > STILL * size:
                ax.plot(t, 1e3 * d[:, k], lw=1.0, label=component)
        ax.set_ylabel(f"{name} (mm)")
        ax.legend(fontsize=8, ncol=3, loc="upper left")
    axes = axes[len(probes):]
    if swing:
        ax = axes.pop(0)
        for name, (times, angle) in swing.items():
            ax.plot(times, angle, lw=1.0, label=name)
        ax.set_ylabel("rope swing (deg)")
        ax.legend(fontsize=8, ncol=4, loc="upper left", title="chord from its direction at t = 0",
                  title_fontsize=7)
    if tension:
        ax = axes.pop(0)
        for name, force in tension.items():
            ax.plot(t, force, lw=1.0, label=name)
        ax.set_ylabel("rope tension (kN)")
        ax.legend(fontsize=8, ncol=4, loc="upper left", title="largest along the rope",
                  title_fontsize=7)
    if reactions:
        ax = axes.pop(0)
        for name, force in reactions.items():
            ax.plot(t, force, lw=1.0, label=name)
        ax.set_ylabel("reaction |F| (kN)")
        ax.legend(fontsize=8, ncol=4, loc="upper left")
    if energy:
        ax = axes.pop(0)
        for key in ("kinetic", "strain", "gravity"):
            if key in energy:
                ax.plot(t, energy[key], lw=1.0, label=key)
        if "total" in energy and len(energy["total"]):
            ax.plot(t, energy["total"] - energy["total"][0], "k--", lw=1.0, label="E - E(0)")
        if "drive_work" in energy:
            ax.plot(t, energy["drive_work"], ":", lw=1.0, label="drive work")
        ax.set_ylabel("energy (J)")
        ax.legend(fontsize=8, ncol=5, loc="upper left")
    first, last = fig.axes[0], fig.axes[-1]
    if not panels:
        first.text(0.5, 0.5, "no probes and no energies in this file", ha="center",
                   transform=first.transAxes)
    last.set_xlabel("time (s)")
    first.set_title(f"{title} ({status})\n" + textwrap.fill(f"probe deflection: {label}", 110),
                    fontsize=9)
    notes = ([f"not moving (not drawn): {', '.join(still)}"] if still else []) + \
        ([f"not drawn (more than {MAX_PROBE_PANELS} probes): {', '.join(left_out)}"]
         if left_out else [])
    if notes:
        fig.text(0.01, 0.002, "; ".join(notes), fontsize=7, color="0.4", va="bottom")
    save_figure(fig, png, dpi=110)
    plt.close(fig)
    return png


def _components(support: bool) -> tuple[str, str, str]:
    """Legend of a probe's three components: along the support frame's axes, or x, y, z."""
    return ("axial (x)", "transverse (y)", "lateral (z)") if support else ("x", "y", "z")


def plot_general_static(h5_path: Path, png: str | Path | None = None) -> Path:
    """Any static result: the deformed structure over a grey ghost of the undeformed one
    (scaled, the factor in the title) when the file has the mesh, and every probe's
    deflection components (mm) as grouped bars."""
    h5_path = Path(h5_path)
    png = Path(png) if png else h5_path.with_suffix(".png")
    with h5py.File(h5_path, "r") as h5:
        _require_static(h5, h5_path)
        static = h5["static"]
        probes = _probe_series(static)
        title = _text(h5.attrs.get("title", h5_path.stem))
        method = _text(static.attrs.get("method", ""))
        label = _deflection_label(static)
        shape = None
        if "mesh_nodes" in static and "model/mesh" in h5:
            ghost = h5["model/mesh/points"][()]
            shape = (_mesh_segments(h5), ghost, static["mesh_nodes"][()] - ghost)
    names = list(probes)
    width = max(6.0, 1.2 * len(names) + 3)
    if shape is None:
        fig, ax = plt.subplots(figsize=(width, 3.8), constrained_layout=True)
    else:
        fig, (ax_shape, ax) = plt.subplots(1, 2, figsize=(width + 5.0, 4.2),
                                           constrained_layout=True,
                                           gridspec_kw={"width_ratios": [1.2, 1.0]})
        segments, ghost, displacement = shape
        scale = shape_scale(ghost, displacement)
        _draw_shape(ax_shape, segments, ghost, displacement, scale)
        peak = 1e3 * float(np.linalg.norm(displacement, axis=1).max(initial=0.0))
        ax_shape.set_title("deformed (blue) over undeformed (grey), displacements "
                           + ("at true scale" if scale == 1.0 else f"x {scale:.3g}")
                           + f"\nlargest displacement {peak:.4g} mm", fontsize=9)
    if names:
        d = 1e3 * np.array([probes[n] for n in names]).reshape(len(names), -1)
        x = np.arange(len(names))
        for k, component in enumerate("xyz"):
            ax.bar(x + (k - 1) * 0.27, d[:, k], width=0.27, label=f"u_{component}")
        ax.set_xticks(x, names, rotation=30 if len(names) > 4 else 0)
        ax.axhline(0.0, color="0.6", lw=0.8)
        ax.legend(fontsize=8)
    else:
        ax.text(0.5, 0.5, "no probes in this file", ha="center", transform=ax.transAxes)
    ax.set_ylabel("deflection (mm)")
    ax.set_title(textwrap.fill(f"probe deflection: {label}", 70), fontsize=8)
    fig.suptitle(f"{title} ({method})", fontsize=10)
    save_figure(fig, png, dpi=110)
    plt.close(fig)
    return png


def plot_results(h5_paths: list[str | Path], png: str | Path | None = None) -> Path:
    """One file: :func:`plot_result`. Several files: leaf spring runs (root attribute kind
    'spring') overlaid in one figure (:func:`plot_spring`); other kinds plot one file at a
    time."""
    paths = [Path(p) for p in h5_paths]
    if not paths:
        raise ValueError("no result file to plot")
    if len(paths) == 1:
        return plot_result(paths[0], png)
    kinds = {}
    for path in paths:
        with h5py.File(path, "r") as h5:
            kinds[path] = _text(h5.attrs.get("kind", ""))
    others = [f"{p.name} ({k or 'unknown'})" for p, k in kinds.items() if k != "spring"]
    if others:
        raise ValueError("several result files are plotted together only for leaf spring runs "
                         f"(kind 'spring'); not: {', '.join(others)}")
    return plot_spring(paths, png)


@record
class SpringRun:
    """What the leaf spring plots read from one result file."""

    path: Path
    title: str
    status: str
    effects: tuple[str, ...]
    values: dict[str, dict]  # the scene's groups with the file's overrides applied
    time: np.ndarray
    chassis: np.ndarray        # vertical displacement of the chassis reference point (m)
    chassis_z: np.ndarray      # its vertical position (m)
    energy: dict[str, np.ndarray]
    contact: dict[str, np.ndarray]  # CONTACT_FIELDS -> (nt, npoints); empty without contact
    points: list[str]

    @property
    def prestress(self) -> bool:
        return bool(self.values.get("leaf", {}).get("prestress", False))

    @property
    def label(self) -> str:
        leaf = self.values.get("leaf", {})
        if self.prestress:
            return f"prestress on (free R {leaf.get('free_radius', float('nan')):g} m)"
        return "prestress off"

    @property
    def cycle(self) -> bool:
        return "load_cycle" in self.effects

    def cycle_force(self) -> np.ndarray:
        """Downward force on the chassis, F(t) = F_c (1 - cos(2 pi t / T)) / 2 for
        0 < t < T, else 0 (drive kind 3 of fortran/src/drives.f90): the file does not record
        it, so F_c and T come from the scene's spring.cycle_force and spring.cycle_period."""
        spring = self.values["spring"]
        amplitude, period = float(spring["cycle_force"]), float(spring["cycle_period"])
        t = self.time
        inside = (t > 0.0) & (t < period)
        return np.where(inside, 0.5 * amplitude * (1.0 - np.cos(2.0 * np.pi * t / period)), 0.0)


def scene_values(h5: h5py.File) -> dict[str, dict]:
    """The scene a result file was run with (root attributes 'scene' and 'overrides'),
    validated with the schema's defaults filled in."""
    import tempfile

    from .io.scene import load_scene
    text = _text(h5.attrs.get("scene", ""))
    overrides = [o for o in _text(h5.attrs.get("overrides", "")).splitlines() if o.strip()]
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "scene.nml"
        path.write_text(text)
        return load_scene(path, overrides).values


def read_spring(h5_path: str | Path) -> SpringRun:
    """The histories of a leaf spring result file (at least two output rows)."""
    h5_path = Path(h5_path)
    with h5py.File(h5_path, "r") as h5:
        if _text(h5.attrs.get("kind", "")) != "spring":
            raise ValueError(f"{h5_path}: not a leaf spring result (kind "
                             f"{_text(h5.attrs.get('kind', ''))!r})")
        if "dynamic" not in h5 or len(h5["dynamic/time"]) < 2:
            raise ValueError(f"{h5_path}: no dynamic steps to plot (status: "
                             f"{_text(h5.attrs.get('status', ''))})")
        dyn = h5["dynamic"]
        contact, points = {}, []
        if "contact" in dyn:
            contact = {k: dyn[f"contact/{k}"][()] for k in dyn["contact"]}
            points = _text(dyn["contact"].attrs.get("points", "")).splitlines()
        probe = _text(h5.attrs.get("response_probe", "chassis"))
        return SpringRun(
            path=h5_path, title=_text(h5.attrs["title"]), status=_text(h5.attrs["status"]),
            effects=tuple(e for e in _text(h5.attrs.get("effects", "")).split(",") if e),
            values=scene_values(h5), time=dyn["time"][()],
            chassis=dyn[f"deflection/{probe}"][:, 2], chassis_z=dyn[f"probes/{probe}"][:, 2],
            energy={k: dyn[f"energy/{k}"][()] for k in dyn["energy"]}, contact=contact,
            points=points)


def load_cycle_summary(run: SpringRun, threshold: float = 0.03) -> dict[str, float | np.ndarray]:
    """Force against downward chassis deflection over a 'load_cycle' run and its energies:

    * ``area``: the loop's enclosed area, the trapezoid rule of F d(delta) around the closed
      loop (the last point joined to the first), delta = -(vertical displacement); it is the
      work of the applied force, positive when the spring dissipates;
    * ``friction_work``, ``damping_work`` (contact damping), ``material_damping_work``: the
      works of /dynamic/energy over the run (negative: dissipated), and ``dissipated``,
      minus their sum;
    * ``mechanical_change`` (``left``): change of kinetic + strain + contact (+ gravity)
      energy, the recorded total without the load cycle's potential F(t) z_chassis: what the
      cycle leaves in the spring (a vibration, a state held by friction);
    * ``residual``: area - dissipated - mechanical_change, the energy balance's error (zero
      when the books balance; a spring released from its assembled state, ``spring.settle =
      'none'``, loses hundreds of J in the first steps' impact that no work accounts for);
    * the same from ``t_from``, the first output time at which F reaches ``threshold`` of its
      peak (``work_from``, ``dissipated_from``, ``mechanical_change_from``,
      ``residual_from``), which leaves such a release out;
    * ``secant_stiffness``: F / delta between the start and the peak force;
    * ``hysteresis``: delta minus a cubic in F fitted over the cycle: the loop without its
      mean curve encloses the same area and shows the friction band (and any vibration)."""
    force = run.cycle_force()
    delta = -run.chassis
    loop_f, loop_d = np.append(force, force[0]), np.append(delta, delta[0])
    area = float(np.sum(0.5 * (loop_f[1:] + loop_f[:-1]) * np.diff(loop_d)))
    e = run.energy
    material = e.get("material_damping_work", np.zeros_like(e["friction_work"]))
    work = e["friction_work"] + e["damping_work"] + material
    mechanical = e["total"] - force * run.chassis_z
    dissipated = float(-(work[-1] - work[0]))
    change = float(mechanical[-1] - mechanical[0])
    k = int(np.argmax(force >= threshold * force.max())) if force.max() > 0 else 0
    work_from = float(np.sum(0.5 * (force[k + 1:] + force[k:-1]) * np.diff(delta[k:])))
    dissipated_from = float(-(work[-1] - work[k]))
    change_from = float(mechanical[-1] - mechanical[k])
    peak = int(np.argmax(force))
    secant = (force[peak] - force[0]) / (delta[peak] - delta[0]) if peak > 0 else np.inf
    # the mean curve delta(F): a cubic in F fitted over the cycle (any function of F leaves
    # the area of the loop unchanged: F d(p(F)) is a total differential)
    scale = max(float(force.max()), 1.0)
    mean = np.polyval(np.polyfit(force / scale, delta, 3), force / scale) \
        if peak > 0 else np.full_like(delta, delta[0])
    return {"force": force, "deflection": delta, "area": area, "dissipated": dissipated,
            "friction_work": float(e["friction_work"][-1] - e["friction_work"][0]),
            "damping_work": float(e["damping_work"][-1] - e["damping_work"][0]),
            "material_damping_work": float(material[-1] - material[0]),
            "mechanical_change": change, "left": change, "residual": area - dissipated - change,
            "t_from": float(run.time[k]), "work_from": work_from,
            "dissipated_from": dissipated_from, "mechanical_change_from": change_from,
            "residual_from": work_from - dissipated_from - change_from,
            "peak_force": float(force.max()), "peak_deflection": float(delta.max()),
            "secant_stiffness": float(secant),
            "hysteresis": delta - mean}


LINESTYLES = ("-", "--", ":", "-.")


def plot_spring(h5_paths: list[str | Path], png: str | Path | None = None) -> Path:
    """Leaf spring runs, one or several overlaid (e.g. prestress on and off): the chassis's
    vertical displacement, each contact point's normal force and penetration, the energy
    books and, for runs with the effect 'load_cycle', the force-deflection loop with its
    enclosed area and the friction + damping work."""
    runs = [read_spring(p) for p in h5_paths]
    first = runs[0].path
    png = Path(png) if png else (first.with_suffix(".png") if len(runs) == 1 else
                                 first.with_name(f"{first.stem}_compare.png"))
    labels = [r.label for r in runs]
    if len(set(labels)) < len(labels):  # same prestress: tell the files apart
        labels = [f"{lab} [{r.path.stem}]" for lab, r in zip(labels, runs)]
    colours = [f"C{i % 10}" for i in range(len(runs))]
    with_contact = any(r.contact for r in runs)
    cycles = [r for r in runs if r.cycle]
    rows = 4 if with_contact else 2
    fig = plt.figure(figsize=(14.5 if cycles else 9, 2.4 * rows + 1.0), constrained_layout=True)
    grid = fig.add_gridspec(rows, 2 if cycles else 1, width_ratios=[1.25, 1] if cycles else None)
    axes = [fig.add_subplot(grid[0, 0])]
    axes += [fig.add_subplot(grid[i, 0], sharex=axes[0]) for i in range(1, rows)]
    ax = axes[0]
    for run, label, colour in zip(runs, labels, colours):
        ax.plot(run.time, 1e3 * run.chassis, color=colour, lw=0.9, label=label)
    ax.axhline(0.0, color="0.6", lw=0.6)
    ax.set_ylabel("chassis vertical\ndisplacement (mm)")
    ax.legend(fontsize=8)
    heading = runs[0].title if len({r.title for r in runs}) == 1 else "leaf spring runs"
    status = ", ".join(sorted({r.status for r in runs}))
    ax.set_title(f"{heading} ({status})", fontsize=9)
    if with_contact:
        _contact_panels(axes[1], axes[2], runs, labels)
    _energy_panel(axes[-1], runs, labels, colours)
    axes[-1].set_xlabel("time (s)")
    for a in axes[:-1]:
        a.tick_params(labelbottom=False)
    if cycles:  # the loop, its friction band magnified, and its energy books as a table
        loop = fig.add_subplot(grid[:max(rows - 2, 1), 1])
        band = fig.add_subplot(grid[rows - 2, 1]) if rows > 2 else None
        notes = fig.add_subplot(grid[rows - 1, 1])
        _loop_panel(loop, band, runs, labels, colours)
        _loop_table(notes, runs, labels, colours)
    save_figure(fig, png, dpi=120)
    plt.close(fig)
    return png


def _contact_panels(ax_force, ax_pen, runs: list[SpringRun], labels: list[str]) -> None:
    """Normal force and penetration of every contact point: colour per point (greens on the
    front edge, purples on the rear edge), line style per file."""
    from matplotlib.lines import Line2D
    handles = []
    for k, (run, label) in enumerate(zip(runs, labels)):
        if not run.contact:
            continue
        style = LINESTYLES[k % len(LINESTYLES)]
        names = run.points or [f"point {i}" for i in range(run.contact["normal_force"].shape[1])]
        front = [i for i, n in enumerate(names) if n.startswith("front")]
        rear = [i for i in range(len(names)) if i not in front]
        colour = {}
        for ids, cmap in ((front, plt.cm.Greens), (rear, plt.cm.Purples)):
            for j, i in enumerate(ids):
                colour[i] = cmap(0.45 + 0.5 * j / max(len(ids) - 1, 1))
        for i, name in enumerate(names):
            show = k == 0 and (len(names) <= 8 or i in (front[:1] + rear[:1]))
            text = name if len(names) <= 8 else (
                f"{name.split(',')[0]} ({len(front) if i in front else len(rear)} points)")
            ax_force.plot(run.time, run.contact["normal_force"][:, i], style, color=colour[i],
                          lw=0.8, label=text if show else None)
            ax_pen.plot(run.time, 1e3 * run.contact["penetration"][:, i], style,
                        color=colour[i], lw=0.8)
        handles.append(Line2D([], [], color="0.3", ls=style, label=label))
    ax_force.set_ylabel("contact normal\nforce (N)")
    ax_force.legend(fontsize=7, ncol=2, loc="upper right")
    ax_pen.set_ylabel("penetration (mm)")
    if len(runs) > 1:
        ax_pen.legend(handles=handles, fontsize=7, loc="upper right")


def _energy_panel(ax, runs: list[SpringRun], labels: list[str], colours: list[str]) -> None:
    """Per file: mechanical energy change (kinetic + strain + contact + gravity), the work
    of friction and contact damping, and the balance (recorded total - total(0) minus the
    works; it also holds the work of a load cycle's force, whose potential is not kept)."""
    for run, colour in zip(runs, colours):
        e = run.energy
        mechanical = e["total"] - (run.cycle_force() * run.chassis_z if run.cycle else 0.0)
        ax.plot(run.time, mechanical - mechanical[0], color=colour, lw=0.9)
        ax.plot(run.time, e["friction_work"] + e["damping_work"], "--", color=colour, lw=0.9)
        if not run.cycle:
            ax.plot(run.time, e["balance"], ":", color=colour, lw=0.9)
    from matplotlib.lines import Line2D
    handles = [Line2D([], [], color="0.3", ls="-", label="E_mech - E_mech(0)"),
               Line2D([], [], color="0.3", ls="--", label="friction + damping work")]
    if any(not r.cycle for r in runs):
        handles.append(Line2D([], [], color="0.3", ls=":", label="balance"))
    ax.legend(handles=handles, fontsize=7, ncol=3, loc="lower left")
    ax.set_ylabel("energy (J)")


def _loop_panel(ax, band, runs: list[SpringRun], labels: list[str],
                colours: list[str]) -> None:
    """Force against downward deflection of the load-cycle runs (loading solid, unloading
    dashed, the start a dot) and, in ``band``, the same loops without their mean curve
    (``load_cycle_summary``'s hysteresis): the friction band, magnified."""
    for run, label, colour in zip(runs, labels, colours):
        if not run.cycle:
            continue
        s = load_cycle_summary(run)
        half = run.time <= 0.5 * float(run.values["spring"]["cycle_period"])
        f, d, h = 1e-3 * s["force"], 1e3 * s["deflection"], 1e3 * s["hysteresis"]
        ax.plot(d[half], f[half], color=colour, lw=0.9, label=label)
        ax.plot(d[~half], f[~half], "--", color=colour, lw=0.9)
        ax.plot(d[:1], f[:1], "o", color=colour, ms=4)
        if band is not None:
            smooth = _bounce_average(run.time, h)
            band.plot(h, f, color=colour, lw=0.5, alpha=0.35)
            band.plot(smooth[half], f[half], color=colour, lw=1.2)
            band.plot(smooth[~half], f[~half], "--", color=colour, lw=1.2)
            band.plot(smooth[:1], f[:1], "o", color=colour, ms=4)
    ax.axvline(0.0, color="0.6", lw=0.6)
    ax.set_xlabel("chassis deflection from the assembled spring, downward (mm)")
    ax.set_ylabel("force on the chassis, downward (kN)")
    ax.set_title("load cycle F = F_c (1 - cos(2 pi t / T)) / 2: loading solid, unloading "
                 "dashed, start (settled state) o", fontsize=8)
    ax.legend(fontsize=8, loc="upper left")
    ax.grid(alpha=0.3)
    if band is not None:
        band.axvline(0.0, color="0.6", lw=0.6)
        band.set_xlabel("deflection - its mean curve, a cubic in F (mm): the loop magnified; "
                        "thin: as computed, with the small bounce\nthe force's onset excites; "
                        "thick: averaged over one bounce period (the friction band)", fontsize=8)
        band.set_ylabel("force (kN)")
        band.grid(alpha=0.3)


def _bounce_average(time: np.ndarray, values: np.ndarray) -> np.ndarray:
    """``values`` averaged over one period of their strongest oscillation above 0.5 Hz (a
    centred moving average; the ends average what there is): removes a free bounce riding on
    a slow curve."""
    if len(time) < 8:
        return values
    dt = float(np.mean(np.diff(time)))
    spectrum = np.abs(np.fft.rfft(values - values.mean()))
    freq = np.fft.rfftfreq(len(values), dt)
    above = freq > 0.5
    if not above.any():
        return values
    width = int(round(1.0 / (freq[above][np.argmax(spectrum[above])] * dt)))
    if width < 2:
        return values
    kernel = np.ones(width)
    return (np.convolve(values, kernel, "same") /
            np.convolve(np.ones_like(values), kernel, "same"))


def _loop_table(ax, runs: list[SpringRun], labels: list[str], colours: list[str]) -> None:
    """The loop's energy books per run: the area (the work of the applied force around the
    loop) against the works that dissipate it and what the cycle left in the spring."""
    ax.axis("off")
    header = ["run", "loop area", "friction", "contact\ndamping", "material\ndamping",
              "left in\nthe spring", "balance\nerror"]
    rows, row_colours = [], []
    for run, label, colour in zip(runs, labels, colours):
        if not run.cycle:
            continue
        s = load_cycle_summary(run)
        settle = str(run.values.get("spring", {}).get("settle", ""))
        rows.append([f"{label}\n(settle '{settle}')" if settle else label,
                     *(_joules(v) for v in (s["area"], -s["friction_work"],
                                             -s["damping_work"], -s["material_damping_work"],
                                             s["left"], s["residual"]))])
        row_colours.append(colour)
    if not rows:
        return
    table = ax.table(cellText=rows, colLabels=header, loc="upper center", cellLoc="center",
                     colWidths=[0.34] + [0.11] * 6)
    table.auto_set_font_size(False)
    table.set_fontsize(7)
    table.scale(1.0, 2.4)
    for i, colour in enumerate(row_colours, start=1):
        table[i, 0].get_text().set_color(colour)
    ax.set_title("loop area = friction + contact damping + material damping + left in the "
                 "spring + balance error\n(dissipated works counted positive; 'left': "
                 "kinetic + strain + contact energy at the end minus at the start)",
                 fontsize=7.5)


def _joules(value: float) -> str:
    """An energy for the loop table: three significant digits, no '-0'."""
    return "0" if value == 0.0 else f"{value:.3g} J"


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
    save_figure(fig, png, dpi=120)
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
    save_figure(fig, png, dpi=120)
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
    save_figure(fig, png, dpi=120)
    plt.close(fig)
    return png


def plot_static(h5_path: Path, png: str | Path | None = None) -> Path:
    """Static result: deflection of the neutral axis along the beam, in the rigid frame."""
    png = Path(png) if png else h5_path.with_suffix(".png")
    with h5py.File(h5_path, "r") as h5:
        _require_static(h5, h5_path)
        s = h5["model/node_s"][()]
        stride = int(h5["model"].attrs.get("node_coordinates", 12))  # beams 12, cables 6
        e0 = h5["model/e0"][()].reshape(-1, stride)
        q = h5["static/q"][()].reshape(-1, stride)
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
    save_figure(fig, png, dpi=120)
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
    mesh_keys = [k for k in keys if is_resolution(k) and k != "solver.dt"]
    nodes_key = mesh_keys[0] if mesh_keys else None
    others = [k for k in keys if not is_resolution(k)]
    numeric = [k for k in others if all(_isnum(r[k]) for r in ok)]
    x_key = numeric[0] if numeric else None  # the x axis; string keys become panels
    panel_keys = [k for k in others if k != x_key]
    panels = sorted({tuple(r[k] for k in panel_keys) for r in ok}, key=lambda t: [float(v) if
                    _isnum(v) else v for v in t])
    if x_key and not any(r.get("dynamic") or "analysis" in r for r in ok):  # static: Figs. 4-5
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
        save_figure(fig, path, dpi=120)
        plt.close(fig)
        out.append(path)
    if any("err_vs_reference" in r for r in ok):
        err_key = "err_vs_reference"
    elif any("err_vs_closed_form" in r for r in ok):
        err_key = "err_vs_closed_form"
    else:
        err_key = "err_vs_finest"
    pts = [r for r in ok if r.get(err_key, 0) > 0 and r.get("compute_time_s", 0) > 0]
    if pts:  # one series per family (the values of the non-refining keys)
        def varies(key: str) -> bool:
            return len({str(r.get(key)) for r in pts}) > 1
        dt_keys = ["solver.dt"] if varies("solver.dt") else []
        # a line per family (the values of the other keys that vary), a label per point
        family_keys = [k for k in others if varies(k)] or dt_keys
        point_keys = mesh_keys + [k for k in dt_keys if k not in family_keys]
        out.append(pareto_chart(
            pts, lambda r: ", ".join(f"{_short(k)} {r[k]}" for k in family_keys) or "runs",
            lambda r: ", ".join(f"{_short(k)} {r[k]}" for k in point_keys), err_key,
            outdir / "error_vs_time.png", common_reference=err_key == "err_vs_reference"))
    return out


def _short(key: str) -> str:
    return key.rpartition(".")[2]


#: the time axis of an accuracy-versus-time chart (results/hdf5.py, phase_times)
COMPUTE_LABEL = ("computing time (s): model, assembly, factorization, solve\n"
                 "(the file's /timing; start-up, reading and writing excluded)")


def pareto_front(points: list[tuple[float, float]]) -> list[tuple[float, float]]:
    """The points no other point beats in both time and error (x: time, y: error), in
    the order of time: the cheapest run for each accuracy."""
    front: list[tuple[float, float]] = []
    for x, y in sorted(points):
        if not front or y < front[-1][1]:
            front.append((x, y))
    return front


def pareto_chart(rows: list[dict], family, point_label, err_key: str, path: Path, *,
                 time_key: str = "compute_time_s", title: str = "what accuracy costs in time",
                 common_reference: bool = False) -> Path:
    """Error against computing time on logarithmic axes. One colour per family
    (``family(row)``: its label); each point annotated with ``point_label(row)`` (e.g. the
    node count and the step); each family's line joins its Pareto front (the cheapest of
    its runs for each accuracy), its other runs are hollow. With ``common_reference`` (every
    error measured against the same reference, so the families are alternatives for one
    problem) the front over all the families is drawn beneath in grey. Used by ``ancf
    sweep`` (families: the values of the other varied keys) and
    benchmarks/accuracy_chart.py."""
    fig, ax = plt.subplots(figsize=(8.5, 5.6), constrained_layout=True)
    families: dict[str, list[dict]] = {}
    for row in rows:
        families.setdefault(family(row), []).append(row)
    if common_reference:
        front = pareto_front([(float(r[time_key]), float(r[err_key])) for r in rows])
        ax.plot([p[0] for p in front], [p[1] for p in front], color="0.75", lw=6, alpha=0.7,
                zorder=0, label="cheapest for its accuracy, over all")
    markers = "osD^v<>p*hX"
    for i, (name, members) in enumerate(families.items()):
        colour, marker = f"C{i % 10}", markers[i % len(markers)]
        points = [(float(r[time_key]), float(r[err_key])) for r in members]
        front = pareto_front(points)
        ax.plot([p[0] for p in front], [p[1] for p in front], "-" + marker, ms=5, lw=1.2,
                color=colour, label=name)
        others = [p for p in points if p not in front]
        if others:
            ax.plot([p[0] for p in others], [p[1] for p in others], marker, ms=5,
                    mfc="none", color=colour)
        for r, (xi, yi) in zip(members, points):
            ax.annotate(point_label(r), (xi, yi), textcoords="offset points", xytext=(3, 3),
                        fontsize=6, color=colour)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(COMPUTE_LABEL if time_key == "compute_time_s"
                  else time_key.replace("_s", " (s)").replace("_", " "))
    ax.set_ylabel(err_key.replace("_", " "))
    ax.set_title(title + "\n(lines: each family's cheapest runs for their accuracy; "
                 "hollow: beaten by a run of the same family)", fontsize=9)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7, loc="best")
    save_figure(fig, path, dpi=120)
    plt.close(fig)
    return path


def plot_histories(rows: list[dict], keys: list[str], outdir: Path) -> list[Path]:
    """Tip sag histories of every node count (at the finest dt), the whole run and one
    panel per luffing stage (the paper's Figs. 6-15); one figure per value of the other
    varied keys."""
    import h5py as _h5
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
                probe, component = row_response(row) or (
                    _text(h5.attrs.get("response_probe", "tip")),
                    int(h5.attrs.get("response_component", 1)))
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
        save_figure(fig, path, dpi=110)
        plt.close(fig)
        out.append(path)
    return out


def _text(value) -> str:
    """An HDF5 string attribute as str (h5py returns bytes for some)."""
    return value.decode() if isinstance(value, bytes) else str(value)


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


def plot_sections(h5_path: str | Path, png: str | Path | None = None) -> Path | None:
    """Section forces and stresses along every beam of a result file: N, the shear forces
    Q, the torsion T, the moments M (components along the section's height and width axes)
    and the von Mises stress of the static state, with the dynamic run's von Mises envelope
    when there is one. None when the file has no section forces."""
    h5_path = Path(h5_path)
    with h5py.File(h5_path, "r") as h5:
        if "static/sections" not in h5 and "dynamic/stress" not in h5:
            return None
        static = {name: {k: g[k][()] for k in g} for name, g in
                  h5["static/sections"].items()} if "static/sections" in h5 else {}
        stress = {name: g["von_mises"][()] for name, g in h5["static/stress"].items()} \
            if "static/stress" in h5 else {}
        envelope = {name: (g["s"][()], g["von_mises_max"][()]) for name, g in
                    h5["dynamic/stress"].items()} if "dynamic/stress" in h5 else {}
        title = _text(h5.attrs.get("title", h5_path.stem))
    fig, axes = plt.subplots(2, 2, figsize=(12, 8), sharex=False)
    (ax_n, ax_q), (ax_m, ax_s) = axes
    for name, f in static.items():
        s = f["s"]
        ax_n.plot(s, f["N"] / 1e3, label=f"{name}: N")
        ax_n.plot(s, f["T"] / 1e3, "--", label=f"{name}: T [kN m]")
        ax_q.plot(s, f["Q"][:, 0] / 1e3, label=f"{name}: Q height")
        ax_q.plot(s, f["Q"][:, 1] / 1e3, "--", label=f"{name}: Q width")
        ax_m.plot(s, f["M"][:, 0] / 1e3, label=f"{name}: M height")
        ax_m.plot(s, f["M"][:, 1] / 1e3, "--", label=f"{name}: M width")
        if name in stress:
            ax_s.plot(s, stress[name] / 1e6, label=f"{name}: static")
    for name, (s, vm) in envelope.items():
        ax_s.plot(s, vm / 1e6, ":", label=f"{name}: dynamic envelope")
    for ax, ylabel in ((ax_n, "N [kN], T [kN m]"), (ax_q, "Q [kN]"), (ax_m, "M [kN m]"),
                       (ax_s, "von Mises [MPa]")):
        ax.set_xlabel("arc length s [m]")
        ax.set_ylabel(ylabel)
        ax.grid(alpha=0.3)
        if ax.lines:
            ax.legend(fontsize=7)
    fig.suptitle(f"{title}: section forces and stresses along the beams")
    fig.tight_layout()
    out = Path(png) if png else h5_path.with_name(h5_path.stem + "_sections.png")
    save_figure(fig, out, dpi=110)
    plt.close(fig)
    return out


def _mesh_segments(h5: h5py.File) -> list[np.ndarray]:
    """Point index lists to draw: each line and each closed quadrilateral of /model/mesh;
    a line from a point to itself (a point mass, a joint) as that one point."""
    group = h5["model/mesh"]
    kind = _text(group.attrs["topology_type"])
    topology = group["topology"][()]
    if kind == "Quadrilateral":
        return [np.append(row, row[0]) for row in topology]
    if kind == "Polyline":
        lines = list(topology)
    else:
        out, lines, k = [], [], 0
        while k < len(topology):
            if topology[k] == 5:
                out.append(np.append(topology[k + 1:k + 5], topology[k + 1]))
                k += 5
            else:
                lines.append(topology[k + 2:k + 4])
                k += 4
        return out + [line[:1] if line[0] == line[1] else line for line in lines]
    return [line[:1] if line[0] == line[1] else line for line in lines]


def mesh_style(segment: np.ndarray) -> dict:
    """matplotlib's style of a mesh segment: a line, or a marker for a lone point."""
    return dict(marker="o", ms=4) if len(segment) == 1 else {}


def _draw_shape(ax, segments: list[np.ndarray], base: np.ndarray, displacement: np.ndarray,
                scale: float) -> None:
    """The mesh at ``base`` (grey ghost) and displaced by ``scale`` x ``displacement``, seen
    in the plane of the mesh's largest extent and the displacement's largest component."""
    extent = np.ptp(base, axis=0)
    along = int(np.argmax(extent))
    moved = int(np.argmax(np.abs(displacement).max(axis=0, initial=0.0)
                          + (np.arange(3) == along) * -1e9))
    deformed = base + scale * displacement
    for seg in segments:
        ax.plot(base[seg, along], base[seg, moved], color="0.75", lw=0.8, **mesh_style(seg))
        ax.plot(deformed[seg, along], deformed[seg, moved], color="C0", lw=1.2,
                **mesh_style(seg))
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(f"{'xyz'[along]} (m)")
    ax.set_ylabel(f"{'xyz'[moved]} (m)")


def shape_scale(base: np.ndarray, displacement: np.ndarray) -> float:
    """The factor that draws a displacement field visibly: its largest displacement shown
    as a tenth of the mesh's size, or 1 (true scale) when it is already larger."""
    size = max(float(np.ptp(base, axis=0).max(initial=0.0)), 1e-12)
    peak = float(np.abs(displacement).max(initial=0.0))
    if peak == 0.0 or peak >= 0.1 * size:
        return 1.0
    return 0.1 * size / peak


def plot_modes(h5_path: Path, png: str | Path | None = None, group: str = "modal",
               count: int = 4) -> Path:
    """The first mode shapes of a modal or buckling analysis: the mesh at the static state
    (grey) and displaced by each shape (scaled to a tenth of the model's size), seen in the
    plane of the model's largest extent and the shape's largest displacement."""
    png = Path(png) if png else h5_path.with_suffix(".png")
    with h5py.File(h5_path, "r") as h5:
        static = h5[f"{group}/mesh_static"][()]
        shapes = h5[f"{group}/mesh_shapes"][:count]
        key = "frequency" if group == "modal" else "load_factor"
        values = h5[f"{group}/{key}"][:count]
        damping = h5[f"{group}/damping_ratio"][:count] if "damping_ratio" in h5[group] else None
        segments = _mesh_segments(h5)
        title = _text(h5.attrs.get("title", ""))
    size = max(float(np.ptp(static, axis=0).max()), 1e-12)
    n = len(shapes)
    fig, axes = plt.subplots(1, max(n, 1), figsize=(3.2 * max(n, 1), 3.2),
                             constrained_layout=True, squeeze=False)
    for k, ax in enumerate(axes[0]):
        if k >= n:
            ax.axis("off")
            continue
        _draw_shape(ax, segments, static, shapes[k], 0.1 * size)
        if group == "modal":
            label = f"mode {k + 1}: {values[k]:.4g} Hz"
            if damping is not None:
                label += f", zeta {damping[k]:.3g}"
        else:
            label = f"mode {k + 1}: load factor {values[k]:.4g}"
        ax.set_title(label, fontsize=9)
    fig.suptitle(textwrap.fill(f"{title} ({group})", max(24, int(16 * max(n, 1)))),
                 fontsize=10)
    save_figure(fig, png, dpi=110)
    plt.close(fig)
    return png
