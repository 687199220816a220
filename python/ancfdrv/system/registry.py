"""The registry of kinds: one :class:`Kind` record per kind of item a system is made of (the
beam, the cable and rope, the plate, the leaf, the rigid body, the force element), each
declared by its own module in :mod:`.kinds` (no kind module imports another). Generic code
(the System, the assembly, the model, the planar reduction, the writers, the answers) asks
the registry about a body (:func:`kind_of`) or walks the kinds (:func:`kinds`), never the
concrete class.

A kind declares

- its namelist group and keys (``group``, ``keys``: the io/schema.py :class:`Key` of each; the
  general scene schema is assembled from them, :func:`register` hands them to
  :func:`ancfdrv.io.schema.register_group`, so each key is spelled once), its API entry
  (``api``: the System method, a thin wrapper over ``System.add(group, **values)``), the
  builder of its item from checked values (``build(system, values)``) and where the System
  keeps its items (``table``);
- its body class (``body_class``);
- a *set builder* ``set_builder(body, context) -> SetInfo`` (the element dofs, the element
  masses as compact (n, n, nel) matrices of the scalar shape functions, and whatever the
  kernel's set needs) and a *kernel adder* per set kind it builds (``adders``: ``add(kernel_system,
  info) -> int``, the set's index); a body whose kind builds no set has no elements (a
  rigid body);
- the size estimate of a body (``part``), its dimension check (``check_dimensions``) and the
  effects a body belongs to by itself (``effects``);
- its planar rule (:mod:`.planar`): the plane a body lies in (``plane``), what keeps it
  from staying in a plane (``planar_problems``) and the coordinates a plane fixes
  (``planar_fixed``); a kind without a rule is not reduced (a plate, a leaf);
- whether its bodies report section forces and stresses at stations (``sections``: the
  answers, :mod:`.answers`, and the dynamic run's recorder of them);
- its elements' end forces at a static state (``end_forces``: the section forces from the
  elements' equilibrium, :mod:`.answers`) and their initial-stress stiffness
  (``stress_stiffness``: the classical linear buckling's geometric stiffness);
- its axial force along the body (``axial_forces``: a cable's and a rope's tension, which
  the dynamic run's recorder of the answers keeps per row);
- its mesh rows (``mesh``: the points and cells the XDMF writer shows for a body, through
  the writer's row builder, ``mesh_order``: the kinds' order in the mesh).

What a body answers about itself (its size, its nodes, its mid-surface, the probe component
a sweep compares, whether it floats in a frame and has a frame of its own, its section's
directors, where a moment on it acts, its bending option and modal reduction) is a property
of its class (:class:`~.bodies.Body`): the assembly, the joints, the supports and the writers
ask it instead of testing its class. A dynamic state's section forces are still re-derived
for beams in numpy (:mod:`.answers`, which still tests a beam's formulation:
tests/test_kinds_registry.py counts those checks and only lets the count go down).

Each family of elements is one Fortran module (an extension of ``element_set`` in
``fortran/src/system/element_sets.f90``, built by one ``system_add_<kind>_set`` routine)
plus one Python module in :mod:`.kinds`.
"""
from __future__ import annotations

from collections import Counter
from dataclasses import field
from typing import Any, Callable

from ..records import record
from ..io.schema import Key, check_call, register_group

__all__ = ["Kind", "SetContext", "register", "kinds", "kind", "kind_of", "checked_values",
           "set_builder", "add_to_kernel", "reports_sections", "axial_forces"]


@record(eq=False)
class SetContext:
    """What a set builder may need besides its body: the body's floating frame (FrameInfo,
    or None) and its 1-based id (0: none), the active effects, the counters and warnings."""

    frame: Any = None
    frame_id: int = 0
    active: set[str] = field(default_factory=set)
    counters: Counter = field(default_factory=Counter)
    warnings: list[str] = field(default_factory=list)


