"""Typed access to the compiled Fortran kernel (the f2py module ``_kernel``).

Every kernel routine returns an error code; the wrappers here turn non-zero codes into
:class:`~ancfdrv.errors.SolverError` / :class:`~ancfdrv.errors.InputError` with a clear
message. Arrays are handed over in Fortran order so f2py does not copy them twice.
"""
from __future__ import annotations

import numpy as np

from . import _kernel
from .errors import InputError, SolverError

__all__ = ["beam_element_arrays", "beam_gravity", "beam_shape", "beam_point_mass",
           "ffr_force", "ffr_element_stiffness", "moment_force", "drive_values",
           "constraint_evaluate", "SparsePattern", "DirectSolver", "plate_shape",
           "plate_element_arrays", "plate_reference", "plate_forces", "PlateReference",
           "StructuralBeam"]


def _f(a, dtype=np.float64) -> np.ndarray:
    return np.asfortranarray(a, dtype=dtype)


def beam_element_arrays(lengths, width, height, density, youngs, poisson, reference):
    """Compact mass (8, 8, nel) and small-strain stiffness K0 (24, 24, nel) per element.

    ``reference`` is (3, 8, nel): the element's nodal vectors in the floating frame.
    """
    mass, stiffness, info = _kernel.beam_element_arrays(_f(lengths), width, height, density,
                                                        youngs, poisson, _f(reference))
    if info:
        element, code = divmod(info, 10)
        reason = {1: "unsupported quadrature", 2: "degenerate reference geometry (det J0 <= 0)"}
        raise InputError(f"beam element {element}: {reason.get(code, f'code {code}')}")
    return mass, stiffness


def beam_gravity(lengths, width, height, density, gravity) -> np.ndarray:
    """Generalized gravity (3, 8, nel) per element."""
    force, info = _kernel.beam_gravity(_f(lengths), width, height, density, _f(gravity))
    if info:
        raise SolverError(f"beam gravity: kernel code {info}")
    return force


def beam_shape(xi, y, z, lengths):
    """Shape functions (8, npts) and derivatives d/dx, d/dy, d/dz at material points."""
    return _kernel.beam_shape_functions(_f(xi), _f(y), _f(z), _f(lengths))


def beam_point_mass(xi, y, z, length, mass) -> np.ndarray:
    """Compact (8, 8) mass of a point mass at a material point of an element."""
    return _kernel.beam_point_mass(xi, y, z, length, mass)


def beam_nonlinear_setup(reference, lengths, width, height):
    """Material gradients (8, 3, npts, nel) and weights (npts, nel) at the Gauss points of
    the large-deformation beam, from the reference configuration (3, 8, nel)."""
    npts = int(_kernel.beam_nonlinear_points())
    gradients, weights, info = _kernel.beam_nonlinear_setup(npts, _f(reference), _f(lengths),
                                                            width, height)
    if info:
        element, code = divmod(info, 10)
        raise InputError(f"beam element {element}: degenerate reference geometry "
                         f"(det J0 <= 0, code {code})")
    return gradients, weights


def beam_nonlinear_forces(dofs, e, gradients, weights, youngs, poisson, want_tangent: bool):
    """Large-deformation elastic force, strain energy and element tangents (24, 24, nel)."""
    return _kernel.beam_nonlinear_forces(_f(dofs + 1, np.int32), _f(e), gradients, weights,
                                         youngs, poisson, int(want_tangent))


class StructuralBeam:
    """Strain forms, reference strains and stiffnesses of the 'cubic' bending option
    (beam_structural.structural_setup) for a mesh with reference nodal vectors (3, 8, nel)."""

    def __init__(self, reference, lengths, width, height, youngs, poisson) -> None:
        nterms = int(_kernel.beam_structural_size())
        (self.forms, self.strain0, self.stiffness,
         info) = _kernel.beam_structural_setup(nterms, _f(reference), _f(lengths), width, height,
                                               youngs, poisson)
        if info:
            element, code = divmod(info, 10)
            reason = {1: "unsupported quadrature",
                      2: "degenerate reference geometry (r0_x vanishes)"}
            raise InputError(f"beam element {element}: {reason.get(code, f'code {code}')}")

    def forces(self, dofs, e, want_tangent: bool):
        """Elastic force, strain energy and element tangents (24, 24, nel) at e."""
        return _kernel.beam_structural_forces(_f(dofs + 1, np.int32), _f(e), self.forms,
                                              self.strain0, self.stiffness, int(want_tangent))


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
        reference.weights, youngs, poisson, thickness, int(want_tangent))
    if info:
        element, code = divmod(info, 1000)
        raise SolverError(f"plate element {element}: the mid-surface normal vanished "
                          f"(r_x parallel to r_y): the configuration is degenerate")
    return force, energy, tangent


