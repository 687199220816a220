"""Beam cross-sections: solid rectangle, box (hollow rectangle), tube and solid circle.

Each section is integrated exactly over its area by a quadrature rule of the kernel
(``fortran/src/elements/beam_section.f90``): the mass and small-strain stiffness need the
moments up to second order, which every rule integrates exactly; the tube and circle rules
are exact to fifth order, the rectangle and box rules for y^a z^b with a, b <= 3. The section
height runs along the beam's ``height_axis`` (the director r_y), the width along r_z.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from .. import kernel
from ..codes import SECTION_BOX, SECTION_CIRCLE, SECTION_RECTANGLE, SECTION_TUBE


class Section:
    """A cross-section; :attr:`data` is its kernel rule and properties."""

    kind: int

    @property
    def dims(self) -> tuple[float, ...]:
        raise NotImplementedError

    @cached_property
    def data(self) -> kernel.SectionData:
        """Quadrature points and weights, A, I_y, I_z, polar moment (kernel.SectionData);
        raises InputError for non-physical dimensions."""
        return kernel.section_data(self.kind, self.dims)

    @property
    def extent(self) -> tuple[float, float]:
        """Half the section's size along y (height) and z (width)."""
        raise NotImplementedError

    # -- what the section forces and stresses use (ancfdrv.system.answers) ------------------
    @property
    def torsion_constant(self) -> float:
        """J (m^4) of the torsion moment T = G J theta' the section forces report; today
        the kernel's I_y + I_z (exact for the tube and circle)."""
        return self.data.polar

    @property
    def shear_factors(self) -> tuple[float, float]:
        """Shear factors (k_y, k_z) of the shear forces Q = k G A gamma along the height and
        width; today the kernel's k = 1."""
        return (1.0, 1.0)

    @property
    def fibre_points(self) -> "np.ndarray":
        """(n, 2) points (y along the height, z along the width; m) of the outer fibres or
        walls where the stresses are evaluated: the outline of the section."""
        half_y, half_z = self.extent
        if isinstance(self, (Tube, Circle)):
            angle = np.linspace(0.0, 2.0 * np.pi, 48, endpoint=False)
            return np.column_stack([half_y * np.cos(angle), half_y * np.sin(angle)])
        edge = np.linspace(-1.0, 1.0, 5)   # corners, quarters and middles of the edges
        ones = np.ones_like(edge)
        outline = np.vstack([np.column_stack([half_y * ones, half_z * edge]),
                             np.column_stack([-half_y * ones, half_z * edge]),
                             np.column_stack([half_y * edge, half_z * ones]),
                             np.column_stack([half_y * edge, -half_z * ones])])
        return np.unique(outline, axis=0)


@dataclass(frozen=True)
class Rectangle(Section):
    """Solid rectangle: width along r_z, height along r_y (m)."""

    width: float
    height: float
    kind = SECTION_RECTANGLE

    @property
    def dims(self) -> tuple[float, ...]:
        return (self.width, self.height)

    @property
    def extent(self) -> tuple[float, float]:
        return (0.5 * self.height, 0.5 * self.width)


@dataclass(frozen=True)
class Box(Section):
    """Hollow rectangle (box girder): outer width and height, wall thickness (m)."""

    width: float
    height: float
    wall: float
    kind = SECTION_BOX

    @property
    def dims(self) -> tuple[float, ...]:
        return (self.width, self.height, self.wall)

    @property
    def extent(self) -> tuple[float, float]:
        return (0.5 * self.height, 0.5 * self.width)


@dataclass(frozen=True)
class Tube(Section):
    """Circular tube: outer diameter and wall thickness (m)."""

    diameter: float
    wall: float
    kind = SECTION_TUBE

    @property
    def dims(self) -> tuple[float, ...]:
        return (self.diameter, self.wall)

    @property
    def extent(self) -> tuple[float, float]:
        return (0.5 * self.diameter, 0.5 * self.diameter)


@dataclass(frozen=True)
class Circle(Section):
    """Solid circle: diameter (m)."""

    diameter: float
    kind = SECTION_CIRCLE

    @property
    def dims(self) -> tuple[float, ...]:
        return (self.diameter,)

    @property
    def extent(self) -> tuple[float, float]:
        return (0.5 * self.diameter, 0.5 * self.diameter)


SECTIONS = {"rectangle": Rectangle, "box": Box, "tube": Tube, "circle": Circle}
