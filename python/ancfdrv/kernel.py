"""Typed access to the compiled Fortran kernel (the f2py module ``_kernel``).

Every kernel routine returns an error code; the wrappers here turn non-zero codes into
:class:`~ancfdrv.errors.SolverError` / :class:`~ancfdrv.errors.InputError` with a clear
message. Arrays are handed over in Fortran order so f2py does not copy them twice.
"""
from __future__ import annotations

import numpy as np

from .records import record
from . import _kernel
from .codes import (CONTACT_RECORD, DRIVE_HERMITE, DRIVE_TABLE, ENERGY_NAMES, KERNEL_LAYOUTS,
                    POWER_NAMES, SECTION_BOX, SECTION_CIRCLE, SECTION_RECTANGLE, SECTION_TUBE)
from .errors import InputError, SolverError

__all__ = ["beam_element_arrays", "beam_gravity", "beam_shape", "beam_point_mass",
           "ffr_force", "ffr_element_stiffness", "moment_force", "drive_values",
           "SparsePattern", "DirectSolver", "plate_shape", "plate_element_arrays",
           "plate_reference", "plate_forces", "PlateReference", "CubicBeam", "SectionData",
           "section_data", "cable_element_arrays", "cable_shape", "cable_forces",
           "constraint_arrays"]


def _f(a, dtype=np.float64) -> np.ndarray:
    return np.asfortranarray(a, dtype=dtype)


def _pack(prefix: str, dtype=np.float64, **values) -> np.ndarray:
    """The small array of a kernel routine's grouped scalars in the layout ``prefix``
    (codes.KERNEL_LAYOUTS, fortran/src/api/api_support.f90), from its values by name."""
    names = KERNEL_LAYOUTS[prefix]
    if set(values) != set(names):
        raise TypeError(f"layout {prefix!r} takes {names}, got {sorted(values)}")
    return np.array([values[n] for n in names], dtype=dtype)


def _at(prefix: str, name: str) -> int:
    """The 0-based position of ``name`` in the layout ``prefix``."""
    return KERNEL_LAYOUTS[prefix].index(name)


def constraint_arrays(kinds, drives, params, operand_const, term_ptr, term_dof, term_coef,
                      drive_kinds, drive_ptr, drive_data) -> tuple[np.ndarray, np.ndarray]:
    """A constraint set's kernel arrays (1-based indices, the constraints module layout)
    packed as the kernel's constraint routines take them (api_support unpack_constraints):
    the integers [ncon, nterm, ndrive, kinds, drives, term_ptr, term_dof, drive_kinds,
    drive_ptr] and the reals [params (8, ncon), operand_const (6, ncon), term_coef,
    drive_data]."""
    kinds, drives = np.ravel(kinds), np.ravel(drives)
    term_dof, drive_kinds = np.ravel(term_dof), np.ravel(drive_kinds)
    if len(np.ravel(term_coef)) != len(term_dof) or \
            len(np.ravel(drive_ptr)) != len(drive_kinds) + 1:
        raise ValueError("constraint arrays: term_coef and term_dof, or drive_ptr and "
                         "drive_kinds, of inconsistent lengths")
    ints = np.concatenate([[len(kinds), len(term_dof), len(drive_kinds)], kinds, drives,
                           np.ravel(term_ptr), term_dof, drive_kinds, np.ravel(drive_ptr)])
    reals = np.concatenate([np.ravel(params, order="F"), np.ravel(operand_const, order="F"),
                            np.ravel(term_coef), np.ravel(drive_data)])
    return _f(ints, np.int32), _f(reals if reals.size else np.zeros(1))


@record(frozen=True, eq=False, repr=False)
class SectionData:
    """A beam cross-section as the kernel integrates it (beam_section.f90): the quadrature
    points (y along the section height, z along its width) with area weights, and the
    properties A, I_y = int z^2 dA, I_z = int y^2 dA and the polar moment."""

    kind: int
    dims: tuple[float, float, float]
    y: np.ndarray
    z: np.ndarray
    weights: np.ndarray
    area: float
    inertia_y: float
    inertia_z: float
    polar: float


_SECTION_NAMES = {SECTION_RECTANGLE: "rectangle", SECTION_BOX: "box", SECTION_TUBE: "tube",
                  SECTION_CIRCLE: "circle"}


def section_data(kind: int, dims) -> SectionData:
    """The section rule and properties of a section kind (codes.SECTION_*)."""
    dims3 = tuple(float(d) for d in (list(dims) + [0.0, 0.0, 0.0])[:3])
    (npoints, y, z, w, area, iy, iz, polar,
     info) = _kernel.beam_section_data(kind, _f(dims3))
    if info:
        what = _SECTION_NAMES.get(kind, f"kind {kind}")
        raise InputError(f"{what} section with dimensions {list(dims)}: " +
                         ("unknown section kind" if info == 1 else
                          "non-physical dimensions (not positive, or a wall of half the "
                          "section or more)"))
    n = int(npoints)
    return SectionData(kind, dims3, y[:n].copy(), z[:n].copy(), w[:n].copy(), float(area),
                       float(iy), float(iz), float(polar))


def beam_element_arrays(lengths, section: SectionData, density, youngs, poisson, reference,
                        shear_scales=(1.0, 0.0, 0.0)):
    """Compact mass (8, 8, nel) and small-strain stiffness K0 (24, 24, nel) per element.

    ``reference`` is (3, 8, nel): the element's nodal vectors in the floating frame;
    ``shear_scales`` the section's torsion and shear correction [c, d_y, d_z]
    (Section.shear_scales; the default is the plain law).
    """
    mass, stiffness, info = _kernel.beam_element_arrays(
        _f(lengths), _f(section.y), _f(section.z), _f(section.weights), density, youngs, poisson,
        _f(shear_scales), _f(reference))
    if info:
        element, code = divmod(info, 10)
        reason = {1: "unsupported quadrature", 2: "degenerate reference geometry (det J0 <= 0)"}
        raise InputError(f"beam element {element}: {reason.get(code, f'code {code}')}")
    return mass, stiffness


def beam_gravity(lengths, section: SectionData, density, gravity) -> np.ndarray:
    """Generalized gravity (3, 8, nel) per element."""
    force, info = _kernel.beam_gravity(_f(lengths), _f(section.y), _f(section.z),
                                       _f(section.weights), density, _f(gravity))
    if info:
        raise SolverError(f"beam gravity: kernel code {info}")
    return force


def beam_shape(xi, y, z, lengths):
    """Shape functions (8, npts) and derivatives d/dx, d/dy, d/dz at material points."""
    return _kernel.beam_shape_functions(_f(xi), _f(y), _f(z), _f(lengths))


def beam_point_mass(xi, y, z, length, mass) -> np.ndarray:
    """Compact (8, 8) mass of a point mass at a material point of an element."""
    return _kernel.beam_point_mass(xi, y, z, length, mass)


def beam_nonlinear_setup(reference, lengths, section: SectionData):
    """Material gradients (8, 3, npts, nel), weights (npts, nel) and the number of volume
    points of the large-deformation beam's Gauss rule, from the reference configuration
    (3, 8, nel); the remaining points are on the neutral axis and the section's twist
    points (beam_nonlinear)."""
    nsec = len(section.weights)
    npts = int(_kernel.beam_nonlinear_points(nsec))
    gradients, weights, info = _kernel.beam_nonlinear_setup(
        npts, _f(reference), _f(lengths), _f(section.y), _f(section.z), _f(section.weights))
    if info:
        element, code = divmod(info, 10)
        raise InputError(f"beam element {element}: degenerate reference geometry "
                         f"(det J0 <= 0, code {code})")
    naxial = (npts - 8) // (nsec + 1)        # 4 axial points; 4 x 2 twist points
    return gradients, weights, nsec * naxial  # the volume points come first


def beam_nonlinear_forces(dofs, e, gradients, weights, nvolume: int, youngs, poisson,
                          want_tangent: bool, shear_scales=(1.0, 0.0, 0.0)):
    """Large-deformation elastic force, strain energy and element tangents (24, 24, nel);
    ``shear_scales`` the section's torsion and shear correction (default: the plain law)."""
    return _kernel.beam_nonlinear_forces(nvolume, _f(dofs + 1, np.int32), _f(e), gradients,
                                         weights, youngs, poisson, _f(shear_scales),
                                         int(want_tangent))


def beam_nonlinear_stress_stiffness(dofs, e, de, gradients, weights, nvolume: int, youngs,
                                    poisson, shear_scales=(1.0, 0.0, 0.0)) -> np.ndarray:
    """The initial-stress part of the continuum beam's element tangents (24, 24, nel) at e
    with each stress replaced by its increment for the coordinate increment de."""
    return _kernel.beam_nonlinear_stress_stiffness(nvolume, _f(dofs + 1, np.int32), _f(e),
                                                   _f(de), gradients, weights, youngs, poisson,
                                                   _f(shear_scales))


