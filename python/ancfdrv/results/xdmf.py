"""XDMF descriptions of result files, for ParaView (and meshio): every body of the model.

A static result has one grid at the static state (:func:`write_static_xdmf`), a modal or
buckling result one grid with a vector attribute per shape (:func:`write_mode_xdmf`), a
dynamic result the following time series (:func:`write_xdmf`), all on the same mesh.

The XDMF 3 file beside ``OUT.h5`` is a temporal collection with one uniform grid per frame
(an output step; long runs are thinned to at most ``output.xdmf_frames`` frames, evenly,
always with the first and the last step). The grid shows

* plates and leaves as quadrilaterals (the elements' corner nodes), as before;
* beams and cables (ropes) as polylines: a 2-node line per element through the node
  positions r;
* rigid bodies as their centre r with their body axes: three lines from the centre along
  r_x, r_y, r_z, as long as the body's radius of gyration sqrt(tr(I) / 2m), and the
  wireframe (12 edges) of their inertia box, the uniform box of the same mass and
  principal moments of inertia, each corner r + u1 r_x + u2 r_y + u3 r_z;
* force elements and distance joints as a line between their two attachment points;
* point masses and joints as lone points (a joint with several points, an edge or box
  selection, as several), labelled by the ``bodies`` list.

Every point is an affine function of the full coordinates q: a sum of coefficients times
nodal 3-vectors plus a constant (a point on the ground). A lone point is written as a line
from the point to itself (``2 2 a a`` in a ``Mixed`` topology): XDMF's own Polyvertex
cannot be used, since in a ``Mixed`` topology VTK (ParaView) reads a Polyvertex with a
node count and meshio without one, so no vertex encoding works for both readers; the plots
draw such a line as a marker, ParaView shows it with the Points representation.

With one kind of cell the topology is ``Quadrilateral`` or ``Polyline`` (2 nodes per line);
with several it is ``Mixed`` (quad: 5 a b c d, line: 2 2 a b). The points' positions come
from the stored coordinates: q of each step expanded to the full coordinates
(:meth:`Model.expand`), mapped by the sparse matrix of :class:`MeshLayout` plus its
constant offset.

meshio's ``meshio.xdmf.TimeSeriesReader`` reads only plain ``Format="HDF"`` items naming
one whole dataset (its readers require ``Format`` on every DataItem: no HyperSlab, no
Function), and of the geometry only the first frame's; ParaView's XDMF 3 reader reads every
frame's geometry and attributes, HyperSlab items included. So:

* a small series (at most :data:`INLINE_VALUES` values of displacement over all frames: a
  boom or a pendulum at the default 250 frames) carries the first frame's points and
  every frame's displacement inline, as ``Format="XML"`` items (the shortest decimal text
  that reads back as the same double), with no HDF5 object per frame;
* a larger one names HDF5 virtual datasets, ``/dynamic/xdmf/position/0`` and
  ``/dynamic/xdmf/displacement/<k>``, that map row k of ``/dynamic/mesh_nodes`` and
  ``/dynamic/mesh_displacement``: no data is copied (the dynamic writer adds them as
  frames are written, :func:`add_step_views`; each costs ~0.15 ms of CPU to make, plus
  its share of the file's close);
* the geometry of frame k >= 1 is a HyperSlab item, row k of ``/dynamic/mesh_nodes``.

meshio shows the motion through the ``displacement`` attribute of every frame, ParaView
through the geometry too.
The XML is built as text with the file name escaped, so any file name (``&``, ``<``,
quotes) gives valid XML; a ``:`` in the HDF5 file name cannot be expressed in XDMF's
``file:/path`` notation and is refused.
"""
from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path

import h5py
import numpy as np
from h5py import h5a, h5d, h5p, h5s, h5t

from ..records import record
from ..csr import Csr
from ..errors import InputError
from ..io.safe_write import replace_atomically, write_text
from ..system.registry import kind_of

_STEPS_GROUP = "dynamic/xdmf"
#: the most displacement values (3 per point and frame) a description carries inline
#: (~20 bytes of text each: at most ~0.6 MB); larger series name per-frame views
INLINE_VALUES = 30_000
#: XDMF cell codes of a Mixed topology
_QUAD, _LINE = 5, 2


