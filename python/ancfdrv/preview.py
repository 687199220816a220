"""``ancf show``: a picture of the undeformed model before any solve (issue 37, item 2).

The scene is read and its model assembled (every input check of a run), nothing is
solved. One PNG shows three orthographic views (x-y, x-z, y-z) and an isometric one:

* bodies as the points and cells their kind's ``mesh`` hook gives the XDMF writer
  (:class:`~ancfdrv.results.xdmf.MeshLayout`: beams and cables as centre lines through
  their nodes, plates and leaves as their element edges, rigid bodies as their centre,
  axes and inertia box), flexible bodies' nodes marked, a rigid body's centre marked;
* joints as labelled points (joints to the ground, the supports, as triangles), distance
  joints and force elements as dashed lines between their points;
* point masses as points, probes as labelled markers, forces and gravity as arrows
  scaled to the model's size (1/6 of its largest extent), moments as labelled points.

Each artist of a body carries ``gid = 'body:<name>'`` (tests read the drawn geometry back).
matplotlib is imported when a picture is drawn, never by importing this module.
"""
from __future__ import annotations

import os
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

from .builders import build_model, build_system
from .builders.general import locate_error
from .errors import InputError
from .io.safe_write import save_figure
from .io.scene import load_scene
from .results.xdmf import MeshLayout
from .system import Model, System
from .system.bodies import Ground
from .system.loads import DeadMoment, Gravity, PointForce, PointMass
from .system.registry import kind_of

#: the figure's size (inches) and resolution: the PNG is FIGSIZE * DPI pixels
FIGSIZE = (14.0, 10.5)
DPI = 110
#: the views: (title, the two axes shown)
VIEWS = (("x-y", (0, 1)), ("x-z", (0, 2)), ("y-z", (1, 2)))
_AXIS = "xyz"


def show_scene(path: str | Path, overrides: list[str] | None = None,
               png: str | Path | None = None) -> Path:
    """The preview of a scene file (``ancf show``): SCENE.png beside the scene unless
    ``png`` is given. Bad input raises InputError naming file, group and key."""
    scene = load_scene(path, overrides)
    built = build_system(scene)
    scene.built = built  # build_model takes it (a general scene's System is built once)
    try:
        model = build_model(scene)
    except InputError as exc:
        raise locate_error(exc, scene) from None
    out = Path(png) if png is not None else Path(scene.path).with_suffix(".png")
    try:
        return draw(built.system, model, out, scene["scene"]["title"])
    finally:
        model.close()


def show_system(system: System, path: str | Path | None = None) -> Path:
    """The preview of a System (``System.show``): written to ``path``, or to a new
    temporary file ``ancf-show-*.png`` when None; returns the PNG's path."""
    if path is None:
        handle, name = tempfile.mkstemp(prefix="ancf-show-", suffix=".png")
        os.close(handle)
        path = name
    model = system.assemble()
    try:
        return draw(system, model, Path(path), system.title)
    finally:
        model.close()


def _segments(points: np.ndarray, pairs: np.ndarray) -> np.ndarray:
    """(n, 3) coordinates of the cells' edges, each edge followed by a NaN row (one line
    per body)."""
    rows = []
    for cell in pairs:
        closed = list(cell) + ([cell[0]] if len(cell) > 2 else [])
        rows.extend(points[closed])
        rows.append(np.full(3, np.nan))
    return np.array(rows) if rows else np.zeros((0, 3))