def ffr_force(dofs, stiffness0, rotation, e, e0_frame):
    """FFR elastic force T K0 (T^T e - e0) and strain energy. ``dofs`` are 0-based (24, nel)."""
    return _kernel.ffr_elastic_force(_f(dofs + 1, np.int32), stiffness0, _f(rotation), _f(e),
                                     _f(e0_frame))


def ffr_element_stiffness(stiffness0, rotation) -> np.ndarray:
    """Element stiffness matrices T K0 T^T (24, 24, nel)."""
    return _kernel.ffr_element_stiffness(stiffness0, _f(rotation))


def moment_force(director, axis, magnitude):
    """Dead moment on a section director: force (3,), Jacobian (3, 3), Hessian (3, 3, 3)."""
    force, jacobian, hessian, info = _kernel.moment_generalized_force(_f(director), _f(axis),
                                                                      magnitude)
    if info:
        raise SolverError("bending moment: the section director became parallel to the "
                          "moment axis, the section rotation is undefined")
    return force, jacobian, hessian


def drive_values(kind: int, params, t):
    """phi, phi', phi'' of a drive at the times t."""
    p = np.zeros(8)
    p[:len(params)] = params
    phi, dphi, ddphi, info = _kernel.drive_values(kind, p, _f(np.atleast_1d(t)))
    if info:
        raise InputError(f"drive kind {kind} with parameters {list(params)}: "
                         + ("unknown kind" if info == 1 else "non-physical parameters"))
    return phi, dphi, ddphi


def constraint_evaluate(ints, reals, drive_kinds, drive_params, e, e_dot, t):
    """Values, gradients (6, ncon), Hessians (6, 6, ncon), Phi_t, Phi_tt, gamma."""
    values, gradients, hessians, phi_t, phi_tt, gamma, info = _kernel.constraint_evaluate(
        _f(ints, np.int32), _f(reals), _f(drive_kinds, np.int32), _f(drive_params), _f(e),
        _f(e_dot), t)
    if info > 0:
        raise InputError(f"constraint {info} is malformed (kind or dof indices)")
    if info < 0:
        raise InputError(f"the drive of constraint {-info} has non-physical parameters")
    return values, gradients, hessians, phi_t, phi_tt, gamma


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
    """Sparse direct solver (sequential MUMPS) behind a kernel handle.

    Analyse a coordinate pattern once, factorize as values change, solve many right-hand
    sides per factorization. Use as a context manager or call :meth:`close`.
    """

    def __init__(self, n: int, rows: np.ndarray, cols: np.ndarray, *, symmetric: bool = False,
                 banded_spd: bool = False, what: str = "system matrix") -> None:
        """``banded_spd`` selects LAPACK's banded Cholesky for a symmetric matrix with a narrow
        band (O(n kd) solves without MUMPS's per-call overhead); a matrix that turns out not
        to be positive definite is factorized by the pivoted banded LU instead (give both
        triangles)."""
        self.what = what
        handle, info, detail = _kernel.direct_create(3 if banded_spd else 2 if symmetric else 0)
        self._check(info, detail, "create")
        self.handle, self.n, self.nnz = handle, n, len(rows)
        self.factorizations = 0
        self.solves = 0
        info, detail = _kernel.direct_analyse(handle, n, _f(np.asarray(rows) + 1, np.int32),
                                              _f(np.asarray(cols) + 1, np.int32))
        self._check(info, detail, "analyse")

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