@record(eq=False, repr=False)
class MeshLayout:
    """The points and cells XDMF shows for a model, and the affine map from full
    coordinates to the points' positions."""

    points: np.ndarray        # (npoints, 3) initial positions
    quads: np.ndarray         # (nquad, 4) point indices
    lines: np.ndarray         # (nline, 2) point indices (a lone point: a line [a, a])
    map: Csr                  # (3 npoints, nfull): positions = map @ q_full + offset
    offset: np.ndarray        # (3 npoints,) the constant part (points on the ground)
    bodies: list[str]         # 'name: kind, points a..b' per item shown
    spans: dict[str, range]   # the points of each body (model.bodies) shown, by name

    @classmethod
    def from_model(cls, model) -> "MeshLayout | None":
        """The layout of every item the XDMF shows: the bodies whose kind shows a mesh
        (:class:`~..system.registry.Kind` ``mesh``; plates first, in the order of
        ``model.plate_geometry``, then beams and cables, then rigid bodies), then the force
        elements, the point masses and the joints; None when it shows nothing."""
        rows = _Rows()
        shown = [(k, b) for b in model.bodies if (k := kind_of(b)) is not None and k.mesh]
        for found, body in sorted(shown, key=lambda pair: pair[0].mesh_order):
            start = rows.count
            found.mesh(body, rows)
            rows.part(body.name, found.word, start)
            rows.spans[body.name] = range(start, rows.count)
        if rows.count == 0:
            return None
        _connections(model, rows)
        count = rows.count
        matrix = Csr.from_coo(rows.rows, rows.cols, rows.coefs, (3 * count, model.nfull))
        offset = np.array(rows.consts, dtype=float).reshape(3 * count)
        points = (matrix @ model.q0 + offset).reshape(count, 3)
        lines = _stack(rows.lines, 2)
        if rows.lone:
            lines = np.vstack([lines, np.repeat(np.array(rows.lone, np.int64)[:, None], 2, 1)])
        return cls(points, _stack(rows.quads, 4), lines, matrix, offset, rows.bodies,
                   rows.spans)

    @property
    def npoints(self) -> int:
        return len(self.points)

    def positions(self, model, e: np.ndarray) -> np.ndarray:
        """Point positions (nt, npoints, 3) from (reduced) coordinates e (nt, ndof)."""
        full = model.expand(np.atleast_2d(e))
        return ((self.map @ full.T).T + self.offset).reshape(len(full), self.npoints, 3)

    def topology(self) -> tuple[str, np.ndarray, int]:
        """(XDMF topology type, connectivity, number of cells): 'Quadrilateral' or
        'Polyline' (ncells, nodes) with one kind of cell, else 'Mixed' (flat)."""
        if len(self.lines) == 0:
            return "Quadrilateral", self.quads, len(self.quads)
        if len(self.quads) == 0:
            return "Polyline", self.lines, len(self.lines)
        flat = np.concatenate([
            np.column_stack([np.full(len(self.quads), _QUAD), self.quads]).ravel(),
            np.column_stack([np.full(len(self.lines), _LINE), np.full(len(self.lines), 2),
                             self.lines]).ravel()])
        return "Mixed", flat, len(self.quads) + len(self.lines)


def _connections(model, rows: "_Rows") -> None:
    """The force elements (a line from the point on body1 to the point on body2; a
    bushing's or a torsion spring's two points coincide at t = 0), the point masses (a lone
    point at the material point of their body) and the joints (a 'distance' joint: a line
    between its points; the others: a lone point per joint point, carried by body2, as
    the ground is always a joint's body1)."""
    for info in model.force_elements:
        start = rows.count
        ends = [rows.expression(slot) for slot in info.slots[:2]]
        rows.lines.append(np.array([ends]))
        rows.part(info.name, "force element", start)
    bodies = {body.name: body for body in model.bodies}
    for name, owner, point, _ in model.point_masses:
        body = bodies[owner]
        start = rows.count
        rows.lone.append(rows.expression(
            body.position(body.locate(point, node=False, what=f"load {name!r}"))))
        rows.part(name, "point mass", start)
    for joint in model.joint_items.values():
        where = f"joint {joint.name!r}"
        start = rows.count
        if joint.type == "distance":
            ends = [rows.expression(body.position(body.locate(p, node=False, what=where)))
                    for body, p in ((joint.body1, joint.point1), (joint.body2, joint.point2))]
            rows.lines.append(np.array([ends]))
        else:
            body = joint.body2
            for point in joint.points:
                rows.lone.append(rows.expression(
                    body.position(body.locate(point, node=False, what=where))))
        rows.part(joint.name, "joint", start)