@record(frozen=True, eq=False)
class Kind:
    """One kind of item (see the module documentation)."""

    #: the namelist group (&beam) and System.add's group name
    group: str
    #: the class of its items
    body_class: type
    #: the namelist keys of the group (the general schema's)
    keys: dict[str, Key]
    #: ``build(system, values) -> item``: the item from the values of one System.add call
    #: (checked with the keys), added to the system
    build: Callable[[Any, dict[str, Any]], Any]
    #: the System method of the kind (a wrapper over System.add)
    api: str
    #: the System's table of its items (``System.bodies``, ``System.force_elements``)
    table: str = "bodies"
    #: keywords the Python API takes besides the namelist keys
    api_keys: tuple[str, ...] = ()
    #: keys whose value the Python API may give as an object instead of a name or a shape
    #: (a Material, a Drive, a Section, a body): checked with their key only as a string
    objects: tuple[str, ...] = ()
    #: namelist keys whose default (None) is a key of &scene (``formulation``)
    scene_defaults: dict[str, str] = field(default_factory=dict)
    #: the word messages name a body of the kind with ("beam 'arm'")
    word: str = ""
    #: ``set_builder(body, context) -> SetInfo`` (None: no element set)
    set_builder: Callable[[Any, SetContext], Any] | None = None
    #: the kernel adder of each set kind (SetInfo.kind) the set builder makes
    adders: dict[str, Callable[[Any, Any], int]] = field(default_factory=dict)
    #: ``part(body) -> validate.Part``: the body's share of the memory estimate (or None)
    part: Callable[[Any], Any] | None = None
    #: ``check_dimensions(body)``: its size and section within the physical minima
    check_dimensions: Callable[[Any], None] | None = None
    #: ``effects(body) -> set``: the effects the body itself belongs to ('prestress')
    effects: Callable[[Any], set[str]] | None = None
    #: ``plane(body, j) -> float | None``: the j-coordinate of the plane normal to e_j the
    #: body lies in (None: any, or no planar rule)
    plane: Callable[[Any, int], float | None] | None = None
    #: ``planar_problems(body, j, tol) -> [text]``: what keeps the body from moving in planes
    #: normal to e_j (each text after "body 'name': "); None: the kind is not reduced
    planar_problems: Callable[[Any, int, float], list[str]] | None = None
    #: ``planar_fixed(body, j, q0) -> [(dof, label)]``: the full coordinates that keep their
    #: initial values in planar motion normal to e_j, each with its equation's label
    planar_fixed: Callable[[Any, int, Any], list[tuple[int, str]]] | None = None
    #: ``mesh(body, rows)``: adds the body's points and cells to the XDMF writer's row
    #: builder (``rows.point(terms)``, ``rows.expression(vec3)`` for an affine expression
    #: of q, ``rows.node_points(first, nnodes, stride)``, ``rows.quads``, ``rows.lines``:
    #: results/xdmf.py); None: not shown
    mesh: Callable[[Any, Any], None] | None = None
    #: the kind's place in the mesh (bodies of lower order first, each kind in the model's
    #: order)
    mesh_order: int = 0
    #: its bodies report section forces and stresses at stations (system/answers.py)
    sections: bool = False
    #: ``end_forces(set_info, q, rotation) -> (forces, vectors)``: each element's elastic
    #: force on its own nodal vectors and the vectors it acts at, both (nel, 8, 3), for the
    #: static section forces from the elements' equilibrium (None: the kind has no beam
    #: sections)
    end_forces: Callable[[Any, Any, Any], tuple[Any, Any]] | None = None
    #: ``axial_forces(body, e_rows) -> (nt, npoints)``: the axial force (N, tension positive)
    #: at the body's integration points for full coordinates e_rows (nt, ndof), the tension
    #: series a dynamic run writes (/dynamic/tension; None: the kind carries none)
    axial_forces: Callable[[Any, Any], Any] | None = None
    #: ``stress_stiffness(set_info, q, dq) -> (tangent, initial_stress) | None``: the
    #: elements' tangents at the full coordinates q and their initial-stress part with each
    #: stress replaced by its increment for dq, both (nde, nde, nel) on the element dofs, for
    #: the classical linear buckling (solvers/buckling.py); None (or a None answer for a set
    #: kind): the kind gives no initial-stress part
    stress_stiffness: Callable[[Any, Any, Any], tuple[Any, Any] | None] | None = None


_KINDS: dict[str, Kind] = {}
_BY_CLASS: dict[type, Kind] = {}
_ADDERS: dict[str, Callable[[Any, Any], int]] = {}


def register(kind: Kind) -> Kind:
    """Adds a kind: its group to the general scene schema, its adders to the kernel's."""
    if kind.group in _KINDS:
        raise ValueError(f"kind {kind.group!r} is registered twice")
    _KINDS[kind.group] = kind
    _BY_CLASS[kind.body_class] = kind
    _ADDERS.update(kind.adders)
    register_group(kind.group, kind.keys)
    return kind


def kinds() -> tuple[Kind, ...]:
    """Every registered kind, in registration order."""
    return tuple(_KINDS.values())


def kind(group: str) -> Kind | None:
    """The kind of a namelist group (None: no kind's)."""
    return _KINDS.get(group)


def kind_of(item) -> Kind | None:
    """The kind of an item (its class's, or its nearest registered base's); None for the
    ground and anything no kind declares."""
    for cls in type(item).__mro__:
        if cls in _BY_CLASS:
            return _BY_CLASS[cls]
    return None


def checked_values(kind: Kind, label: str, values: dict[str, Any]) -> dict[str, Any]:
    """The values of one System.add call checked with the kind's keys (the namelist's
    checks and messages, ``io.schema.check_call``); an object given for one of the kind's
    ``objects`` keys passes unchanged, and so do the API's own keywords."""
    plain = {k: x for k, x in values.items() if k in kind.keys and
             (x is None or isinstance(x, str) or k not in kind.objects)}
    return {**values, **check_call(kind.group, label, plain)}


def reports_sections(body) -> bool:
    """Whether the body's kind reports section forces and stresses (``Kind.sections``)."""
    found = kind_of(body)
    return found is not None and found.sections


def axial_forces(body) -> Callable[[Any, Any], Any] | None:
    """The body's kind's axial forces along it (``Kind.axial_forces``), or None."""
    found = kind_of(body)
    return None if found is None else found.axial_forces


def set_builder(body) -> Callable[[Any, SetContext], Any] | None:
    """The set builder of the body's kind, or None."""
    found = kind_of(body)
    return None if found is None else found.set_builder


def add_to_kernel(kernel_system, info) -> int:
    """Hands one assembled set to the kernel; its index there."""
    try:
        add = _ADDERS[info.kind]
    except KeyError:
        raise ValueError(f"no kernel adder registered for element sets of kind {info.kind!r}") \
            from None
    return add(kernel_system, info)