def geometry(system: System, model: Model) -> dict[str, Any]:
    """What the preview draws, in the initial configuration: per body its edges (NaN
    separated), nodes and label point; joints, distance lines, force elements, probes,
    point masses, forces, moments and gravity."""
    layout = MeshLayout.from_model(model)
    bodies = {}
    for body in model.bodies:
        if layout is None or body.name not in layout.spans:
            continue
        span = layout.spans[body.name]
        edges = np.vstack([_segments(layout.points, cells[np.all(
            (cells >= span.start) & (cells < span.stop), axis=1)])
            for cells in (layout.lines, layout.quads)])
        nodes = layout.points[span.start:span.stop]
        centre = None if body.flexible else np.asarray(body.centre, dtype=float)
        word = kind_of(body).word
        section_label = getattr(getattr(body, "section", None), "label", None)
        if callable(section_label):  # a standard section: its name and strong axis
            word += ", " + section_label(body.orientation[:, 1])
        bodies[body.name] = dict(edges=edges, nodes=nodes if body.flexible else None,
                                 centre=centre, label=nodes.mean(axis=0), word=word)
    joints, lines = [], []
    for joint in system.joints.values():
        support = isinstance(joint.body1, Ground) or isinstance(joint.body2, Ground)
        if joint.type == "distance":
            lines.append((joint.name, np.array([joint.point1, joint.point2]), "distance"))
            continue
        for point in (joint.points or [p for p in (joint.pivot,) if p is not None])[:1]:
            joints.append((f"{joint.name} ({joint.type})", np.asarray(point, float), support))
    for element in system.force_elements.values():
        ends = np.array([element.point1, element.point2], dtype=float)
        lines.append((f"{element.name} ({element.type})", ends, "force element"))
    loads = list(system.loads.values())
    return dict(
        bodies=bodies, joints=joints, lines=lines,
        probes=[(p.name, np.asarray(p.point, float)) for p in system.probes.values()],
        masses=[(f"{m.name} ({m.mass:g} kg)", m.point) for m in loads
                if isinstance(m, PointMass)],
        forces=[(f"{f.name} ({np.linalg.norm(f.vector):.3g} N)", f.point, f.vector)
                for f in loads if isinstance(f, PointForce)],
        moments=[(f"{m.name} ({np.linalg.norm(m.vector):.3g} N m)", m.point) for m in loads
                 if isinstance(m, DeadMoment)],
        gravity=[g.vector for g in loads if isinstance(g, Gravity)])


def bounding_box(shapes: dict[str, Any]) -> tuple[np.ndarray, np.ndarray]:
    """(low, high) corners of every point drawn but the arrows and labels."""
    pts = [b["edges"] for b in shapes["bodies"].values()]
    pts += [b["nodes"] for b in shapes["bodies"].values() if b["nodes"] is not None]
    pts += [ends for _, ends, _ in shapes["lines"]]
    pts += [np.atleast_2d(p) for key in ("joints", "probes", "masses", "forces", "moments")
            for _, p, *_ in shapes[key]]
    every = np.vstack([np.asarray(p, float).reshape(-1, 3) for p in pts]) if pts else \
        np.zeros((1, 3))
    return np.nanmin(every, axis=0), np.nanmax(every, axis=0)


def draw(system: System, model: Model, png: Path, title: str) -> Path:
    """Draws the preview (see the module documentation) into ``png``."""
    import matplotlib.pyplot as plt
    fig = figure(system, model, title)
    png.parent.mkdir(parents=True, exist_ok=True)
    try:
        save_figure(fig, png, dpi=DPI)
    finally:
        plt.close(fig)
    return png