def _stack(blocks: list[np.ndarray], width: int) -> np.ndarray:
    return np.vstack(blocks).astype(np.int64) if blocks else np.zeros((0, width), np.int64)


class _Rows:
    """The row builder a kind's ``mesh`` hook fills: points (each a sum of coefficients
    times 3-vectors of the full coordinates, plus a constant), quadrilaterals, lines and
    lone points."""

    def __init__(self) -> None:
        self.rows: list[int] = []
        self.cols: list[int] = []
        self.coefs: list[float] = []
        self.consts: list[float] = []
        self.quads: list[np.ndarray] = []
        self.lines: list[np.ndarray] = []
        self.lone: list[int] = []
        self.bodies: list[str] = []
        self.spans: dict[str, range] = {}
        self.count = 0

    def point(self, terms: list[tuple[int, float]], const=(0.0, 0.0, 0.0)) -> int:
        """A new point at const + sum coef * q[first + (0, 1, 2)]; returns its index."""
        for first, coef in terms:
            for axis in range(3):
                self.rows.append(3 * self.count + axis)
                self.cols.append(first + axis)
                self.coefs.append(coef)
        self.consts.extend(float(c) for c in const)
        self.count += 1
        return self.count - 1

    def expression(self, v) -> int:
        """A new point at an affine expression of the full coordinates
        (:class:`~..system.expressions.Vec3`); returns its index."""
        return self.point(sorted(v.terms.items()), v.const)

    def node_points(self, first: int, nnodes: int, stride: int) -> int:
        """A point per node (positions at first + stride * node); the first one's index."""
        start = self.count
        for node in range(nnodes):
            self.point([(first + stride * node, 1.0)])
        return start

    def part(self, name: str, word: str, start: int) -> None:
        """Names the points from ``start`` to the last one made ('name: word, points a..b')."""
        self.bodies.append(f"{name}: {word}, points {start}..{self.count - 1}")


def frame_rows(total_rows: int, frames: int) -> tuple[int, int]:
    """(stride, last row): a run of ``total_rows`` output rows shows rows 0, stride,
    2 stride, ... and the last row, at most ``frames`` frames (frames >= 2)."""
    if total_rows <= frames:
        return 1, total_rows - 1
    return math.ceil((total_rows - 1) / (frames - 1)), total_rows - 1


def frame_count(total_rows: int, frames: int) -> int:
    """The frames :func:`frame_rows` shows of a run of ``total_rows`` rows."""
    stride, last = frame_rows(total_rows, frames)
    return last // stride + 1 + int(last % stride != 0)


def inline(npoints: int, nframes: int) -> bool:
    """Whether the description of ``nframes`` frames of ``npoints`` points carries the
    points' data inline (:data:`INLINE_VALUES`) instead of naming per-frame views."""
    return 3 * npoints * nframes <= INLINE_VALUES


def _escape(text: str) -> str:
    """``text`` as XML character data or a double-quoted attribute value."""
    return (text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
            .replace('"', "&quot;"))


def _item(dims: tuple[int, ...], h5_name: str, dataset: str, number_type: str = "Float",
          precision: int = 8) -> str:
    """A ``Format="HDF"`` DataItem naming ``dataset`` of ``h5_name`` (already escaped)."""
    return (f'<DataItem Dimensions="{" ".join(map(str, dims))}" NumberType="{number_type}" '
            f'Precision="{precision}" Format="HDF">{h5_name}:{_escape(dataset)}</DataItem>')


def _topology_xml(kind: str, ncells: int, dims: tuple[int, ...], h5_name: str,
                  dataset: str) -> str:
    nodes = ' NodesPerElement="2"' if kind == "Polyline" else ""
    return (f'<Topology TopologyType="{kind}" NumberOfElements="{ncells}"{nodes}>'
            f'{_item(dims, h5_name, dataset, "Int")}</Topology>')


