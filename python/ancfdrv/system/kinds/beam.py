"""The beam kind: ANCF beams (floating-frame 'ffr' or large-deformation 'nonlinear',
bending 'continuum' or 'cubic'), the namelist group &beam and ``System.beam``. The kind's
whole Python side: the body, its keys, its element sets (kernel set kinds 'ffr',
'continuum', 'cubic') and their kernel adders, its registration (:mod:`..registry`).
"""
from __future__ import annotations

import numpy as np

from ... import kernel
from ...errors import InputError
from ...gauss import leggauss
from ...io import validate
from ...io.schema import (GEOMETRIC_STIFFNESS_DOC, MODES_DOC, Key, at_least, name_key,
                          non_negative, one_of,
                          positive, vector3)
from ..bodies import (VECTOR_OFFSETS, Attachment, Body, Material, _vec, along_axis,
                      axis_stations, check_axis_dimensions)
from ..expressions import Vec3
from ..model import SetInfo
from ..registry import Kind, SetContext, checked_values, register
from ..sections import Rectangle, Section, section_name_problem, section_of

BEAM_NODE_DOFS = 12
FORMULATIONS = ("ffr", "nonlinear")
BENDING = ("continuum", "cubic")


class Beam(Body):
    """A straight ANCF beam from ``start`` to ``end`` with ``nodes`` nodes (equally spaced, or
    equally within each of ``segments``, whose lengths add up to the beam's), section
    height along ``height_axis`` (default global z; y for a beam along z), formulation
    'ffr' (small strain in a floating frame) or 'nonlinear' (large deformation), bending
    'continuum' or 'cubic'. Its frame is the body frame (axis, height, width directions) at
    t = 0, turned by ``frame_drive`` about ``frame_axis`` through ``frame_pivot`` (default:
    the start) when given: for 'ffr' the elastic model lives in it, for either formulation
    probe deflections are resolved in it. ``geometric_stiffness`` (for 'ffr'): the
    geometric stiffness of the current axial force (P-delta, docs/theory.md, 'FFR geometric stiffness').
    ``modes`` (for 'ffr', dynamic runs): 0 integrates every coordinate, N > 0 the modal
    reduction with N modes (:mod:`ancfdrv.solvers.ffr_reduced`)."""

    flexible = True
    response_component = 1
    section_directors = ("r_y", "r_z")

    @property
    def floating(self) -> bool:
        """Formulation 'ffr': small strain in its floating frame."""
        return self.formulation == "ffr"

    @property
    def framed(self) -> bool:
        """Always: its body frame (turned by ``frame_drive`` when given)."""
        return True

    @property
    def nnodes(self) -> int:
        return self.nodes

    @property
    def mesh_nodes(self) -> int:
        return self.nodes

    @property
    def extent(self) -> float:
        return self.length

    def __init__(self, name: str, material: Material, start, end, nodes: int,
                 section: Section | None = None, *, height_axis=None, formulation: str = "ffr",
                 bending: str = "continuum", segments=None, frame_drive=None,
                 frame_axis=(0.0, 0.0, 1.0), frame_pivot=None,
                 geometric_stiffness: bool = False, modes: int = 0) -> None:
        self.name = name
        self.geometric_stiffness = bool(geometric_stiffness)
        if not isinstance(modes, (int, np.integer)) or isinstance(modes, bool) or modes < 0:
            raise InputError(f"beam {name!r}: modes = {modes!r} must be an integer >= 0")
        self.modes = int(modes)
        where = f"beam {name!r}"
        self.material = material
        self.start, self.end = _vec(start, "start", where), _vec(end, "end", where)
        axis = self.end - self.start
        self.length = float(np.linalg.norm(axis))
        if self.length <= 0.0:
            raise InputError(f"{where}: start and end coincide")
        if not isinstance(nodes, (int, np.integer)) or nodes < 2:
            raise InputError(f"{where}: nodes = {nodes!r} must be an integer >= 2")
        if formulation not in FORMULATIONS:
            raise InputError(f"{where}: formulation {formulation!r} must be one of {FORMULATIONS}")
        if bending not in BENDING:
            raise InputError(f"{where}: bending {bending!r} must be one of {BENDING}")
        self.nodes, self.formulation, self.bending = int(nodes), formulation, bending
        self.section = section if section is not None else Rectangle(0.1, 0.1)
        self.section.data  # validates the dimensions now  # noqa: B018
        tangent = axis / self.length
        if height_axis is None:
            height_axis = (0.0, 1.0, 0.0) if abs(tangent[2]) > 1.0 - 1e-12 else (0.0, 0.0, 1.0)
        h = _vec(height_axis, "height_axis", where)
        h = h - (h @ tangent) * tangent
        if np.linalg.norm(h) < 1e-9:
            raise InputError(f"{where}: height_axis is parallel to the beam axis")
        h /= np.linalg.norm(h)
        self.orientation = np.column_stack([tangent, h, np.cross(tangent, h)])
        self.stations = axis_stations(self.length, self.nodes, segments, where)
        self.lengths = self.stations[1:] - self.stations[:-1]   # (np.diff's values)
        self.frame_drive = frame_drive
        self.frame_axis = _vec(frame_axis, "frame_axis", where)
        if np.linalg.norm(self.frame_axis) == 0.0:
            raise InputError(f"{where}: frame_axis must not vanish")
        self.frame_pivot = self.start.copy() if frame_pivot is None else \
            _vec(frame_pivot, "frame_pivot", where)


    # -- geometry ---------------------------------------------------------------------------
    @property
    def nel(self) -> int:
        return self.nodes - 1

    @property
    def ncoordinates(self) -> int:
        return BEAM_NODE_DOFS * self.nodes

    def node_positions(self) -> np.ndarray:
        return self.start + np.outer(self.stations, self.orientation[:, 0])

    def coordinates(self) -> np.ndarray:
        q = np.zeros((self.nodes, BEAM_NODE_DOFS))
        q[:, 0:3] = self.node_positions()
        q[:, 3:12] = self.orientation.T.ravel()
        return q.ravel()

    def element_dofs(self) -> np.ndarray:
        """(24, nel) full coordinates of every element (after numbering)."""
        return self.first + np.array([np.arange(24) + BEAM_NODE_DOFS * el
                                      for el in range(self.nel)]).T

    def node_first(self, node: int, which: str = "r") -> int:
        return self.first + BEAM_NODE_DOFS * node + VECTOR_OFFSETS[which]

    # -- attachments ------------------------------------------------------------------------
    def locate(self, point, *, node: bool, what: str) -> Attachment:
        p = _vec(point, "point", what)
        rel = p - self.start
        s = float(rel @ self.orientation[:, 0])
        y = float(rel @ self.orientation[:, 1])
        z = float(rel @ self.orientation[:, 2])
        tol = 1e-6 * self.length
        half_y, half_z = self.section.extent
        if s < -tol or s > self.length + tol or abs(y) > half_y + tol or abs(z) > half_z + tol:
            raise InputError(f"{what}: point {list(p)} is not a material point of beam "
                             f"{self.name!r} (axis from {list(self.start)} to {list(self.end)})")
        nearest = int(np.argmin(np.abs(self.stations - s)))
        at_node = abs(self.stations[nearest] - s) <= tol and abs(y) <= tol and abs(z) <= tol
        if node and not at_node:
            raise InputError(f"{what}: point {list(p)} is not a node of beam {self.name!r} "
                             f"(nearest node at {list(self.node_positions()[nearest])})")
        s = min(max(s, 0.0), self.length)
        element = min(int(np.searchsorted(self.stations, s, side="right")) - 1, self.nel - 1)
        xi = (s - self.stations[element]) / self.lengths[element]
        return Attachment(nearest if at_node else None, element, (xi, y, z))

    def position(self, at: Attachment) -> Vec3:
        if at.node is not None:
            return Vec3.of(self.node_first(at.node))
        xi, y, z = at.local
        shape, *_ = kernel.beam_shape([xi], [y], [z], [self.lengths[at.element]])
        first = self.first + BEAM_NODE_DOFS * at.element
        return Vec3({first + 3 * a: float(shape[a, 0]) for a in range(8) if shape[a, 0] != 0.0})

    def vector(self, at: Attachment, which: str) -> Vec3:
        """A nodal vector at a node; between nodes or off the axis the same gradient of the
        position field at the material point (through the shape functions: r_x = dr/dx,
        r_y = dr/dy, r_z = dr/dz there; r_y and r_z interpolate the two nodes' directors)."""
        if at.node is not None:
            return Vec3.of(self.node_first(at.node, which))
        if which == "r":
            return self.position(at)
        xi, y, z = at.local
        derivs = kernel.beam_shape([xi], [y], [z], [self.lengths[at.element]])
        weights = derivs[VECTOR_OFFSETS[which] // 3][:, 0]
        first = self.first + BEAM_NODE_DOFS * at.element
        return Vec3({first + 3 * a: float(weights[a]) for a in range(8) if weights[a] != 0.0})

    def basis(self, at: Attachment) -> list[Vec3]:
        return [self.vector(at, w) for w in ("r_x", "r_y", "r_z")]

    def held_vectors(self, at: Attachment) -> list[str]:
        return ["r_y", "r_z"]  # the cross-section (a section clamp); r_x may shear and stretch

    def directors(self, at: Attachment) -> list[str]:
        return list(self.section_directors)

    # -- what the assembly asks of a flexible body besides its set ---------------------------
    def point_mass(self, at: Attachment, mass: float) -> np.ndarray:
        """A point mass's share of its element's compact mass matrix."""
        return kernel.beam_point_mass(*at.local, self.lengths[at.element], mass)

    def gravity_forces(self, g: np.ndarray) -> np.ndarray:
        """Generalized gravity forces per element (24, nel) of the acceleration g (3,)."""
        return kernel.beam_gravity(self.lengths, *self.section.mass_rule(self.material.density),
                                   g)

    def torsion_shares(self) -> tuple[float, float]:
        """How a torque about the axis divides between the directors r_y and r_z when the
        section turns without shearing: halves with 'cubic' bending (its twist is
        (r_y,x . r_z - r_z,x . r_y)/2); in the continuum element r_y's turn shears the fibres
        at distance y (along the height) and r_z's those at distance z, so int y^2 dA / J
        and int z^2 dA / J."""
        if self.bending == "cubic":
            return 0.5, 0.5
        data = self.section.data
        return data.inertia_z / data.polar, data.inertia_y / data.polar

    def moment_attachments(self, point, what: str) -> list[tuple[Attachment, float]]:
        """At a node, or between nodes the two nodes of its element in the shares
        (1 - xi, xi) by which its directors r_y, r_z interpolate them there (the virtual
        work of the moment on the interpolated section's turn); the point's offset from the
        axis does not matter for a moment."""
        at = self.locate(point, node=False, what=what)
        if at.node is not None:
            return [(at, 1.0)]
        xi = at.local[0]
        nodes = [(at.element, 1.0 - xi), (at.element + 1, xi)]
        return [(Attachment(node, at.element, at.local), w) for node, w in nodes if w > 0.0]


KEYS: dict[str, Key] = {
    "name": name_key(),
    "material": Key("str", doc="name of a &material"),
    "start": Key("floats", check=vector3, doc="start of the neutral axis (m)"),
    "end": Key("floats", check=vector3, doc="end of the neutral axis (m)"),
    "nodes": Key("int", check=at_least(2), doc="nodes on the beam (>= 2)"),
    "segments": Key("floats", None, doc="segment lengths (m) each split equally (keeps "
                    "their ends as nodes); default: one segment"),
    "section": Key("str", "rectangle", section_name_problem,
                   "cross-section: 'rectangle' (width, height), 'box' (width, height, wall), "
                   "'tube' (diameter, wall), 'circle' (diameter), 'general' (area, iy, iz, "
                   "torsion_constant, shear_factor_y, shear_factor_z; optional "
                   "mass_per_length, rotary_inertia, fibre_points), or a standard steel "
                   "section alone: 'IPE80'...'IPE600', 'HEA100'...'HEA600', "
                   "'HEB100'...'HEB600' (EN 10365), 'RHS200x100x8', 'SHS100x5', "
                   "'CHS168.3x8' (EN 10219-2; docs/modelling.md lists the sizes), its web "
                   "along height_axis: iz (bending in the web's plane) is the strong axis"),
    "width": Key("float", None, positive, "section width along r_z (m)"),
    "height": Key("float", None, positive, "section height along r_y (m)"),
    "wall": Key("float", None, positive, "wall thickness of 'box' and 'tube' (m)"),
    "diameter": Key("float", None, positive, "outer diameter of 'tube' and 'circle' (m)"),
    "shear": Key("str", None, one_of("unit", "cowper"), "shear factors of 'rectangle', "
                 "'box', 'tube', 'circle': 'unit' (k = 1, the default) or 'cowper' "
                 "(Cowper 1966, from the section and nu)"),
    "area": Key("float", None, positive, "'general': cross-section area A (m^2)"),
    "iy": Key("float", None, positive, "'general': I_y = int z^2 dA, bending along the "
              "width r_z (m^4)"),
    "iz": Key("float", None, positive, "'general': I_z = int y^2 dA, bending along the "
              "height r_y (m^4)"),
    "torsion_constant": Key("float", None, positive, "'general': Saint-Venant torsion "
                            "constant J (m^4)"),
    "shear_factor_y": Key("float", None, positive, "'general': shear factor k_y (shear "
                          "stiffness k_y G A along the height)"),
    "shear_factor_z": Key("float", None, positive, "'general': shear factor k_z (along the "
                          "width)"),
    "mass_per_length": Key("float", None, positive, "'general', optional: mass per unit "
                           "length (kg/m; default density * area)"),
    "rotary_inertia": Key("floats", None, vector3, "'general', optional: r_x, r_y, r_z, "
                          "rotary inertia per unit length about the axis, the height and "
                          "the width axes (kg m; r_x = r_y + r_z; default density * (iy + "
                          "iz, iy, iz))"),
    "fibre_points": Key("floats", None, doc="'general', optional: outer-fibre points y1, "
                        "z1, y2, z2, ... in the section (m) for stresses (default: the "
                        "corners of the rectangle of the same A, I_y, I_z)"),
    "height_axis": Key("floats", None, vector3, "direction of the section height "
                       "(default: global z, or y for a beam along z)"),
    "formulation": Key("str", None, one_of("ffr", "nonlinear"),
                       "'ffr' or 'nonlinear' (default: the scene's)"),
    "bending": Key("str", "continuum", one_of("continuum", "cubic"), "bending option"),
    "geometric_stiffness": Key("bool", False, doc=GEOMETRIC_STIFFNESS_DOC),
    "modes": Key("int", 0, non_negative, MODES_DOC),
    "frame_drive": Key("str", None, doc="drive turning the beam's frame (FFR: the "
                       "floating frame; both: the frame of the probe deflections)"),
    "frame_axis": Key("floats", [0.0, 0.0, 1.0], vector3, "axis of the frame's turn"),
    "frame_pivot": Key("floats", None, vector3, "point of the frame's axis (default: start)"),
}


def build(system, v: dict) -> Beam:
    """A beam from the values of ``System.add('beam', ...)``."""
    section = section_of(v, f"beam[{v['name']}]")
    name = system._body_name(v["name"])
    where = f"beam {name!r}"
    v = checked_values(KIND, f"beam[{name}]", v)
    system._check_size(part_of(name, v["nodes"]))
    return system._add_body(Beam(
        name, system._material(v["material"], where), v["start"], v["end"], v["nodes"],
        section, height_axis=v.get("height_axis"), formulation=v.get("formulation") or "ffr",
        bending=v.get("bending", "continuum"), segments=v.get("segments"),
        frame_drive=system._drive(v.get("frame_drive"), where),
        frame_axis=v.get("frame_axis", (0.0, 0.0, 1.0)), frame_pivot=v.get("frame_pivot"),
        geometric_stiffness=v.get("geometric_stiffness", False), modes=v.get("modes", 0)))


def part_of(name: str, nodes: int) -> validate.Part:
    """A beam's share of the memory estimate."""
    return validate.Part(f"beam[{name}]", "nodes", "beam", nodes, BEAM_NODE_DOFS, sections=True)


def _beam_set(beam: Beam, context: SetContext) -> SetInfo:
    frame, frame_id = context.frame, context.frame_id
    dofs = beam.element_dofs()
    local = dofs - beam.first
    q = beam.coordinates()
    rotation0 = frame.rotation(0.0)
    frame_q = (q.reshape(-1, 3) @ rotation0).ravel()       # A0^T v for every 3-vector
    positions = q.reshape(-1, 4, 3)[:, 0, :] - frame.pivot
    frame_q.reshape(-1, 4, 3)[:, 0, :] = positions @ rotation0
    section = beam.section.data
    m = beam.material
    frame_ref = frame_q[local].reshape(3, 8, beam.nel, order="F")
    global_ref = q[local].reshape(3, 8, beam.nel, order="F")
    # torsion constant J and shear factors of the section (docs/theory.md, "Sections")
    shear_scales = beam.section.shear_scales(m.poisson_ratio)
    torsion = beam.section.torsion_constant
    shear_factors = beam.section.shear_factors(m.poisson_ratio)
    mass_compact, stiffness0 = kernel.beam_element_arrays(
        beam.lengths, section, m.density, m.youngs_modulus, m.poisson_ratio, frame_ref,
        shear_scales)
    mass_rule, mass_density = beam.section.mass_rule(m.density)
    if mass_rule is not section:   # a general section's own mass and rotary inertia
        mass_compact, _ = kernel.beam_element_arrays(
            beam.lengths, mass_rule, mass_density, m.youngs_modulus, m.poisson_ratio, frame_ref)
    info = SetInfo(body=beam, kind="", dofs=dofs, nel=beam.nel, frame=frame_id,
                   mass_compact=mass_compact)
    if beam.formulation == "ffr":
        info.kind, info.floating = "ffr", True
        if beam.bending == "cubic":  # K0: the cubic tangent at the reference, in the frame
            cubic = kernel.CubicBeam(frame_ref, beam.lengths, section, m.youngs_modulus,
                                     m.poisson_ratio, torsion, shear_factors)
            *_, stiffness0 = cubic.forces(local, frame_q, True)
        info.stiffness0 = np.asfortranarray(stiffness0)
        info.reference = np.asfortranarray(frame_q[local])
        if beam.geometric_stiffness:
            info.second_order = ffr_second_order_data(frame_ref, beam.lengths,
                                                      m.youngs_modulus * beam.section.area)
    elif beam.bending == "cubic":
        info.kind = "cubic"
        info.cubic = kernel.CubicBeam(global_ref, beam.lengths, section, m.youngs_modulus,
                                      m.poisson_ratio, torsion, shear_factors)
    else:
        info.kind = "continuum"
        info.gradients, info.weights, info.nvolume = kernel.beam_nonlinear_setup(
            global_ref, beam.lengths, section)
        info.shear_scales = shear_scales
    return info



def ffr_second_order_data(frame_ref: np.ndarray, lengths: np.ndarray, axial_rigidity: float
                          ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The per-element data of the FFR geometric stiffness (ffr_elastic module doc): EA,
    the unit axis in the frame (from the reference r_A to r_B, frame_ref (3, 8, nel)), the
    length and G_ab = int S_a' S_b' dx over the centre-line shape functions (N1, L N2, N3,
    L N4 on the slots r_A, r_xA, r_B, r_xB; 3-point Gauss, exact for the degree-4 integrand)."""
    nel = len(lengths)
    chord = frame_ref[:, 4, :] - frame_ref[:, 0, :]
    axis = chord / np.linalg.norm(chord, axis=0)
    points, weights = leggauss(3)
    xi, w = 0.5 * (points + 1.0), 0.5 * weights
    # d/dxi of N1, N2, N3, N4 (cubic Hermite)
    dn = np.array([-6 * xi + 6 * xi**2, 1 - 4 * xi + 3 * xi**2, 6 * xi - 6 * xi**2,
                   3 * xi**2 - 2 * xi])
    gram = np.zeros((8, 8, nel))
    for el, length in enumerate(lengths):
        ds = np.zeros((8, len(xi)))
        ds[[0, 1, 4, 5]] = dn * np.array([1.0, length, 1.0, length])[:, None]
        # int_0^L (dS_a/dx)(dS_b/dx) dx = (1/L) int_0^1 (dS_a/dxi)(dS_b/dxi) dxi
        gram[:, :, el] = (ds * w) @ ds.T / length
    return (np.full(nel, float(axial_rigidity)), np.asfortranarray(axis),
            np.asarray(lengths, dtype=float), np.asfortranarray(gram))


def _add_ffr(ks: kernel.KernelSystem, s: SetInfo) -> int:
    index = ks.add_ffr_set(s.dofs, s.scatter, s.stiffness0, s.reference, s.frame,
                           s.damping_time)
    if s.second_order is not None:
        ks.ffr_second_order(index, *s.second_order)
    _add_sections(ks, index, s, s.reference)   # (its reference is in its frame)
    return index


def _add_continuum(ks: kernel.KernelSystem, s: SetInfo) -> int:
    index = ks.add_continuum_set(s.dofs, s.scatter, s.gradients, s.weights, s.nvolume,
                                 s.body.material.youngs_modulus, s.body.material.poisson_ratio,
                                 s.frame, s.damping_time, s.shear_scales)
    _add_sections(ks, index, s, s.body.coordinates()[s.dofs - s.body.first])
    return index


def _add_cubic(ks: kernel.KernelSystem, s: SetInfo) -> int:
    index = ks.add_cubic_set(s.dofs, s.scatter, *s.cubic.tables(), s.frame, s.damping_time)
    s.cubic.release()   # the kernel's set keeps the forms; the rare later uses remake them
    _add_sections(ks, index, s, s.body.coordinates()[s.dofs - s.body.first])
    return index


def _add_sections(ks: kernel.KernelSystem, index: int, s: SetInfo, reference: np.ndarray
                  ) -> None:
    """The data of the set's section forces (fortran/src/elements/beam_stations.f90): the
    reference nodal vectors (24, nel), the section's stiffnesses (E A, G J, k G A, the
    moments' -E I_y and E I_z) and the bending option."""
    beam = s.body
    data, section, mat = beam.section.data, beam.section, beam.material
    e_mod = mat.youngs_modulus
    g_mod = e_mod / (2.0 * (1.0 + mat.poisson_ratio))
    k_y, k_z = section.shear_factors(mat.poisson_ratio)
    ks.set_sections(index, beam.lengths, np.reshape(reference, (3, 8, s.nel), order="F"),
                    beam.bending == "cubic", axial=e_mod * data.area,
                    torsion=g_mod * section.torsion_constant, shear_y=k_y * g_mod * data.area,
                    shear_z=k_z * g_mod * data.area, moment_height=-e_mod * data.inertia_y,
                    moment_width=e_mod * data.inertia_z, youngs=e_mod,
                    inertia_y=data.inertia_y, inertia_z=data.inertia_z, polar=data.polar)


def _planar_problems(body: Beam, j: int, tol: float) -> list[str]:
    """The planar rule (system/planar.py): the axis in a plane normal to e_j, a section axis
    along e_j, and not 'ffr'."""
    plane = "xyz"[j]
    if abs(float(body.start[j] - body.end[j])) > tol:
        return [f"its axis leaves the plane normal to {plane}"]
    out = []
    if body.formulation == "ffr":
        out.append("formulation 'ffr' keeps its constant iteration matrix by turning whole "
                   "nodal 3-vectors with the frame; it is not reduced (use 'nonlinear', or "
                   "planar = 'off')")
    if not (along_axis(body.orientation[:, 1], j) or along_axis(body.orientation[:, 2], j)):
        out.append(f"no section axis (height or width) lies along {plane}")
    return out


def _planar_fixed(body: Beam, j: int, q0) -> list[tuple[int, str]]:
    """In planar motion normal to e_j every node keeps r_j, r_x,j and the in-plane
    director's j-component, and the normal director's two in-plane components."""
    normal_director = "r_y" if along_axis(body.orientation[:, 1], j) else "r_z"
    inplane_director = "r_z" if normal_director == "r_y" else "r_y"
    out = []
    for node in range(body.nodes):
        tag = f"{body.name}: planar node {node + 1}"
        for which in ("r", "r_x", inplane_director):
            out.append((body.node_first(node, which) + j, f"{tag} {which}"))
        for k in range(3):
            if k != j:
                out.append((body.node_first(node, normal_director) + k,
                            f"{tag} {normal_director}"))
    return out


def _mesh(body: Beam, rows) -> None:
    """XDMF: a 2-node line per element through the node positions r."""
    nodes = rows.node_points(body.first, body.nodes, 12) + np.arange(body.nodes)
    rows.lines.append(np.column_stack([nodes[:-1], nodes[1:]]))


# -- section forces from the elements' equilibrium (static states: system/answers.py) ---
def _end_forces(info: SetInfo, q: np.ndarray,
                rotation: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The beam kind's ``end_forces`` hook: (nel, 8, 3) the elastic force of every element of
    a beam's set on its own eight nodal vectors at the full coordinates q (global axes),
    from the kernel's element routines (each element is handed its own 24 slots, so the
    kernel's sum over the elements leaves them apart), and (nel, 8, 3) the nodal vectors
    the forces act at (an 'ffr' set without geometric stiffness: its reference, turned by
    the frame's rotation; else the coordinates themselves)."""
    beam, nel = info.body, info.nel
    own = np.arange(24 * nel).reshape(nel, 24).T
    e = q[info.dofs].reshape(-1, order="F")
    mat = beam.material
    if info.kind == "cubic":
        force = info.cubic.forces(own, e, False)[0]
    elif info.kind == "continuum":
        force = kernel.beam_nonlinear_forces(own, e, info.gradients, info.weights, info.nvolume,
                                             mat.youngs_modulus, mat.poisson_ratio, False,
                                             info.shear_scales)[0]
    else:
        force = kernel.ffr_force(own, info.stiffness0, rotation, e, info.reference)[0]
        if info.second_order is not None:  # ffr_elastic: f_2 = N (G x I3) u in the frame
            rigidity, axis, length, gram = info.second_order
            u = (e.reshape(nel, 8, 3) @ rotation) - info.reference.T.reshape(nel, 8, 3)
            n = rigidity * np.einsum("ke,ek->e", axis, u[:, 4] - u[:, 0]) / length
            local = n[:, None, None] * np.einsum("abe,ebk->eak", gram, u)
            force = force + (local @ rotation.T).reshape(-1)
    if info.kind == "ffr" and info.second_order is None:   # the reference, turned
        vectors = info.reference.T.reshape(nel, 8, 3) @ rotation.T
    else:
        vectors = q[info.dofs].T.reshape(nel, 8, 3)
    return np.asarray(force).reshape(nel, 8, 3), vectors


def _stress_stiffness(info: SetInfo, q: np.ndarray, dq: np.ndarray
                      ) -> tuple[np.ndarray, np.ndarray] | None:
    """The elements' tangents at the full coordinates q and their initial-stress part for
    the increment dq (each (24, 24, nel)); None for an 'ffr' set (its constant stiffness
    has no initial-stress part the kernel could split off)."""
    own = np.arange(24 * info.nel).reshape(info.nel, 24).T
    e, de = q[info.dofs].reshape(-1, order="F"), dq[info.dofs].reshape(-1, order="F")
    mat = info.body.material
    if info.kind == "cubic":
        return info.cubic.forces(own, e, True)[2], info.cubic.stress_stiffness(own, e, de)
    if info.kind == "continuum":
        args = (info.gradients, info.weights, info.nvolume, mat.youngs_modulus,
                mat.poisson_ratio)
        tangent = kernel.beam_nonlinear_forces(own, e, *args, True, info.shear_scales)[2]
        return tangent, kernel.beam_nonlinear_stress_stiffness(own, e, de, *args,
                                                               info.shear_scales)
    return None


KIND = register(Kind(
    group="beam", body_class=Beam, keys=KEYS, build=build, api="beam", word="beam",
    objects=("material", "section", "frame_drive"), scene_defaults={"formulation": "formulation"},
    set_builder=_beam_set,
    adders={"ffr": _add_ffr, "continuum": _add_continuum, "cubic": _add_cubic},
    part=lambda body: part_of(body.name, body.nodes),
    check_dimensions=lambda body: check_axis_dimensions(body, "beam"),
    plane=lambda body, j: float(body.start[j]), planar_problems=_planar_problems,
    planar_fixed=_planar_fixed, mesh=_mesh, mesh_order=1, sections=True,
    end_forces=_end_forces, stress_stiffness=_stress_stiffness))
