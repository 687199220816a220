"""Structured meshes of the thin-plate bodies: flat rectangles and curved leaves (circular
arcs), with their node numbering, element sizes and named node sets.

A node carries 9 coordinates [r, r_x, r_y]; an element 4 nodes (36 coordinates),
counter-clockwise from its (x0, y0) corner. ``x`` runs along the plate's length (for a leaf:
the arc length), ``y`` along its width. Node numbering runs fastest across the shorter side,
which keeps the band of the iteration matrix narrow.
"""
from __future__ import annotations

from dataclasses import field

import numpy as np

from ..records import record
from ..errors import InputError

PLATE_NODE_DOFS = 9


@record(eq=False, repr=False)
class PlateMesh:
    """Nodes (initial configuration), connectivity, element sizes and named node sets.

    ``coords`` is (nnodes, 9): r, r_x, r_y per node. ``grid[i, j]`` is the node at the
    i-th station along x and the j-th across y. Node numbering runs fastest across the
    shorter side, which keeps the banded solver's bandwidth small.
    """

    coords: np.ndarray
    elements: np.ndarray          # (nel, 4) node ids
    a: np.ndarray                 # (nel,) element length along x (parent coordinate)
    b: np.ndarray                 # (nel,) element width along y
    grid: np.ndarray              # (nx + 1, ny + 1) node ids
    node_sets: dict[str, np.ndarray] = field(default_factory=dict)

    @property
    def nnodes(self) -> int:
        return len(self.coords)

    @property
    def nel(self) -> int:
        return len(self.elements)


def _grid_mesh(stations_x: np.ndarray, stations_y: np.ndarray, node_vectors) -> PlateMesh:
    """A structured mesh; node_vectors(s, y) -> (r, r_x, r_y) of the point at parent
    coordinates (s, y)."""
    nx, ny = len(stations_x) - 1, len(stations_y) - 1
    if nx < 1 or ny < 1:
        raise InputError("a plate mesh needs at least one element in each direction")
    grid = np.zeros((nx + 1, ny + 1), dtype=int)
    for i in range(nx + 1):
        for j in range(ny + 1):
            grid[i, j] = i * (ny + 1) + j if ny <= nx else j * (nx + 1) + i
    coords = np.zeros((grid.size, PLATE_NODE_DOFS))
    for i, s in enumerate(stations_x):
        for j, y in enumerate(stations_y):
            coords[grid[i, j]] = np.concatenate(node_vectors(s, y))
    elements, a, b = [], [], []
    for j in range(ny):
        for i in range(nx):
            elements.append([grid[i, j], grid[i + 1, j], grid[i + 1, j + 1], grid[i, j + 1]])
            a.append(stations_x[i + 1] - stations_x[i])
            b.append(stations_y[j + 1] - stations_y[j])
    sets = {
        "edge_x0": grid[0, :], "edge_x1": grid[-1, :], "edge_y0": grid[:, 0],
        "edge_y1": grid[:, -1], "corner_00": grid[:1, 0], "corner_10": grid[-1:, 0],
        "corner_11": grid[-1:, -1], "corner_01": grid[:1, -1],
    }
    if nx % 2 == 0:
        sets["middle_x"] = grid[nx // 2, :]
    sets["boundary"] = np.unique(np.concatenate([grid[0, :], grid[-1, :], grid[:, 0],
                                                 grid[:, -1]]))
    return PlateMesh(coords, np.array(elements), np.array(a), np.array(b), grid, sets)


def flat_mesh(corner, edge_x, edge_y, nx: int, ny: int) -> PlateMesh:
    """A flat rectangular plate with its first corner at ``corner`` and the two (orthogonal)
    edge vectors edge_x, edge_y; nodal gradients r_x, r_y are the unit edge directions."""
    corner = np.asarray(corner, dtype=float)
    edge_x, edge_y = np.asarray(edge_x, dtype=float), np.asarray(edge_y, dtype=float)
    length_x, length_y = float(np.linalg.norm(edge_x)), float(np.linalg.norm(edge_y))
    if length_x <= 0.0 or length_y <= 0.0:
        raise InputError("plate edges must have a positive length")
    ux, uy = edge_x / length_x, edge_y / length_y
    if abs(ux @ uy) > 1e-9:
        raise InputError(f"plate edges are not orthogonal (cos = {ux @ uy:.3g}): the thin plate "
                         "element needs rectangular elements")

    def vectors(s: float, y: float):
        return corner + s * ux + y * uy, ux.copy(), uy.copy()
    return _grid_mesh(np.linspace(0.0, length_x, nx + 1), np.linspace(0.0, length_y, ny + 1),
                      vectors)


def rectangle_mesh(length_x: float, length_y: float, nx: int, ny: int,
                   origin=(0.0, 0.0, 0.0)) -> PlateMesh:
    """A flat rectangular plate in the r1-r2 plane with corner (0, 0) at ``origin``."""
    return flat_mesh(origin, (length_x, 0.0, 0.0), (0.0, length_y, 0.0), nx, ny)


def arc_point(s: float, radius: float, z_offset: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Point and unit tangent at arc length s from the middle of a circular arc in the
    r1-r3 plane, concave up (its centre above the middle point), lowest point at r3 =
    z_offset; radius = inf gives the straight line."""
    if not np.isfinite(radius):
        return np.array([s, 0.0, z_offset]), np.array([1.0, 0.0, 0.0])
    theta = s / radius
    return (np.array([radius * np.sin(theta), 0.0, z_offset + radius * (1.0 - np.cos(theta))]),
            np.array([np.cos(theta), 0.0, np.sin(theta)]))


def arc_mesh(arc_length: float, radius: float, width: float, nx: int, ny: int,
             z_offset: float = 0.0, centre=(0.0, 0.0, 0.0)) -> PlateMesh:
    """A leaf: a cylindrical strip bent about r2, symmetric about r1 = 0, concave up, its
    mid-surface given by arc length x in [-L/2, L/2] and width y in [-w/2, w/2]. The
    nodal gradients are exact (unit tangent, r_y = e2), so the parent coordinates measure
    reference length."""
    if np.isfinite(radius) and arc_length > 2 * np.pi * radius:
        raise InputError(f"leaf arc length {arc_length} m exceeds the circle of radius "
                         f"{radius} m")

    shift = np.asarray(centre, dtype=float)

    def vectors(s: float, y: float):
        point, tangent = arc_point(s, radius, z_offset)
        return point + [0.0, y, 0.0] + shift, tangent, np.array([0.0, 1.0, 0.0])
    return _grid_mesh(np.linspace(-arc_length / 2, arc_length / 2, nx + 1),
                      np.linspace(-width / 2, width / 2, ny + 1), vectors)