_DOCUMENT_START = '<?xml version="1.0" encoding="utf-8"?>\n<Xdmf Version="3.0"><Domain>'
_DOCUMENT_END = "</Domain></Xdmf>"


def _document(grids: str) -> str:
    return f"{_DOCUMENT_START}{grids}{_DOCUMENT_END}"


def add_step_views(h5: h5py.File, first: int, stop: int, *, existing: bool = False) -> None:
    """Virtual datasets /dynamic/xdmf/displacement/<k> = /dynamic/mesh_displacement[k] for
    frames first <= k < stop, and /dynamic/xdmf/position/0 = /dynamic/mesh_nodes[0] (the
    geometry meshio reads) with the first frame, each with its source's ``units``: the
    items of a series too large to carry inline (:func:`inline`). The dynamic writer calls
    this at each flush, so the cost (~0.15 ms of CPU per view, most of it inside HDF5) is
    spread over the run and a stopped run does not wait for it. (h5py's
    low-level API: its high-level VirtualLayout took ~1 ms per view.) ``existing``: some of
    the views may exist already (an older file): their names are listed once, not looked
    up per view."""
    for source, name, last in (("dynamic/mesh_nodes", "position", 1),
                               ("dynamic/mesh_displacement", "displacement", stop)):
        if source not in h5:
            continue
        data = h5[source]
        shape = data.shape
        stop_here = min(last, stop, shape[0])
        if stop_here <= first:
            continue
        group = h5.require_group(f"{_STEPS_GROUP}/{name}")
        made = set(group) if existing and len(group) else set()
        todo = [k for k in range(first, stop_here) if str(k) not in made]
        if not todo:
            continue
        selection = h5s.create_simple(shape)
        view_space = h5s.create_simple(shape[1:])
        dtype = data.id.get_type()
        text = h5py.string_dtype()
        text_type = h5t.py_create(text, logical=True)
        scalar = h5s.create(h5s.SCALAR)
        units = np.array(data.attrs.get("units", "m"), dtype=text)
        count = (1, *shape[1:])
        source_name = ("/" + source).encode()
        for k in todo:
            selection.select_hyperslab((k,) + (0,) * (len(shape) - 1), count)
            plist = h5p.create(h5p.DATASET_CREATE)
            plist.set_virtual(view_space, b".", source_name, selection)
            view = h5d.create(group.id, str(k).encode(), dtype, view_space, dcpl=plist)
            h5a.create(view, b"units", text_type, scalar).write(units)


def _values(values: np.ndarray) -> str:
    """An inline ``Format="XML"`` item of float64 values: each the shortest decimal text
    that reads back as the same double (meshio and ParaView parse it with strtod)."""
    dims = " ".join(map(str, values.shape))
    text = " ".join(map(repr, values.ravel().tolist()))
    return (f'<DataItem Dimensions="{dims}" NumberType="Float" Precision="8" Format="XML">'
            f"{text}</DataItem>")


def _row_item(k: int, rows: int, npoints: int, h5_name: str, dataset: str) -> str:
    """A HyperSlab item: row k of the (rows, npoints, 3) dataset (start, stride, count)."""
    return (f'<DataItem ItemType="HyperSlab" Dimensions="1 {npoints} 3">'
            f'<DataItem Dimensions="3 3" NumberType="Int" Format="XML">{k} 0 0 1 1 1 1 '
            f'{npoints} 3</DataItem>{_item((rows, npoints, 3), h5_name, dataset)}</DataItem>')


def _topology_of(h5: h5py.File) -> tuple[str, tuple[int, ...], str, int, int]:
    """(type, dims, dataset, ncells, npoints) of the file's mesh: /model/mesh, or for
    files written before it the plates' /model/elements and /model/nodes."""
    if "model/mesh" in h5:
        group = h5["model/mesh"]
        return (str(group.attrs["topology_type"]), group["topology"].shape, "/model/mesh/topology",
                int(group.attrs["ncells"]), len(group["points"]))
    shape = h5["model/elements"].shape
    return "Quadrilateral", shape, "/model/elements", shape[0], len(h5["model/nodes"])