# -- rigid bodies and leaf contact (seed 003, eqs. 17-32) ---------------------------------
def reference_node_mass(mass: float, centre, inertia) -> np.ndarray:
    """12 x 12 mass matrix of an ANCF reference node (eq. 32), coordinates [r, r_x, r_y, r_z]."""
    matrix, info = _kernel.reference_node_mass(mass, _f(centre), _f(inertia))
    if info == 1:
        raise InputError(f"rigid body mass {mass} must be positive")
    if info == 2:
        raise InputError("rigid body inertia tensor is not symmetric or not physical (its "
                         "principal moments violate the triangle inequality)")
    return matrix


#: contact_params layout of fortran/src/leaf_contact.f90
CONTACT_PARAMS = ("stiffness", "damping", "friction", "slip_velocity", "upper_thickness",
                  "lower_thickness", "friction_on")


def contact_params(stiffness: float, damping: float, friction: float, slip_velocity: float,
                   upper_thickness: float, lower_thickness: float, friction_on: bool) -> np.ndarray:
    return np.array([stiffness, damping, friction, slip_velocity, upper_thickness,
                     lower_thickness, 1.0 if friction_on else 0.0, 0.0])


def contact_pair(upper, upper_rates, a_u, b_u, xi_q, eta_q, lower, lower_rates, a_l, b_l, xi_p,
                 eta_p, params, velocity_factor: float = 0.0) -> dict:
    """One contact pair: element coordinates (3, 12) and rates; forces on the upper and lower
    element, Jacobian of minus the forces (72 x 72), record (penetration, F_n, |F_t|, slip),
    penalty potential and powers (damping, friction)."""
    (fu, fl, jac, record, potential, powers, active, info) = _kernel.contact_pair(
        _f(upper), _f(upper_rates), a_u, b_u, xi_q, eta_q, _f(lower), _f(lower_rates), a_l, b_l,
        xi_p, eta_p, _f(params), velocity_factor)
    if info:
        raise SolverError("contact pair: a mid-surface normal vanished")
    return dict(force_upper=fu, force_lower=fl, jacobian=jac, record=record,
                potential=float(potential), powers=powers, active=bool(active))


def contact_projection(e, dofs, sizes, grid, point, guess) -> tuple[np.ndarray, int, int]:
    """Closest point (leaf-level coordinates) of the upper mid-surface grid to ``point``;
    returns it with the Newton iterations and fallback sweeps used."""
    guess, counts, info = _kernel.contact_projection(
        _f(e), _f(np.asarray(dofs) + 1, np.int32), _f(sizes), _f(np.asarray(grid) + 1, np.int32),
        _f(point), _f(guess))
    if info:
        raise SolverError("contact search: no closest point found")
    return guess, int(counts[0]), int(counts[1])


def contact_evaluate(e, rates, dofs, sizes, grid, point_element, point_local, params, guesses,
                     counts, velocity_factor: float = 0.0, pattern: "SparsePattern | None" = None):
    """All contact points (see leaf_contact%contact_assemble): force (full), records
    (6, npoints), potential, powers, updated guesses and counters, and the Jacobian's CSR
    values on ``pattern`` when given."""
    n = len(e)
    if pattern is None:
        row_ptr, col, want = np.ones(n + 1, np.int32), np.ones(1, np.int32), 0
    else:
        row_ptr, col, want = pattern.row_ptr + 1, pattern.col_index + 1, 1
    (guesses, counts, force, records, potential, powers, values, info) = _kernel.contact_evaluate(
        _f(e), _f(rates), _f(np.asarray(dofs) + 1, np.int32), _f(sizes),
        _f(np.asarray(grid) + 1, np.int32), _f(np.asarray(point_element) + 1, np.int32),
        _f(point_local), _f(params), velocity_factor, want, _f(row_ptr, np.int32),
        _f(col, np.int32), _f(guesses), _f(counts, np.int32))
    if info == 8:
        raise SolverError("contact search: no closest point found on the upper leaf")
    if info:
        raise SolverError("contact: a mid-surface normal vanished")
    return dict(force=force, records=records, potential=float(potential), powers=powers,
                guesses=guesses, counts=counts, values=values if pattern is not None else None)