class CubicBeam:
    """Strain forms, reference strains and stiffnesses of the 'cubic' bending option
    (beam_cubic.cubic_setup) for a mesh with reference nodal vectors (3, 8, nel);
    ``torsion`` the Saint-Venant constant J (default: the polar moment) and
    ``shear_factors`` (k_y, k_z) (default 1). The tables are made (and the geometry checked)
    at construction and kept until :meth:`release`, after which :meth:`tables` makes them
    anew: a model's set hands them to its kernel system, which keeps its own copy (the forms
    are 10.8 kB an element), and releases them."""

    def __init__(self, reference, lengths, section: SectionData, youngs, poisson,
                 torsion: float | None = None, shear_factors=(1.0, 1.0)) -> None:
        torsion = section.polar if torsion is None else torsion
        self._arguments = (_f(reference), _f(lengths),
                           _pack("cs", area=section.area, inertia_y=section.inertia_y,
                                 inertia_z=section.inertia_z, torsion=torsion,
                                 shear_y=shear_factors[0], shear_z=shear_factors[1],
                                 youngs=youngs, poisson=poisson))
        self._tables: tuple[np.ndarray, np.ndarray, np.ndarray] | None = self._setup()

    def _setup(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        forms, strain0, stiffness, info = _kernel.beam_cubic_setup(
            int(_kernel.beam_cubic_size()), *self._arguments)
        if info:
            element, code = divmod(info, 10)
            reason = {1: "unsupported quadrature",
                      2: "degenerate reference geometry (r0_x vanishes)"}
            raise InputError(f"beam element {element}: {reason.get(code, f'code {code}')}")
        return forms, strain0, stiffness

    def tables(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(forms (8, 8, nterms, nel), reference strains and term stiffnesses (nterms, nel))."""
        return self._setup() if self._tables is None else self._tables

    def release(self) -> None:
        """Forget the kept tables (:meth:`tables` makes them anew when asked)."""
        self._tables = None

    def forces(self, dofs, e, want_tangent: bool):
        """Elastic force, strain energy and element tangents (24, 24, nel) at e."""
        forms, strain0, stiffness = self.tables()
        return _kernel.beam_cubic_forces(_f(dofs + 1, np.int32), _f(e), forms, strain0,
                                         stiffness, int(want_tangent))

    def stress_stiffness(self, dofs, e, de) -> np.ndarray:
        """The initial-stress part of the element tangents (24, 24, nel) at e, each strain
        replaced by its increment for the coordinate increment de: sum k (C e . de) C x I3."""
        forms, _, stiffness = self.tables()
        return _kernel.beam_cubic_stress_stiffness(_f(dofs + 1, np.int32), _f(e), _f(de),
                                                   forms, stiffness)


def cable_element_arrays(lengths, mass_per_length: float, load) -> tuple[np.ndarray, np.ndarray]:
    """Cable elements (cable_element): scalar element masses Mbar (4, 4, nel) (the element
    mass is kron(Mbar, I3)) and the generalized forces (12, nel) of a uniform load per
    length (3,)."""
    return _kernel.cable_element_arrays(_f(np.atleast_1d(lengths)), float(mass_per_length),
                                        _f(load))


def cable_shape(xi: float, length: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Cable shape rows (4,) at xi of an element: position, d/dx and d2/dx2."""
    return _kernel.cable_shape_functions(float(xi), float(length))


def cable_forces(dofs, e, lengths, axial_stiffness: float, bending_stiffness: float,
                 want_tangent: bool, tension_only: bool = False, *, rates=None,
                 damping_time: float = 0.0, rate_factor: float = 0.0):
    """Cable force (global), strain energy, element tangents (12, 12, nel) and the dissipated
    power at e; dofs (12, nel) 0-based; tension_only: a rope's axial law (no compression).
    Without damping (damping_time 0) the force is the elastic dU/de and the power 0; with the
    axial Kelvin-Voigt damping_time > 0 at the rates, the force includes the damping force
    and the tangents are dQ/de + rate_factor dQ/de'."""
    e = _f(e)
    if damping_time > 0.0 and rates is None:
        raise ValueError("cable_forces: a damping_time needs the rates")
    properties = _pack("cb", axial_stiffness=axial_stiffness,
                       bending_stiffness=bending_stiffness, damping_time=damping_time,
                       rate_factor=rate_factor)
    v = np.zeros_like(e) if rates is None else _f(rates)
    force, energy, tangent, dissipation, info = _kernel.cable_forces(
        _f(np.asarray(dofs) + 1, np.int32), e, v, _f(np.atleast_1d(lengths)), properties,
        int(want_tangent), int(tension_only))
    if info:
        raise SolverError(f"cable element {info}: r' vanished at a Gauss point")
    return force, float(energy), tangent, float(dissipation)



def cable_stress_stiffness(dofs, e, de, lengths, axial_stiffness: float,
                           tension_only: bool = False) -> np.ndarray:
    """The cable elements' initial-stress stiffness (12, 12, nel) at e for the increment de
    (cable_element.f90's cable_stress_stiffness: the axial force of the strain's derivative
    along de, sum w dN S'^T S' x I3); dofs (12, nel) 0-based; tension_only: a rope (nothing
    where it is slack at e)."""
    tangent, info = _kernel.cable_stress_stiffness_set(
        _f(np.asarray(dofs) + 1, np.int32), _f(e), _f(de), _f(np.atleast_1d(lengths)),
        float(axial_stiffness), int(tension_only))
    if info:
        raise SolverError(f"cable element {info}: its Gauss rule is unavailable")
    return tangent

PLATE_VARIANTS = {"plain": 0, "completed": 1}


def plate_shape(xi: float, eta: float, a: float, b: float) -> tuple[np.ndarray, np.ndarray]:
    """Thin-plate shape functions (12,) and their x, y, xx, yy, xy derivatives (12, 5)."""
    return _kernel.plate_shape_functions(xi, eta, a, b)


def plate_element_arrays(a, b, thickness: float, density: float, load) -> tuple[np.ndarray,
                                                                               np.ndarray]:
    """Compact plate mass matrices (12, 12, nel) and the generalized force (3, 12, nel) of a
    constant load per unit area (e.g. rho h g)."""
    mass, force, info = _kernel.plate_element_arrays(_f(a), _f(b), thickness, density, _f(load))
    if info:
        raise SolverError(f"plate element arrays: kernel code {info}")
    return mass, force


class PlateReference:
    """Reference data of a plate mesh at the Gauss points (plate_element.plate_setup):
    shape derivatives, the frame maps K, the reference curvatures and the weights."""

    def __init__(self, reference: np.ndarray, a, b, variant: str) -> None:
        npts = int(_kernel.plate_rule())
        if variant not in PLATE_VARIANTS:
            raise InputError(f"plate variant '{variant}': expected one of "
                             f"{sorted(PLATE_VARIANTS)}")
        self.variant = variant
        (self.derivs, self.frame, self.curvature0, self.weights,
         info) = _kernel.plate_reference(npts, _f(reference), _f(a), _f(b),
                                         PLATE_VARIANTS[variant])
        if info:
            element, code = divmod(info, 1000)
            raise InputError(f"plate element {element}: degenerate reference geometry "
                             f"(r_x parallel to r_y, code {code})")


def plate_forces(dofs, e, reference: PlateReference, youngs: float, poisson: float,
                 thickness: float, want_tangent: bool):
    """Plate elastic force (ndof,), strain energy and element tangents (36, 36, nel)."""
    force, energy, tangent, info = _kernel.plate_elastic_forces(
        _f(dofs + 1, np.int32), _f(e), reference.derivs, reference.frame, reference.curvature0,
        reference.weights, _pack("pm", youngs=youngs, poisson=poisson, thickness=thickness),
        int(want_tangent))
    if info:
        element, code = divmod(info, 1000)
        raise SolverError(f"plate element {element}: the mid-surface normal vanished "
                          f"(r_x parallel to r_y): the configuration is degenerate")
    return force, energy, tangent


def ffr_force(dofs, stiffness0, rotation, e, reference):
    """FFR elastic force T K0 (T^T e - e0) and strain energy. ``dofs`` are 0-based (24, nel),
    ``reference`` the rigid configuration in the frame per element (24, nel)."""
    return _kernel.ffr_elastic_force(_f(dofs + 1, np.int32), stiffness0, _f(reference),
                                     _f(rotation), _f(e))


def ffr_element_stiffness(stiffness0, rotation) -> np.ndarray:
    """Element stiffness matrices T K0 T^T (24, 24, nel)."""
    return _kernel.ffr_element_stiffness(stiffness0, _f(rotation))


def vector_load_force(kind: int, vector, shares, a, b):
    """A driven or follower point load (vector_loads.f90): forces (3, 3) on the slots
    (a, b, p) and the Jacobian (3, 3, 3, 2): d force(i, slot) / d (a, b)(j)."""
    force, jacobian, info = _kernel.vector_load_generalized_force(
        kind, _f(vector), _f(shares), _f(a), _f(b))
    if info:
        raise SolverError(f"point load of unknown kind {kind}")
    return force, jacobian


def force_element(kind: int, params, table_kind: int, table, x, xd, length: float = 0.0,
                  length_rate: float = 0.0) -> dict:
    """One force element (force_elements.f90) at its slot values x (3, ns) and rates xd:
    force (3, ns), stiffness and damping (3, ns, 3, ns) (derivatives of the force by x and
    xd), energy, dissipation, drive_power and reaction (7: force, moment, axial)."""
    params = np.asarray(params, dtype=float)
    table = np.asarray(table, dtype=float)
    force, stiffness, damping, energies, reaction, info = _kernel.force_element_generalized(
        _pack("fk", np.int32, element=kind, table=table_kind), len(params), _pad_last(params),
        len(table), _pad_last(table), _f(x), _f(xd),
        _pack("fg", length=length, length_rate=length_rate))
    energy, dissipation, power = (float(energies[_at("fe", n)])
                                  for n in ("energy", "dissipation", "drive_power"))
    if info:
        raise SolverError({1: f"force element of unknown kind {kind} or wrong sizes",
                           2: "force element: its two points coincide",
                           3: "force element: its table cannot be evaluated"}.get(
                               info, f"force element: code {info}"))
    return dict(force=force, stiffness=stiffness, damping=damping, energy=energy,
                dissipation=dissipation, drive_power=power, reaction=reaction)



def force_element_initial_stress(kind: int, params, table_kind: int, table, x, xd, at,
                                 length: float = 0.0, length_rate: float = 0.0) -> np.ndarray:
    """One force element's initial-stress stiffness (3, ns, 3, ns) (force_elements.f90's
    force_element_initial_stress): its measures' forces at the slot values x (3, ns) and
    rates xd times the measures' Hessians at the slot values ``at``."""
    params = np.asarray(params, dtype=float)
    table = np.asarray(table, dtype=float)
    stiffness, info = _kernel.force_element_initial_stress_generalized(
        _pack("fk", np.int32, element=kind, table=table_kind), len(params), _pad_last(params),
        len(table), _pad_last(table), _f(x), _f(xd),
        _pack("fg", length=length, length_rate=length_rate), _f(at))
    if info:
        raise SolverError({1: f"force element of unknown kind {kind} or wrong sizes",
                           2: "force element: its two points coincide (or its torsion "
                              "has no angle)",
                           3: "force element: its table cannot be evaluated"}.get(
                               info, f"force element: code {info}"))
    return stiffness

def moment_force(director, axis, magnitude):
    """Dead moment on a section director: force (3,), Jacobian (3, 3), Hessian (3, 3, 3)."""
    force, jacobian, hessian, info = _kernel.moment_generalized_force(_f(director), _f(axis),
                                                                      magnitude)
    if info:
        raise SolverError("bending moment: the section director became parallel to the "
                          "moment axis, the section rotation is undefined")
    return force, jacobian, hessian


def reduced_ffr_newmark(dt: float, beta: float, gamma: float, omega2, gyroscopic,
                        centrifugal, pdelta_linear, pdelta_quadratic, load_patterns, rate,
                        accel, sin_psi, one_minus_cos, tol: float,
                        max_newton: int) -> dict[str, np.ndarray]:
    """Newmark stepping of a modally reduced FFR model (fortran reduced_ffr_stepper;
    ancfdrv.solvers.ffr_reduced) from rest: 'eta' and 'velocity' (steps + 1, r), per step
    'corrections' (Newton) and 'factorized' (0 or 1). The load at each time, formed in the
    stepper as simulate forms it, is -accel l_e - rate^2 l_c - sin_psi l_s + one_minus_cos
    l_k with load_patterns (r, 4) = (l_e, l_c, l_s, l_k); rate, accel, sin_psi and
    one_minus_cos (steps + 1,); pdelta_linear None: no P-delta remainder."""
    r = len(omega2)
    pdelta = pdelta_linear is not None
    lin = _f(pdelta_linear) if pdelta else np.zeros((r, r), order="F")
    quad = _f(pdelta_quadratic) if pdelta else np.zeros((r, r, r), order="F")
    motion = dict(rate=rate, sin_psi=sin_psi, one_minus_cos=one_minus_cos, accel=accel)
    frame = _f(np.column_stack([np.asarray(motion[n], dtype=float)
                                for n in KERNEL_LAYOUTS["fm"]]))
    eta, velocity, counts, status = _kernel.reduced_ffr_newmark(
        _pack("rs", dt=dt, beta=beta, gamma=gamma, tol=tol),
        _pack("rc", np.int32, pdelta=int(pdelta), max_newton=max_newton), _f(omega2),
        _f(gyroscopic), _f(centrifugal), lin, quad, _f(load_patterns), frame)
    corrections, factorized = counts[:, _at("rn", "corrections")], \
        counts[:, _at("rn", "factorized")]
    info, step = int(status[_at("rt", "info")]), int(status[_at("rt", "failed_step")])
    if info:
        what = "Newton did not converge" if info == 1 else "singular iteration matrix"
        raise SolverError(f"reduced FFR stepper: {what} at step {step}")
    return {"eta": eta.T, "velocity": velocity.T, "corrections": corrections.astype(np.int64),
            "factorized": factorized.astype(np.int64)}


def drive_values(kind: int, params, t):
    """phi, phi', phi'' of a drive at the times t (params: its parameters, any length)."""
    p = np.asarray(params, dtype=float).ravel()
    # unused trailing parameters of the fixed layouts are zero; a table's length is its data
    if kind not in (DRIVE_TABLE, DRIVE_HERMITE) and p.size < 8:
        p = np.concatenate([p, np.zeros(8 - p.size)])
    if p.size == 0:
        p = np.zeros(1)
    phi, dphi, ddphi, info = _kernel.drive_values(kind, _f(p), _f(np.atleast_1d(t)))
    if info:
        raise InputError(f"drive kind {kind} with parameters {list(params)}: "
                         + ("unknown kind" if info == 1 else "non-physical parameters"))
    return phi, dphi, ddphi


class SparsePattern:
    """CSR pattern of an n x n matrix built once from element dof lists (0-based, -1 = none),
    with the scatter map that assembles element matrices without searching."""

    def __init__(self, n: int, dofs: np.ndarray) -> None:
        dofs1 = _f(np.asarray(dofs) + 1, np.int32)
        nnz, info = _kernel.sparse_pattern_count(n, dofs1)
        if info:
            raise InputError("sparse pattern: a dof index is out of range")
        row_ptr, col_index, scatter_map, info = _kernel.sparse_pattern_build(n, dofs1, nnz)
        if info:
            raise SolverError(f"sparse pattern: kernel code {info}")
        self.n, self.nnz = n, int(nnz)
        self.row_ptr = row_ptr - 1
        self.col_index = col_index - 1
        self.scatter_map = scatter_map
        self.rows = np.repeat(np.arange(n), np.diff(self.row_ptr))

    def assemble(self, element_values: np.ndarray) -> np.ndarray:
        """CSR values (nnz,) from element matrices (ndofe, ndofe, nel)."""
        return _kernel.sparse_assemble(self.nnz, self.scatter_map, _f(element_values))

    def to_scipy(self, values: np.ndarray):
        """A scipy CSR matrix with its own copy of the pattern (scipy shares index arrays,
        and in-place operations such as eliminate_zeros would corrupt this pattern)."""
        import scipy.sparse as sp
        return sp.csr_matrix((values.copy(), self.col_index.copy(), self.row_ptr.copy()),
                             shape=(self.n, self.n))


_MUMPS_MESSAGES = {-10: "the matrix is numerically singular",
                   -9: "MUMPS workspace too small", -13: "MUMPS could not allocate memory",
                   -6: "the matrix is structurally singular", -5: "MUMPS out of memory"}


class DirectSolver:
    """Sparse direct solver (sequential MUMPS, LAPACK's banded Cholesky or LU, the kernel's
    envelope LU) behind a kernel handle.

    Analyse a coordinate pattern once, factorize as values change, solve many right-hand
    sides per factorization. Use as a context manager or call :meth:`close`.
    """

    def __init__(self, n: int, rows: np.ndarray, cols: np.ndarray, *, symmetric: bool = False,
                 banded_spd: bool = False, what: str = "system matrix") -> None:
        """``banded_spd`` selects LAPACK's banded Cholesky for a symmetric matrix with a narrow
        band (O(n kd) solves without MUMPS's per-call overhead); a matrix that turns out not
        to be positive definite is factorized by the pivoted banded LU instead (give both
        triangles). :meth:`by_cost` lets the kernel choose between its banded LU (in its
        reverse Cuthill-McKee order) and MUMPS."""
        self.what = what
        kind = 3 if banded_spd else 2 if symmetric else 0
        handle, info, detail = _kernel.direct_create(kind)
        self._check(info, detail, "create")
        self.handle, self.n, self.nnz = handle, n, len(rows)
        self.kind = "banded Cholesky" if banded_spd else "MUMPS"
        self.banded_lu = self.envelope_lu = False
        self.factorizations = 0
        self.solves = 0
        info, detail = _kernel.direct_analyse(handle, n, _f(np.asarray(rows) + 1, np.int32),
                                              _f(np.asarray(cols) + 1, np.int32))
        self._check(info, detail, "analyse")

    @classmethod
    def by_cost(cls, n: int, rows: np.ndarray, cols: np.ndarray, *,
                what: str = "system matrix", positive: bool = False) -> "DirectSolver":
        """The solver the kernel's cost rule picks for any (e.g. saddle-point) pattern, the
        rule of the static Newton and the consistent start (``sparse_direct``'s
        solver_create_for): LAPACK's banded LU in the reverse Cuthill-McKee order of the
        pattern's symmetric closure when 4 n kd^2 <= 5e7 (``banded_lu_flops``), else MUMPS
        (general; give every entry). ``positive``: every matrix it will factorize has a
        positive definite symmetric part (an iteration matrix beta' M + ...): the envelope
        LU without pivoting (``envelope_lu.f90``, in a profile-reducing order) replaces the
        banded LU, which factorizes any matrix that meets a pivot that is not positive
        (:attr:`fallbacks` counts them). ``kind`` ('banded LU', 'envelope LU', 'MUMPS'),
        ``banded_lu``, ``envelope_lu`` and ``width`` (kd in the reverse Cuthill-McKee
        order) say which."""
        self = cls.__new__(cls)
        self.what, self.n, self.nnz = what, n, len(rows)
        self.factorizations = 0
        self.solves = 0
        self.handle = 0
        handle, width, kind, info, detail = _kernel.direct_create_for(
            n, _f(np.asarray(rows) + 1, np.int32), _f(np.asarray(cols) + 1, np.int32),
            int(positive))
        self._check(info, detail, "creation and analysis")
        self.handle, self.width = handle, int(width)
        self.kind = {0: "MUMPS", 2: "banded LU", 3: "envelope LU"}[int(kind)]
        self.banded_lu = self.kind == "banded LU"
        self.envelope_lu = self.kind == "envelope LU"
        return self

    @property
    def fallbacks(self) -> int:
        """Factorizations of the envelope LU that fell back to the pivoted banded LU (0 for
        the other kinds)."""
        return int(_kernel.direct_envelope_counts(self.handle)[0]) if self.handle else 0

    @property
    def envelope(self) -> int:
        """The envelope LU's entries below the diagonal in its order (as many above it; 0
        for the other kinds): its solve takes about twice this many multiply-adds."""
        return int(_kernel.direct_envelope_counts(self.handle)[1]) if self.handle else 0

    def analyse(self, n: int, rows: np.ndarray, cols: np.ndarray) -> None:
        """Another pattern on the same solver (MUMPS analyses it anew; no new instance),
        to be factorized next."""
        info, detail = _kernel.direct_analyse(self.handle, n, _f(np.asarray(rows) + 1, np.int32),
                                              _f(np.asarray(cols) + 1, np.int32))
        self._check(info, detail, "analyse")
        self.n, self.nnz = n, len(rows)

    def _check(self, info: int, detail: int, step: str) -> None:
        if info == 0:
            return
        if info < 0:
            reason = _MUMPS_MESSAGES.get(info, f"MUMPS error INFOG(1) = {info}")
            raise SolverError(f"{self.what}: {step} failed: {reason} (INFOG(2) = {detail})")
        reason = {1: "invalid handle", 2: "called out of sequence", 3: "size mismatch"}[info]
        raise SolverError(f"{self.what}: {step} failed: {reason}")

    def factorize(self, values: np.ndarray) -> None:
        info, detail = _kernel.direct_factorize(self.handle, _f(values))
        self._check(info, detail, "factorization")
        self.factorizations += 1

    def solve(self, rhs: np.ndarray) -> np.ndarray:
        """Solution for rhs of shape (n,) or (n, k)."""
        b = np.asarray(rhs, dtype=np.float64)
        matrix = np.array(b.reshape(self.n, -1), dtype=np.float64, order="F")  # kernel solves in place
        x, info, detail = _kernel.direct_solve(self.handle, matrix)
        self._check(info, detail, "solve")
        self.solves += matrix.shape[1]
        return x.reshape(b.shape)

    def close(self) -> None:
        if getattr(self, "handle", 0):
            _kernel.direct_destroy(self.handle)
            self.handle = 0

    def __enter__(self) -> "DirectSolver":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __del__(self) -> None:
        try:
            self.close()
        except Exception:
            pass


def reference_node_mass(mass: float, centre, inertia) -> np.ndarray:
    """12 x 12 mass matrix of an ANCF reference node (eq. 32), coordinates [r, r_x, r_y, r_z]."""
    matrix, info = _kernel.reference_node_mass(mass, _f(centre), _f(inertia))
    if info == 1:
        raise InputError(f"rigid body mass {mass} must be positive")
    if info == 2:
        raise InputError("rigid body inertia tensor is not symmetric or not physical (its "
                         "principal moments violate the triangle inequality)")
    return matrix


def contact_params(stiffness: float, damping: float, friction: float, slip_velocity: float,
                   upper_thickness: float, lower_thickness: float, friction_on: bool) -> np.ndarray:
    return np.array([stiffness, damping, friction, slip_velocity, upper_thickness,
                     lower_thickness, 1.0 if friction_on else 0.0, 0.0])


def contact_pair(upper, upper_rates, a_u, b_u, xi_q, eta_q, lower, lower_rates, a_l, b_l, xi_p,
                 eta_p, params, velocity_factor: float = 0.0) -> dict:
    """One contact pair: element coordinates (3, 12) and rates; forces on the upper and lower
    element, Jacobian of minus the forces (72 x 72), record (penetration, F_n, |F_t|, slip),
    penalty potential and powers (damping, friction)."""
    geometry = _f(np.column_stack([_pack("cg", a=a_u, b=b_u, xi=xi_q, eta=eta_q),
                                   _pack("cg", a=a_l, b=b_l, xi=xi_p, eta=eta_p)]))
    (forces, jac, record, energies, active, info) = _kernel.contact_pair(
        _f(upper), _f(upper_rates), _f(lower), _f(lower_rates), geometry, _f(params),
        velocity_factor)
    if info:
        raise SolverError("contact pair: a mid-surface normal vanished")
    return dict(force_upper=forces[:, 0], force_lower=forces[:, 1], jacobian=jac, record=record,
                potential=float(energies[_at("ce", "potential")]),
                powers=energies[[_at("ce", "damping"), _at("ce", "friction")]],
                active=bool(active))


def contact_projection(e, dofs, sizes, grid, point, guess) -> tuple[np.ndarray, int, int]:
    """Closest point (leaf-level coordinates) of the upper mid-surface grid to ``point``;
    returns it with the Newton iterations and fallback sweeps used."""
    guess, counts, info = _kernel.contact_projection(
        _f(e), _f(np.asarray(dofs) + 1, np.int32), _f(sizes), _f(np.asarray(grid) + 1, np.int32),
        _f(point), _f(guess))
    if info:
        raise SolverError("contact search: no closest point found")
    return guess, int(counts[0]), int(counts[1])


# -- a mechanical system behind a kernel handle (fortran/src/api/system_api.f90) ----------
def _i(a) -> np.ndarray:
    return np.asfortranarray(a, dtype=np.int32)


def _state(e, v) -> np.ndarray:
    """(n, 2): coordinates and rates as the kernel's state columns (codes.KERNEL_LAYOUTS
    'sv')."""
    columns = dict(coordinates=np.asarray(e, dtype=float), rates=np.asarray(v, dtype=float))
    return _f(np.column_stack([columns[n] for n in KERNEL_LAYOUTS["sv"]]))


def _pad_last(a: np.ndarray, dtype=np.float64) -> np.ndarray:
    """f2py refuses zero-size arrays: one unused entry along the last axis."""
    a = np.asarray(a, dtype=dtype)
    if a.shape[-1] == 0:
        a = np.zeros(a.shape[:-1] + (1,), dtype=dtype)
    return np.asfortranarray(a)


#: the lengths of the energies of an output row and of the works and powers of the state
ENERGY_COUNT, POWER_COUNT = len(ENERGY_NAMES), len(POWER_NAMES)
#: the arrays of the packed stepper state after t, in order (stepper.f90 state_size)
_PACKED_ARRAYS = ("e", "v", "a", "accel", "lam", "work", "powers")


class PackedState(dict):
    """A stepper state (t, e, v, a, accel, lam, work, powers, guesses, counts) whose arrays
    are views of one packed buffer in the layout of stepper.f90 ``state_size``: the kernel
    steps the buffer in place (:meth:`KernelSystem.advance`), so a call packs and unpacks
    nothing (issue 25: the packing cost ~31,000 instructions per single-step call). Reading
    a key gives its view (changed by the next call: copy what must stay); assigning a key
    (or :meth:`update`) copies the value into the buffer. ``t`` reads as a float. A plain
    dict of the same keys is accepted by :meth:`KernelSystem.advance` too (packed per
    call)."""

    def __init__(self, cuts: list[slice], npoint: int, values: dict) -> None:
        super().__init__()
        self.packed = np.zeros(cuts[-1].stop)
        self.npoint = npoint
        views = {key: self.packed[part] for key, part in zip(_PACKED_ARRAYS, cuts[1:8])}
        if npoint:   # (2, npoint) in Fortran order: a view of the packed guesses
            views["guesses"] = self.packed[cuts[8]].reshape((2, npoint), order="F")
        self._views = views
        for key, value in values.items():
            self[key] = value

    def __setitem__(self, key: str, value) -> None:
        if key == "t":
            self.packed[0] = value
            dict.__setitem__(self, "t", float(value))
            return
        view = self._views.get(key)
        if view is None:
            dict.__setitem__(self, key, value)
            return
        if view is not value:
            view[...] = np.asarray(value)[:, :self.npoint] if key == "guesses" else value
        dict.__setitem__(self, key, view)

    def update(self, other=(), **kwargs) -> None:  # type: ignore[override]
        for key, value in dict(other, **kwargs).items():
            self[key] = value

    def stepped(self, packed: np.ndarray, counts: np.ndarray) -> None:
        """Take the kernel's state after a call (in place unless f2py had to copy)."""
        if packed is not self.packed:
            self.packed[...] = packed
        dict.__setitem__(self, "t", float(self.packed[0]))
        if counts is not dict.__getitem__(self, "counts"):
            dict.__setitem__(self, "counts", counts)


def _text(message: bytes | str) -> str:
    """A kernel message buffer (f2py returns character(len=200) as bytes) as text."""
    if isinstance(message, bytes):
        message = message.decode("ascii", "replace")
    return str(message).strip() or "no message"


class KernelSystem:
    """A mechanical system held by the kernel (system_store): built once by the set-up
    methods (indices are 0-based here, 1-based in the kernel), then evaluated or stepped
    chunk by chunk without sending its arrays again. Use as a context manager or call
    :meth:`close`."""

    def __init__(self, ndof: int, nfull: int) -> None:
        handle, info, message = _kernel.system_create(ndof, nfull)
        if info:
            raise SolverError(_text(message))
        self.handle, self.ndof, self.nfull = int(handle), ndof, nfull
        self.ncon = self.nprobe = self.npoint = 0
        self.nnz_pattern = 0
        #: the elements of each beam set given section data (set_sections), by index
        self._set_sizes: dict[int, int] = {}

    def _check(self, info: int, what: str, message: bytes | str = b"") -> None:
        """Raise with the kernel's own text (code 1: a stale handle, 2: sizes or indices
        inconsistent with the system: a bug of the caller)."""
        if info:
            raise SolverError(f"kernel system set-up ({what}), code {info}: {_text(message)}")

    # element sets: dofs 0-based (nde, nel), scatter 1-based (Pattern.scatter), frame: the
    # 1-based frame id (0: none); damping_time: the Kelvin-Voigt retardation time tau (s) of
    # the set's material damping (0: none, and none of its code runs)
    def add_ffr_set(self, dofs, scatter, stiffness0, reference, frame: int,
                    damping_time: float = 0.0) -> int:
        index, info, message = _kernel.system_add_ffr_set(self.handle, _i(dofs + 1), _i(scatter),
                                                 _f(stiffness0), _f(reference), frame,
                                                 damping_time)
        self._check(info, "FFR beam set", message)
        return int(index)

    def ffr_second_order(self, index: int, axial_rigidity, axis, length, slope_gram) -> None:
        """Turn on the geometric stiffness (P-delta) of FFR set ``index`` (1-based):
        per element EA, the unit axis in the frame (3, nel), the length and the centre-line
        slope Gram matrix (8, 8, nel) (ffr_elastic module doc)."""
        info, message = _kernel.system_ffr_second_order(self.handle, index, _f(axial_rigidity),
                                                        _f(axis), _f(length), _f(slope_gram))
        self._check(info, "FFR geometric stiffness", message)

    def add_continuum_set(self, dofs, scatter, gradients, weights, nvolume: int, youngs: float,
                          poisson: float, frame: int, damping_time: float = 0.0,
                          shear_scales=(1.0, 0.0, 0.0)) -> int:
        index, info, message = _kernel.system_add_continuum_set(
            self.handle, nvolume, _i(dofs + 1), _i(scatter), _f(gradients), _f(weights),
            _pack("bm", youngs=youngs, poisson=poisson), _f(shear_scales), frame, damping_time)
        self._check(info, "continuum beam set", message)
        return int(index)

    def add_cubic_set(self, dofs, scatter, forms, strain0, stiffness, frame: int,
                      damping_time: float = 0.0) -> int:
        index, info, message = _kernel.system_add_cubic_set(
            self.handle, _i(dofs + 1), _i(scatter), _f(forms), _f(strain0), _f(stiffness),
            frame, damping_time)
        self._check(info, "cubic beam set", message)
        return int(index)

    def set_sections(self, index: int, lengths, reference, cubic: bool, **section: float
                     ) -> None:
        """Give beam set ``index`` (1-based) the data of its section forces: the element
        lengths (nel,), the reference nodal vectors (3, 8, nel) (an 'ffr' set's in its
        frame), the bending option and the section (codes.KERNEL_LAYOUTS 'sk', by name)."""
        info, message = _kernel.system_set_sections(self.handle, index, _f(lengths),
                                                    _f(reference), _pack("bs", **section),
                                                    int(cubic))
        self._check(info, "beam section data", message)
        self._set_sizes[index] = len(lengths)

    def section_forces(self, index: int, times, e_rows, xi) -> tuple[np.ndarray, np.ndarray]:
        """Section forces (6, nrows, ns nel) [N, T, Q_height, Q_width, M_height, M_width]
        of beam set ``index`` at the stations xi (ns,) of every element for the states
        e_rows (nrows, ndof) (independent coordinates) at the times (nrows,) (element_sets
        section_forces; station i of element el at el ns + i, 0-based), in one call for all
        rows, and each force's largest magnitude over the rows (6, ns nel) (NaN where a
        row's is NaN). Each component's (nrows, ns nel) is C-contiguous."""
        nel = self._set_sizes[index]
        xi = np.asarray(xi, dtype=np.float64)
        times = np.asarray(times, dtype=np.float64)
        # the kernel writes every entry: numpy.empty, not f2py's zero-filled output (a
        # chunk's forces, 700 kB for the FFR boom, were zeroed twice beyond the cache)
        forces = np.empty((len(xi) * nel, len(times), 6), order="F")
        # the rows (nrows, ndof) in C order are the kernel's (ndof, nrows) columns
        largest, info, message = _kernel.system_section_forces(
            self.handle, index, times, np.ascontiguousarray(e_rows, dtype=np.float64).T, xi,
            forces)
        if info:
            raise SolverError(f"kernel section forces, code {info}: {_text(message)}")
        return forces.T, largest.T

    def ffr_departures(self, index: int, times, e_rows) -> np.ndarray:
        """The small-strain measure of FFR set ``index`` at the states e_rows (nrows, ndof)
        (independent coordinates) at the times (nrows,): per row the largest change of a
        section vector r_x, r_y, r_z from its reference in the frame (ffr_elastic
        ffr_departures), (nrows,), in one call for all rows."""
        rows = np.ascontiguousarray(e_rows, dtype=np.float64)
        departure, info, message = _kernel.system_ffr_departures(
            self.handle, index, np.asarray(times, dtype=np.float64), rows.T)
        if info:
            raise SolverError(f"kernel small-strain measure, code {info}: {_text(message)}")
        return departure

    def add_plate_set(self, dofs, scatter, reference: "PlateReference", youngs: float,
                      poisson: float, thickness: float, damping_time: float = 0.0) -> int:
        index, info, message = _kernel.system_add_plate_set(
            self.handle, _i(dofs + 1), _i(scatter), reference.derivs, reference.frame,
            reference.curvature0, reference.weights,
            _pack("pm", youngs=youngs, poisson=poisson, thickness=thickness), damping_time)
        self._check(info, "plate set", message)
        return int(index)

    def add_cable_set(self, dofs, scatter, lengths, axial_stiffness: float,
                      bending_stiffness: float, damping_time: float = 0.0,
                      tension_only: bool = False) -> int:
        index, info, message = _kernel.system_add_cable_set(
            self.handle, _i(dofs + 1), _i(scatter), _f(lengths), axial_stiffness,
            bending_stiffness, damping_time, int(tension_only))
        self._check(info, "cable set", message)
        return int(index)

    #: the set-up calls that set nothing a new system holds already (no frames, no drives:
    #: system_create's empty lists) are not made
    _frames_set = _drives_set = False

    def set_frames(self, drives, axes, bases, pivots) -> None:
        """Frames: drive (0-based drive index, -1: fixed), axis, base (3, 3), pivot."""
        n = len(drives)
        if n == 0 and not self._frames_set:
            return   # system_create's frames(0)
        self._frames_set = True
        info, message = _kernel.system_set_frames(
            self.handle, n, _pad_last(np.asarray(drives, dtype=np.int32) + 1, np.int32),
            _pad_last(np.asarray(axes, dtype=float).reshape(-1, 3).T),
            _pad_last(np.transpose(np.asarray(bases, dtype=float).reshape(-1, 3, 3), (1, 2, 0))),
            _pad_last(np.asarray(pivots, dtype=float).reshape(-1, 3).T))
        self._check(info, "frames", message)

    def set_drives(self, kinds, params: list) -> None:
        if not len(kinds) and not params and not self._drives_set:
            return   # system_create's drive_kinds(0), drive_ptr = [1], drive_data(0)
        self._drives_set = True
        ptr = np.concatenate([[0], np.cumsum([len(p) for p in params])]).astype(np.int32) + 1
        data = np.concatenate([np.asarray(p, dtype=float) for p in params]) if params else \
            np.zeros(0)
        info, message = _kernel.system_set_drives(self.handle, len(kinds), len(data),
                                         _pad_last(np.asarray(kinds, dtype=np.int32), np.int32),
                                         _i(ptr), _pad_last(data))
        self._check(info, "drives", message)

    def set_matrices(self, mass_csr, full_pattern, solver_handle: int, policy: int,
                     mass_pattern, vector_frame, block_first, saddle_mass) -> None:
        """M (CSR arrays indptr, indices, data on the independent coordinates: an
        ancfdrv.csr.Csr or a scipy matrix), the full pattern (row_ptr,
        col_index, 0-based), the solver and its policy, M on the solver's pattern, the frame
        of each reduced 3-vector (0: global; frames 1-based here), the blocks' first dofs and
        M as the model assembled it (CSR, zero entries kept: the mass block of the kernel's
        consistent acceleration, ``fortran/src/solvers/consistent_start.f90``)."""
        full_row_ptr, full_col = full_pattern
        self.nnz_pattern = len(mass_pattern)
        self._full_col = full_col
        info, message = _kernel.system_set_mass(
            self.handle, _i(mass_csr.indptr + 1), _i(mass_csr.indices + 1), _f(mass_csr.data),
            _f(mass_pattern), _i(saddle_mass.indptr + 1), _i(saddle_mass.indices + 1),
            _f(saddle_mass.data), ndof=self.ndof)
        self._check(info, "matrices", message)
        info, message = _kernel.system_set_solver(
            self.handle, _i(np.asarray(full_row_ptr) + 1), _i(np.asarray(full_col) + 1),
            _pack("sl", np.int32, handle=solver_handle, policy=policy), len(vector_frame),
            _pad_last(np.asarray(vector_frame, dtype=np.int32), np.int32), len(block_first),
            _pad_last(np.asarray(block_first, dtype=np.int32) + 1, np.int32), nfull=self.nfull)
        self._check(info, "matrices", message)

    def set_kron_mass(self, scalar_csr) -> None:
        """M = kron(Mbar, I3): Mbar's CSR on the 3-vectors replaces M in the products."""
        info, message = _kernel.system_set_kron_mass(self.handle, _i(scalar_csr.indptr + 1),
                                            _i(scalar_csr.indices + 1), _f(scalar_csr.data))
        self._check(info, "kron mass", message)

    def set_carry(self, vectors: tuple[np.ndarray, ...] | None) -> None:
        """The 3-vectors jacobian 'reuse' carries its iteration matrix with under rotation
        (``fortran/src/solvers/carried_rotation.f90``): (first full dof 0-based, weight,
        1 position / 0 gradient or director, group 0-based: each group is fitted its own
        rotation) of each, or None: not carried."""
        if vectors is None:
            first, weight, position, group = (np.zeros(0, dtype=np.int64), np.zeros(0),
                                              np.zeros(0, dtype=np.int64),
                                              np.zeros(0, dtype=np.int64))
        else:
            first, weight, position, group = vectors
        info, message = _kernel.system_set_carry(
            self.handle, len(first), _pad_last(np.asarray(first) + 1, np.int32),
            _pad_last(np.asarray(weight, dtype=float)),
            _pad_last(np.asarray(position), np.int32), _pad_last(np.asarray(group) + 1, np.int32))
        self._check(info, "carry", message)

    def set_reduction(self, b_csr, offset, plan_source, plan_target, plan_coef) -> None:
        info, message = _kernel.system_set_reduction(
            self.handle, len(b_csr.data), _i(b_csr.indptr + 1),
            _pad_last(b_csr.indices + 1, np.int32), _pad_last(b_csr.data), _f(offset),
            len(plan_coef), _pad_last(np.asarray(plan_source) + 1, np.int32),
            _pad_last(np.asarray(plan_target) + 1, np.int32), _pad_last(plan_coef),
            nfull=self.nfull)
        self._check(info, "reduction", message)

    def set_loads(self, constant_force, force_drives, force_vectors, moment_dofs, moment_axes,
                  magnitudes, moment_references) -> None:
        """Driven forces: 0-based drive indices and vectors (ndof, n); moments: full director
        dofs (n, 3, 0-based), axes, magnitudes, directors at t = 0."""
        nforce, nmoment = len(force_drives), len(magnitudes)
        info, message = _kernel.system_set_loads(
            self.handle, _f(constant_force), nforce,
            _pad_last(np.asarray(force_drives, dtype=np.int32) + 1, np.int32),
            _pad_last(np.asarray(force_vectors, dtype=float).reshape(self.ndof, nforce)), nmoment,
            _pad_last(np.asarray(moment_dofs, dtype=np.int32).reshape(-1, 3).T + 1, np.int32),
            _pad_last(np.asarray(moment_axes, dtype=float).reshape(-1, 3).T),
            _pad_last(np.asarray(magnitudes, dtype=float)),
            _pad_last(np.asarray(moment_references, dtype=float).reshape(-1, 3).T),
            ndof=self.ndof)
        self._check(info, "loads", message)

    def set_fixed_loads(self, fixed_force, force_fixed, moment_fixed, vload_fixed) -> None:
        """The fixed loads (kept at their value whatever the load factor), after
        :meth:`set_loads` and :meth:`set_vector_loads`: the fixed share of the constant
        force and per driven force, dead moment and vector load whether it is fixed."""
        def flags(x):
            return _pad_last(np.asarray(x, dtype=np.int32), np.int32)
        info, message = _kernel.system_set_fixed_loads(
            self.handle, _f(fixed_force), len(force_fixed), flags(force_fixed),
            len(moment_fixed), flags(moment_fixed), len(vload_fixed), flags(vload_fixed),
            ndof=self.ndof)
        self._check(info, "fixed loads", message)

    def set_vector_loads(self, loads) -> None:
        """Driven and follower point loads (model.VectorLoadInfo)."""
        ptr, dofs, coefs = [0], [], []
        for load in loads:
            for slot in load.slots:
                dofs += [d for d, _ in slot]
                coefs += [c for _, c in slot]
                ptr.append(len(dofs))
        info = _kernel.system_set_vector_loads(
            self.handle, len(loads), len(dofs),
            _pad_last(np.array([x.kind for x in loads], dtype=np.int32), np.int32),
            _pad_last(np.array([x.drive + 1 for x in loads], dtype=np.int32), np.int32),
            _pad_last(np.array([x.vector for x in loads], dtype=float).reshape(-1, 3).T),
            _pad_last(np.array([x.shares for x in loads], dtype=float).reshape(-1, 2).T),
            _i(np.array(ptr) + 1), _pad_last(np.array(dofs, dtype=np.int32) + 1, np.int32),
            _pad_last(np.array(coefs, dtype=float)))
        self._check(info, "vector loads")

    def set_force_elements(self, layout: dict) -> None:
        """Force elements (system/force_elements.kernel_layout: 0-based indices)."""
        nfel, nslot = len(layout["kinds"]), len(layout["term_ptr"]) - 1
        info = _kernel.system_set_force_slots(
            self.handle, nslot, len(layout["term_dof"]),
            _pad_last(np.asarray(layout["slot_const"], dtype=float).T),
            _i(np.array(layout["term_ptr"]) + 1),
            _pad_last(np.array(layout["term_dof"], dtype=np.int32) + 1, np.int32),
            _pad_last(np.array(layout["term_coef"], dtype=float)))
        self._check(info, "force elements")
        columns = dict(kind=np.array(layout["kinds"]), drive=np.array(layout["drives"]) + 1,
                       table_kind=np.array(layout["table_kinds"]),
                       slot_first=np.array(layout["slot_first"]) + 1)
        elements = np.array([columns[n] for n in KERNEL_LAYOUTS["fl"]], dtype=np.int32)
        pointers = dict(param=layout["param_ptr"], table=layout["table_ptr"],
                        position=layout["position_ptr"])
        info = _kernel.system_set_force_elements(
            self.handle, nfel, len(layout["params"]), len(layout["table"]),
            len(layout["positions"]), _pad_last(elements.reshape(len(elements), nfel), np.int32),
            _i(np.column_stack([np.asarray(pointers[n]) + 1 for n in KERNEL_LAYOUTS["fp"]])),
            _pad_last(np.array(layout["params"])), _pad_last(np.array(layout["table"])),
            _pad_last(np.asarray(layout["positions"]) + 1, np.int32))
        self._check(info, "force elements")
        self.nfel = nfel

    def force_element_reactions(self, t: float, e, v) -> np.ndarray:
        """(7, nfel): per force element the force and moment body1 exerts on body2
        (global) and the axial force (tension positive) at (t, e, e')."""
        nfel = getattr(self, "nfel", 0)
        out, info, message = _kernel.system_force_element_reactions(
            self.handle, nfel, t, _f(e), _f(v), ndof=self.ndof)
        if info:
            raise SolverError(f"force element reactions: {_text(message)}")
        return out[:, :nfel]

    def set_constraints(self, layout: "ConstraintLayout") -> None:
        ncon, nterm = len(layout.kinds), len(layout.term_dof)
        info, message = _kernel.system_set_constraints(
            self.handle, ncon, nterm, _pad_last(layout.kinds, np.int32),
            _pad_last(np.asarray(layout.drives) + 1, np.int32), _pad_last(layout.params),
            _pad_last(layout.operand_const), _i(np.asarray(layout.term_ptr) + 1),
            _pad_last(np.asarray(layout.term_dof) + 1, np.int32), _pad_last(layout.term_coef))
        self._check(info, "constraints", message)
        self.ncon = ncon

    def add_contact_pair(self, dofs, sizes, grid, point_element, point_local, params) -> None:
        info, message = _kernel.system_add_contact_pair(
            self.handle, _i(np.asarray(dofs) + 1), _f(sizes), _i(np.asarray(grid) + 1),
            _i(np.asarray(point_element) + 1), _f(point_local), _f(params))
        self._check(info, "contact pair", message)
        self.npoint += len(point_element)

    def set_probes(self, ptr, dofs, coefs, frames, reference) -> None:
        """Probe p = sum coef q[dof:dof+3] over terms ptr[p]:ptr[p+1] (0-based dofs),
        deflection frame (0: global, frames 1-based), rigid position in it (nprobe, 3)."""
        nprobe = len(ptr) - 1
        info, message = _kernel.system_set_probes(
            self.handle, len(dofs), _i(np.asarray(ptr) + 1),
            _pad_last(np.asarray(dofs, dtype=np.int32) + 1, np.int32), _pad_last(coefs),
            _pad_last(np.asarray(frames, dtype=np.int32), np.int32),
            _pad_last(np.asarray(reference, dtype=float).reshape(-1, 3).T))
        self._check(info, "probes", message)
        self.nprobe = nprobe

    def evaluate(self, t: float, e, v, guesses, counts, *, load_factor: float = 1.0,
                 velocity_factor: float = 0.0, want_tangent: bool = False) -> dict:
        """Internal forces B^T (Q_el - Q_c - lf Q_M), external lf Q(t), strain energy, contact
        potential and records, and on request the tangent on the solver's pattern; the
        contact guesses and counters are updated (returned)."""
        nnz = self.nnz_pattern if want_tangent else 1
        out = _kernel.system_evaluate(
            self.handle, nnz, self.npoint, _state(e, v),
            _pack("ef", time=t, load_factor=load_factor, velocity_factor=velocity_factor),
            int(want_tangent), _f(guesses), _i(counts), ndof=self.ndof)
        (guesses, counts, forces, energies, records, tangent, info, message) = out
        if info:
            self._failure(info, "force evaluation", message)
        return dict(internal=forces[:, _at("ff", "internal")],
                    external=forces[:, _at("ff", "external")],
                    strain=float(energies[_at("ee", "strain")]),
                    contact_potential=float(energies[_at("ee", "contact_potential")]),
                    records=records[:, :self.npoint],
                    tangent=tangent if want_tangent else None, guesses=guesses, counts=counts)

    def static_solve(self, *, t: float, load_factor: float, e0, rows, cols, e, lam, guesses,
                     counts, tol: float, length_scale: float, max_iter: int, check_start: bool,
                     force_scale: float, load_step: int, load_steps: int, mode: int = 0,
                     arc: float = 0.0, direction: float = 1.0, previous=None) -> dict:
        """One call of the kernel's static Newton (``fortran/src/solvers/static_solver.f90``)
        from (e, lam) at ``load_factor``, the tangent's pattern ``rows``, ``cols`` (0-based).
        ``mode`` 0: a load step, equilibrium at ``load_factor``; 1: one arc-length step of
        length ``arc`` from the converged (e, lam), the load factor an unknown (``previous``
        the previous step's increment of e, None on the first step, where ``direction`` is
        the sign of the load increment); 2: no step, the tangent along the loads at the
        state. ``force_scale`` < 0 is set from the start and returned. Returns e, lam, the
        contact guesses and counters, force_scale, iterations, the relative residual
        history, the last residual and constraint violation, the load factor reached,
        converged_by (static_solver's by_* code) and factorizations, with info and the
        kernel's message (0 and '' when converged); modes 1 and 2 also ||q||, ||du_q|| and
        q . du_q at the state on entry (load_norm, tangent_norm, flexibility; q = -dr/dP,
        du_q = K_T^{-1} q on the constraints)."""
        e = np.asarray(e, dtype=float)
        n, ncon = len(e), len(lam)
        guesses = np.asarray(guesses, dtype=float)[:, :self.npoint]
        state = np.concatenate([e, np.asarray(lam, dtype=float), guesses.ravel(order="F")])
        scales = _pack("sr", force_scale=force_scale, force_res=0.0, con_res=0.0,
                       load_factor=load_factor, load_norm=0.0, tangent_norm=0.0,
                       flexibility=0.0)
        vectors = np.zeros((n, len(KERNEL_LAYOUTS["sx"])), order="F")
        vectors[:, _at("sx", "reference")] = e0
        if previous is not None:
            vectors[:, _at("sx", "previous")] = previous
        out = _kernel.system_static_solve(
            self.handle, state, _i(np.array(counts)), vectors,
            _i(np.column_stack([np.asarray(rows) + 1, np.asarray(cols) + 1])),
            _pack("ss", time=t, load_factor=load_factor, tol=tol, length_scale=length_scale,
                  arc=arc, direction=direction),
            _pack("sc", np.int32, check_start=int(check_start), load_step=load_step,
                  load_steps=load_steps, mode=mode), max_iter, scales)
        state, counts, scales, history, outcome, message = out
        info, iterations = int(outcome[_at("so", "info")]), int(outcome[_at("so", "iterations")])
        guesses_out = np.zeros((2, max(1, self.npoint)), order="F")
        guesses_out[:, :self.npoint] = state[n + ncon:].reshape(2, self.npoint, order="F")
        figures = {name: float(scales[_at("sr", name)]) for name in KERNEL_LAYOUTS["sr"]}
        return dict(e=state[:n].copy(), lam=state[n:n + ncon].copy(), guesses=guesses_out,
                    counts=counts, iterations=iterations, history=history[:iterations].copy(),
                    converged_by=int(outcome[_at("so", "converged_by")]),
                    factorizations=int(outcome[_at("so", "factorizations")]), info=info,
                    message=_text(message) if info else "", **figures)

    def full_forces(self, t: float, e, v, guesses, *, load_factor: float = 1.0) -> np.ndarray:
        """Q_el - Q_c - lf Q_M at (t, e, e') in the full coordinates q (before B^T): what
        the joint reactions of eliminated linear joints are recovered from. The caller's
        contact guesses are not changed."""
        full, info, message = _kernel.system_full_forces(
            self.handle, self.nfull, self.npoint, t, _f(e), _f(v), load_factor,
            _f(np.array(guesses)), ndof=self.ndof)
        if info:
            self._failure(info, "full force evaluation", message)
        return full

    def energy_momentum_obstacle(self) -> str:
        """What of the model the energy-momentum stepper does not support ('' when it
        supports it): the kernel's own list (``fortran/src/solvers/energy_momentum.f90``)."""
        obstacle, info, message = _kernel.system_energy_momentum_check(self.handle)
        self._check(info, "energy_momentum_check", message)
        if isinstance(obstacle, bytes):
            obstacle = obstacle.decode("ascii", "replace")
        return str(obstacle).strip()

    def midpoint_residual(self, h: float, t: float, e0, v0, e1, lam,
                          want_jacobian: bool = False) -> dict:
        """The residual of one energy-momentum step (``fortran/src/solvers/
        energy_momentum.f90``) from (e0, v0) at t with step h, at (e1, lam): ``residual``
        (ndof + ncon), the reduced discrete-gradient force ``internal`` (ndof) and, on
        request, the ``jacobian`` in (e1, lam)."""
        ncon = len(lam)
        residual, internal, jacobian, info, message = _kernel.system_midpoint_residual(
            self.handle, ncon, h, t, np.asfortranarray(np.column_stack([e0, v0, e1]),
                                                       dtype=float),
            _f(lam) if ncon else np.zeros(1), int(want_jacobian), ndof=self.ndof)
        if info:
            self._failure(info, "midpoint residual", message)
        return dict(residual=residual, internal=internal,
                    jacobian=jacobian if want_jacobian else None)

    def output_row(self, t: float, e, v, lam, work, guesses, counts) -> dict:
        cut = self._layout(False)[1]
        out = _kernel.system_output_row(
            self.handle, self.ncon, self.npoint, cut[6].stop, t, _state(e, v),
            _f(lam) if len(lam) else np.zeros(1), _f(work), _f(guesses), _i(counts),
            ndof=self.ndof)
        (guesses, counts, row, powers, info, message) = out
        if info:
            self._failure(info, "output row", message)
        return dict(probes=row[cut[1]].reshape(self.nprobe, 3),
                    deflections=row[cut[2]].reshape(self.nprobe, 3), energy=row[cut[4]].copy(),
                    violation=float(row[cut[5]][0]),
                    records=row[cut[6]].reshape(self.npoint, len(CONTACT_RECORD)).T,
                    guesses=guesses, counts=counts, powers=powers)

    def contact_forces(self, e_full, rates_full, guesses, counts, *,
                       velocity_factor: float = 0.0, want_jacobian: bool = False) -> dict:
        """The contact forces of the system's contact pairs at the full coordinates and
        rates (leaf_contact%contact_assemble): force (full), records (6, npoint), potential,
        powers (damping, friction), the updated guesses and counters and, on request, the
        Jacobian of minus the forces on the full pattern (its CSR values)."""
        nnz = len(self._full_col) if want_jacobian else 1
        (guesses, counts, force, records, energies, values, info,
         message) = _kernel.system_contact_forces(
            self.handle, nnz, self.npoint, _state(e_full, rates_full), velocity_factor,
            int(want_jacobian), _f(guesses), _i(counts), nfull=self.nfull)
        if info:
            self._failure(info, "contact forces", message)
        return dict(force=force, records=records[:, :self.npoint],
                    potential=float(energies[_at("ce", "potential")]),
                    powers=energies[[_at("ce", "damping"), _at("ce", "friction")]],
                    guesses=guesses, counts=counts, values=values if want_jacobian else None)

    def _failure(self, info: int, what: str, message: bytes | str) -> None:
        """Raise with the kernel's text of the failure (a stale handle and inconsistent sizes
        are named as such, not as a solver failure)."""
        raise SolverError(f"{what}, kernel code {info}: {_text(message)}")

    def stepper_setup(self, settings) -> None:
        """Start a run of the kernel's stepper (``fortran/src/solvers/stepper.f90``) with the
        run's settings (a :class:`~ancfdrv.solvers.dynamic.DynamicSettings`: beta, gamma,
        alpha_m, alpha_f, tol, length_scale, max_newton, the Jacobian policy, contraction,
        and the step-size control: dt, dt_min, step, tolerance), sent once per run, not with
        every chunk. What the stepper learned in earlier runs (contraction estimate, a
        matrix factorized at another state, the step-size control's state) is forgotten: a
        run from a new initial state is reproducible."""
        info, message = _kernel.system_stepper_setup(
            self.handle, int(settings.integrator == "energy_momentum"), settings.beta,
            settings.gamma, settings.alpha_m, settings.alpha_f, settings.tol,
            settings.length_scale, settings.max_newton, settings.jacobian_code,
            settings.contraction,
            _pack("sk", dt=settings.dt, dt_min=settings.dt_min,
                  adaptive=float(settings.step == "adaptive"), tolerance=settings.tolerance))
        self._check(info, "stepper_setup", message)
        self.nanswer = 0   # (a new run's rows answer nothing until answer_setup)

    def answer_setup(self, columns, mass_rows, constant, driven) -> None:
        """Make the rows of the run set up by :meth:`stepper_setup` answer
        (``fortran/src/solvers/row_answers.f90``): each force element's reactions (7 values)
        and the residual of the equations of motion at the full coordinates ``columns``
        (0-based), from the full mass's rows there (``mass_rows``: a scipy CSR matrix, one
        row per column, over the full coordinates) and the loads there: ``constant`` (ncol,)
        and ``driven`` (ncol, one column per force drive, in the order of
        :meth:`set_loads`)."""
        columns = np.asarray(columns, dtype=np.int32)
        ncol, nnz = len(columns), int(mass_rows.nnz)
        driven = np.asarray(driven, dtype=float)   # (ncol, ndrive)
        info, message = _kernel.system_answer_setup(
            self.handle, ncol, nnz, driven.shape[1], _pad_last(columns + 1, np.int32),
            _i(np.asarray(mass_rows.indptr) + 1),
            _pad_last(np.asarray(mass_rows.indices) + 1, np.int32),
            _pad_last(np.asarray(mass_rows.data, dtype=float)),
            _pad_last(np.asarray(constant, dtype=float)),
            _f(driven if driven.size else np.zeros((max(ncol, 1), max(driven.shape[1], 1)))))
        self._check(info, "answer_setup", message)
        self.nanswer = 7 * getattr(self, "nfel", 0) + ncol

    def answer_row(self, t: float, e, v, accel, guesses) -> np.ndarray:
        """The answers of the state (t, e, e', e'') with the contact projections
        ``guesses``, in the layout of the answers of a row of :meth:`advance` (the run's
        initial row)."""
        out, info, message = _kernel.system_answer_row(
            self.handle, self.npoint, self.nanswer, t, _state(e, v), _f(accel),
            _f(np.array(guesses)), ndof=self.ndof)
        if info:
            self._failure(info, "answer row", message)
        return out[:self.nanswer]

    def consistent_acceleration(self, t: float, e, v, guesses, counts) -> dict:
        """The consistent acceleration e'' and multipliers lambda of the state (t, e, e')
        (``fortran/src/solvers/consistent_start.f90``); the contact guesses and counters are
        updated (returned). A failure raises SolverError with the kernel's text."""
        guesses, counts, accel, lam, info, message = _kernel.system_consistent_acceleration(
            self.handle, self.ncon, self.npoint, t, _state(e, v), _f(guesses), _i(counts),
            ndof=self.ndof)
        if info:
            raise SolverError(_text(message))
        return dict(accel=accel, lam=lam[:self.ncon], guesses=guesses, counts=counts)

    def _layout(self, store_q: bool) -> tuple[list[slice], list[slice]]:
        """The slices of the packed state (t, e, v, a, accel, lam, work, powers, guesses) and
        of an output row (time, probes, deflections, lam, energy, constraint, contact,
        answers, q): stepper.f90 ``state_size`` and ``row_size``; computed once per system,
        run answers (:meth:`answer_setup`) and store_q."""
        # kept per key: a run asks for both (the packed state's without q, the rows' with
        # it), and one kept layout was made again at each change (~9 us)
        key = (self.ndof, self.ncon, self.npoint, self.nprobe, getattr(self, "nanswer", 0),
               store_q)
        kept = self.__dict__.setdefault("_layouts", {})
        found = kept.get(key)
        if found is None:
            n, nc, npt, npr, nanswer = key[:5]

            def cut(lengths):
                edges = [0]
                for length in lengths:
                    edges.append(edges[-1] + int(length))
                return [slice(a, b) for a, b in zip(edges[:-1], edges[1:])]
            found = kept[key] = (
                cut([1, n, n, n, n, nc, POWER_COUNT, POWER_COUNT, 2 * npt]),
                cut([1, 3 * npr, 3 * npr, nc, ENERGY_COUNT, 1, len(CONTACT_RECORD) * npt,
                     nanswer, n if store_q else 0]))
        return found

    def state_size(self) -> int:
        """The length of the packed stepper state (stepper.f90 ``state_size``)."""
        return self._layout(False)[0][-1].stop

    def row_size(self, store_q: bool) -> int:
        """The length of one output row of :meth:`advance` (stepper.f90 ``row_size``)."""
        return self._layout(store_q)[1][-1].stop

    def packed_state(self, values: dict) -> PackedState:
        """A :class:`PackedState` of this system holding ``values`` (copied)."""
        values = dict(values)
        values.setdefault("counts", np.zeros(6, dtype=np.int32))
        values["counts"] = _i(values["counts"]).copy()
        return PackedState(self._layout(False)[0], self.npoint, values)

    def advance_rows(self, nrows: int, budget: int, state: dict, store_q: bool) -> tuple:
        """:meth:`advance` without unpacking the rows: (rows (row_size, nrows) in the layout
        of :meth:`row_slices`, stats (5, nrows), sizes (nrows,), status, figures, message),
        for the stepper's own loop (every numpy call counts)."""
        cuts, rows_cut = self._layout(store_q)
        npt = self.npoint
        if isinstance(state, PackedState) and len(state.packed) == cuts[-1].stop:
            # (system_advance_into: rows made by numpy.empty, which the kernel writes in
            # full; f2py would zero-fill system_advance's fresh output arrays first)
            rows = np.empty((rows_cut[-1].stop, nrows), order="F")
            stats = np.empty((5, nrows), dtype=np.int32, order="F")
            sizes = np.empty(nrows)
            packed, counts, status, figures, message = \
                _kernel.system_advance_into(self.handle, budget, state.packed,
                                            state["counts"], rows, stats, sizes)
            state.stepped(packed, counts)
            status = status.tolist()
            if status[1] == 9:
                self._failure(9, "system_advance", message)
        else:  # a plain dict: packed and unpacked on every call
            packed = np.empty(cuts[-1].stop)
            packed[0] = state["t"]
            for key, part in zip(_PACKED_ARRAYS, cuts[1:8]):
                packed[part] = state[key]
            if npt:
                packed[cuts[8]] = np.asarray(state["guesses"])[:, :npt].ravel(order="F")
            packed, counts, rows, stats, sizes, status, figures, message = \
                _kernel.system_advance(self.handle, nrows, budget, packed,
                                       _i(state["counts"]), rows_cut[-1].stop)
            status = [int(x) for x in status]
            if status[1] == 9:
                self._failure(9, "system_advance", message)
            state["t"] = float(packed[0])
            for key, part in zip(_PACKED_ARRAYS, cuts[1:8]):
                state[key] = packed[part]
            state["counts"] = counts
            if npt:  # (without contact the guesses are one unused column, left as they are)
                guesses = np.array(state["guesses"], dtype=np.float64)
                guesses[:, :npt] = packed[cuts[8]].reshape((2, npt), order="F")
                state["guesses"] = guesses
        return rows, stats, sizes, status, figures, message

    def row_slices(self, store_q: bool) -> list[slice]:
        """The slices of an output row (time, probes, deflections, lam, energy, constraint,
        contact, answers, q): stepper.f90 ``row_size``."""
        return self._layout(store_q)[1]

    def advance(self, nrows: int, state: dict, store_q: bool, budget: int | None = None) -> dict:
        """Advance up to nrows output rows of the run set up by :meth:`stepper_setup`
        (``fortran/src/solvers/step_control.f90``: whole chunks at dt, cut steps, restarts,
        adaptive steps) with at most ``budget`` steps tried (default: 1024 per row) from
        state (t, e, v, a, accel, lam, work, powers, guesses, counts; its entries are
        replaced by the new state's). Returns the outputs (time, probes (3, nprobe, nrows),
        deflections, lam, energy, constraint, contact, q, stats (5, nrows): corrections,
        factorizations, jacobians, substeps, cuts; sizes: the smallest step to each row),
        status and figures (codes.KERNEL_LAYOUTS 'as', 'af'), the kernel's text of a failure
        (``message``). A refused call (a stale handle, no run set up, sizes inconsistent
        with the system) raises SolverError with the kernel's text."""
        budget = 1024 * nrows if budget is None else budget
        rows, stats, sizes, status, figures, message = self.advance_rows(nrows, budget, state,
                                                                         store_q)
        npt = self.npoint
        rows_cut = self._layout(store_q)[1]
        time, probes, deflections, lam, energy, constraint, contact, _, q = rows_cut
        return dict(time=rows[0], probes=rows[probes].reshape((3, -1, nrows), order="F"),
                    deflections=rows[deflections].reshape((3, -1, nrows), order="F"),
                    lam=rows[lam], energy=rows[energy], constraint=rows[constraint.start],
                    contact=rows[contact].reshape((len(CONTACT_RECORD), npt, nrows),
                                                  order="F"),
                    q=rows[q] if store_q else np.zeros((self.ndof, 1)), stats=stats,
                    sizes=sizes, status=status, figures=figures,
                    message=_text(message) if status[1] else "")

    def close(self) -> None:
        if getattr(self, "handle", 0):
            _kernel.system_destroy(self.handle)
            self.handle = 0

    def __enter__(self) -> "KernelSystem":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __del__(self) -> None:
        try:
            self.close()
        except Exception:
            pass