def figure(system: System, model: Model, title: str) -> Any:
    """The preview's matplotlib figure (see the module documentation): the three views,
    then the isometric one."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    shapes = geometry(system, model)
    low, high = bounding_box(shapes)
    size = float(np.max(high - low)) or 1.0
    arrow = size / 6.0
    fig = plt.figure(figsize=FIGSIZE, dpi=DPI)
    axes = [fig.add_subplot(2, 2, k + 1) for k in range(3)]
    iso = fig.add_subplot(2, 2, 4, projection="3d")
    areas = [np.prod((high - low)[list(pair)] + 1e-12 * size) for _, pair in VIEWS]
    labelled = int(np.argmax(areas))
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]

    # the isometric view stands the axis opposite to gravity up (z without gravity),
    # the others in cyclic (right-handed) order
    gravity = shapes["gravity"][0] if shapes["gravity"] else np.array([0.0, 0.0, -1.0])
    up = int(np.argmax(np.abs(gravity)))
    upright = [(up + 1) % 3, (up + 2) % 3, up]

    def draw_view(ax, pair, labels: bool) -> None:
        three = pair is None
        idx = upright if three else list(pair)

        def coords(p):
            p = np.atleast_2d(np.asarray(p, float))
            return [p[:, i] for i in idx]

        def text(point, words, **kw):
            ax.text(*[c[0] for c in coords(point)], " " + words, fontsize=7, **kw)

        for k, (name, body) in enumerate(shapes["bodies"].items()):
            colour = colours[k % len(colours)]
            ax.plot(*coords(body["edges"]), "-", color=colour, lw=1.8, gid=f"body:{name}")
            if body["nodes"] is not None:
                ax.plot(*coords(body["nodes"]), "o", color=colour, ms=3, gid=f"body:{name}")
            if body["centre"] is not None:
                ax.plot(*coords(body["centre"]), "s", color=colour, ms=6, gid=f"body:{name}")
            if labels:
                text(body["label"], f"{name} ({body['word']})", color=colour,
                     fontweight="bold")
        for name, ends, what in shapes["lines"]:
            ax.plot(*coords(ends), "--", color="0.3", lw=1.2, gid=f"line:{name}")
            if labels:
                text(ends.mean(axis=0), name, color="0.3")
        for name, point, support in shapes["joints"]:
            ax.plot(*coords(point), "^" if support else "o", color="k", mfc="w" if not support
                    else "k", ms=7, gid=f"joint:{name}")
            if labels:
                text(point, name)
        for name, point in shapes["probes"]:
            ax.plot(*coords(point), "D", color="tab:purple", mfc="none", ms=8,
                    gid=f"probe:{name}")
            if labels:
                text(point, name, color="tab:purple", va="top")
        for name, point in shapes["masses"]:
            ax.plot(*coords(point), "o", color="tab:brown", ms=10, gid=f"mass:{name}")
            if labels:
                text(point, name, color="tab:brown", va="bottom")
        for name, point in shapes["moments"]:
            ax.plot(*coords(point), "o", color="tab:red", mfc="none", ms=12,
                    gid=f"moment:{name}")
            if labels:
                text(point, name, color="tab:red")
        arrows = [(name, np.asarray(p, float), np.asarray(v, float), "tab:red")
                  for name, p, v in shapes["forces"]]
        arrows += [("g", np.array([low[0], high[1], high[2]]), g, "tab:green")
                   for g in shapes["gravity"]]
        for name, point, vector, colour in arrows:
            norm = float(np.linalg.norm(vector))
            if norm == 0.0:
                continue
            tip = point if name != "g" else point + vector / norm * arrow
            tail = tip - vector / norm * arrow
            if three:
                ax.quiver(*tail[idx], *(tip - tail)[idx], color=colour,
                          arrow_length_ratio=0.25)
            else:
                ax.annotate("", xy=tip[idx], xytext=tail[idx],
                            arrowprops=dict(arrowstyle="-|>", color=colour, lw=1.5))
                ax.update_datalim([tail[idx], tip[idx]])
            if labels:
                text(tail, name, color=colour)
        margin = 0.08 * size
        if three:
            centre = 0.5 * (low + high)[idx]
            for setter, c in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre):
                setter(c - 0.5 * size - margin, c + 0.5 * size + margin)
            ax.set_box_aspect((1, 1, 1))
            ax.set_proj_type("ortho")
            ax.view_init(elev=np.degrees(np.arctan(1 / np.sqrt(2))), azim=-45)
            ax.set_xlabel(f"{_AXIS[idx[0]]} (m)")
            ax.set_ylabel(f"{_AXIS[idx[1]]} (m)")
            ax.set_zlabel(f"{_AXIS[idx[2]]} (m)")
            ax.set_title("isometric", fontsize=10)
        else:
            half = 0.5 * float(np.max((high - low)[idx])) + margin  # a square view
            for setter, i in ((ax.set_xlim, idx[0]), (ax.set_ylim, idx[1])):
                centre = 0.5 * (low[i] + high[i])
                setter(centre - half, centre + half)
            ax.set_aspect("equal", adjustable="box")
            ax.grid(True, lw=0.3)
            ax.set_xlabel(f"{_AXIS[idx[0]]} (m)")
            ax.set_ylabel(f"{_AXIS[idx[1]]} (m)")

    for k, (ax, (name, pair)) in enumerate(zip(axes, VIEWS)):
        draw_view(ax, pair, k == labelled)
        ax.set_title(f"{name} view" + (" (names)" if k == labelled else ""), fontsize=10)
    draw_view(iso, None, True)
    counts = ", ".join(f"{n} {one if n == 1 else many}" for n, one, many in (
        (len(shapes["bodies"]), "body", "bodies"), (len(system.joints), "joint", "joints"),
        (len(system.force_elements), "force element", "force elements"),
        (len(system.loads), "load", "loads"), (len(system.probes), "probe", "probes")))
    counts += f"; {model.summary()['ndof']} coordinates; undeformed, nothing solved"
    fig.suptitle(f"{title}\n{counts}", fontsize=11)
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    return fig