@record(eq=False, repr=False)
class Series:
    """What the XDMF description of a dynamic run names: its frames (output rows and
    times), its mesh and which per-point series the file holds."""

    rows: np.ndarray          # the output row of each frame
    times: np.ndarray         # (nframes,) s
    stored: int               # the rows of /dynamic/mesh_nodes (>= the frames)
    topology: tuple[str, tuple[int, ...], str, int, int]   # see _topology_of
    displacement: bool        # /dynamic/mesh_displacement
    stress_points: bool       # /dynamic/mesh_von_mises_max
    #: a small series' first points (npoints, 3) and displacements (nframes, npoints, 3),
    #: written inline (:func:`inline`); None: named as per-frame views
    values: tuple[np.ndarray, np.ndarray | None] | None = None

    @classmethod
    def of(cls, h5: h5py.File) -> "Series":
        """The series of an open result file: a small one with its values, a larger one
        after making the per-frame views its writer has not made (a run stopped between
        flushes, an older file)."""
        times = h5["dynamic/time"]
        nodes = h5["dynamic/mesh_nodes"]
        stored, npoints = nodes.shape[0], nodes.shape[1]
        rows = h5["dynamic/mesh_rows"][()] if "dynamic/mesh_rows" in h5 else np.arange(stored)
        nframes = min(stored, int(np.searchsorted(rows, len(times))))
        rows = rows[:nframes]
        displacement = "dynamic/mesh_displacement" in h5
        values = None
        if inline(npoints, nframes):
            values = (nodes[0] if nframes else np.zeros((npoints, 3)),
                      h5["dynamic/mesh_displacement"][:nframes] if displacement else None)
        else:
            add_step_views(h5, 0, nframes, existing=True)
        return cls(rows, times[()][rows] if nframes else np.zeros(0), stored, _topology_of(h5),
                   displacement, "dynamic/mesh_von_mises_max" in h5, values)

    def xml(self, h5_name: str) -> Iterator[str]:
        """The XDMF 3 text in pieces, to be written one after the other: a temporal
        collection of one uniform grid per frame, built as text (an ElementTree of the same
        grids took ~0.2 ms per frame to build and write; the whole text joined, with its
        copies, was ~0.6 MB of a small run's peak). ``h5_name``: the HDF5 file's name,
        already checked for ``:``."""
        kind, dims, topology_data, ncells, npoints = self.topology
        name = _escape(h5_name)
        topology = _topology_xml(kind, ncells, dims, name, topology_data)
        stress = ""
        if self.stress_points:  # the run's von Mises envelope at the beam nodes (Pa)
            stress = ('<Attribute Name="von_mises_max" AttributeType="Scalar" Center="Node">'
                      f'{_item((npoints,), name, "/dynamic/mesh_von_mises_max")}</Attribute>')
        yield (f'{_DOCUMENT_START}<Grid Name="motion" GridType="Collection" '
               'CollectionType="Temporal">')
        for k, (row, time) in enumerate(zip(self.rows, self.times)):
            motion = ""
            if self.displacement:
                shift = _values(self.values[1][k]) if self.values is not None else \
                    _item((npoints, 3), name, f"/{_STEPS_GROUP}/displacement/{k}")
                motion = ('<Attribute Name="displacement" AttributeType="Vector" '
                          f'Center="Node">{shift}</Attribute>')
            if k > 0:
                where = _row_item(k, self.stored, npoints, name, "/dynamic/mesh_nodes")
            elif self.values is not None:
                where = _values(self.values[0])
            else:
                where = _item((npoints, 3), name, f"/{_STEPS_GROUP}/position/0")
            yield (f'\n<Grid Name="step {row}" GridType="Uniform"><Time Value="{time:.17g}"/>'
                   f'{topology}<Geometry GeometryType="XYZ">{where}</Geometry>'
                   f"{motion}{stress}</Grid>")
        yield f"\n</Grid>{_DOCUMENT_END}"


def xdmf_target(path: Path, as_name: Path | None = None) -> Path:
    """The HDF5 file name the XDMF beside ``path`` names (``as_name`` when the file is
    about to be moved there); refused with ':' in it (XDMF's ``file:/path`` notation
    cannot express it)."""
    target = Path(as_name) if as_name is not None else Path(path)
    if ":" in target.name:
        raise InputError("XDMF cannot name an HDF5 file with ':' in its name", file=str(path))
    return target


def write_series(series: Series, target: Path) -> Path:
    """The XDMF file of ``series`` beside ``target`` (the HDF5 file it names)."""
    out = target.with_suffix(".xdmf")
    with replace_atomically(out, "w", encoding="utf-8") as fh:
        fh.writelines(series.xml(target.name))
    return out


def write_xdmf(path: Path, as_name: Path | None = None) -> Path:
    """An XDMF file beside the HDF5 result of a dynamic run: one grid per frame at the
    points' positions of that step, with their displacement from t = 0; opens in ParaView
    as a time series. ``as_name``: the name the HDF5 file will have (it is about to be
    moved there); the XDMF is written beside that name and refers to it."""
    target = xdmf_target(path, as_name)
    with h5py.File(path, "a") as h5:
        series = Series.of(h5)
    return write_series(series, target)


def write_mode_xdmf(path: Path, group: str, as_name: Path | None = None) -> Path:
    """An XDMF file beside the HDF5 result of a modal or buckling analysis: one grid (the
    mesh at the static state the analysis linearized about, ``/<group>/mesh_static``) with
    one vector attribute per mode, ``mode_1``, ``mode_2``, ... (``/<group>/xdmf/mode_<k>``,
    each scaled to a largest displacement of 1): in ParaView, Warp By Vector with a mode
    shows its shape."""
    with h5py.File(path, "r") as h5:
        modes = sorted((k for k in h5[f"{group}/xdmf"]), key=lambda k: int(k.split("_")[1]))
    return _one_grid(path, f"{group} shapes", f"/{group}/mesh_static",
                     [(mode, f"/{group}/xdmf/{mode}") for mode in modes], as_name)


def write_static_xdmf(path: Path, as_name: Path | None = None) -> Path:
    """An XDMF file beside the HDF5 result of a static analysis: one grid, the mesh at the
    static state (``/static/mesh_nodes``), with its ``displacement`` from the undeformed
    mesh (``/static/mesh_displacement``)."""
    return _one_grid(path, "static state", "/static/mesh_nodes",
                     [("displacement", "/static/mesh_displacement")], as_name)


def write_any_xdmf(path: Path, as_name: Path | None = None) -> Path | None:
    """The XDMF a result file's run writes, by what the file holds: the motion of a
    dynamic run (:func:`write_xdmf`), else the shapes of a modal or buckling analysis
    (:func:`write_mode_xdmf`), else the static state (:func:`write_static_xdmf`); None
    when it holds none of them (no mesh)."""
    with h5py.File(path, "r") as h5:
        if "model/mesh" not in h5 and "model/elements" not in h5:
            return None
        motion = "dynamic/mesh_nodes" in h5 and "dynamic/time" in h5
        eigen = next((g for g in ("modal", "buckling") if f"{g}/xdmf" in h5), None)
        static = "static/mesh_displacement" in h5
    if motion:
        return write_xdmf(path, as_name)
    if eigen is not None:
        return write_mode_xdmf(path, eigen, as_name)
    return write_static_xdmf(path, as_name) if static else None


def _one_grid(path: Path, title: str, geometry_data: str,
              attributes: list[tuple[str, str]], as_name: Path | None) -> Path:
    """An XDMF file of one uniform grid: the file's mesh at the points ``geometry_data``
    with a vector attribute per (name, dataset)."""
    path = Path(path)
    name = Path(as_name) if as_name is not None else path
    if ":" in name.name:
        raise InputError("the file name must not contain ':' (XDMF cannot name it)",
                         file=str(name))
    with h5py.File(path, "r") as h5:
        kind, dims, topology, ncells, npoints = _topology_of(h5)
    h5_name = _escape(name.name)
    parts = [f'<Grid Name="{_escape(title)}" GridType="Uniform">',
             _topology_xml(kind, ncells, dims, h5_name, topology),
             '<Geometry GeometryType="XYZ">'
             f'{_item((npoints, 3), h5_name, geometry_data)}</Geometry>']
    for label, dataset in attributes:
        parts.append(f'<Attribute Name="{_escape(label)}" AttributeType="Vector" Center="Node">'
                     f'{_item((npoints, 3), h5_name, dataset)}</Attribute>')
    parts.append("</Grid>")
    out = name.with_suffix(".xdmf")
    write_text(out, _document("\n".join(parts)))
    return out
