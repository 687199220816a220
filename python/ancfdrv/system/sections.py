"""Beam cross-sections: solid rectangle, box (hollow rectangle), tube, solid circle, a
general section given by its properties, and the standard steel sections (IPE, HEA, HEB,
RHS, SHS, CHS: :class:`Standard`, a general section with the numbers of
:mod:`.section_tables`).

Each section is integrated exactly over its area by a quadrature rule of the kernel
(``fortran/src/elements/beam_section.f90``): the mass and small-strain stiffness need the
moments up to second order, which every rule integrates exactly; the tube and circle rules
are exact to fifth order, the rectangle and box rules for y^a z^b with a, b <= 3. The section
height runs along the beam's ``height_axis`` (the director r_y), the width along r_z.

The public properties every section has (docs/theory.md, "Sections"): ``area``, ``iy``
(int z^2 dA, bending about the height axis y), ``iz`` (int y^2 dA), ``torsion_constant``
(Saint-Venant J: rectangle by the series of Timoshenko & Goodier, box by Bredt-Batho on the
wall's midline plus the walls' own open-section share, tube and circle exact, J = I_p),
:meth:`Section.shear_factors` (1 by default, as before issue 20; ``shear='cowper'``:
Cowper 1966, which depend on Poisson's ratio) and
:meth:`Section.fibre_points` (the outer-fibre points (y, z) at which stresses peak).
"""
from __future__ import annotations

import math
from functools import cached_property

import numpy as np

from ..records import record
from .. import kernel
from ..codes import SECTION_BOX, SECTION_CIRCLE, SECTION_RECTANGLE, SECTION_TUBE
from ..errors import InputError
from ..io.schema import short_repr
from .._lazy import LazyModule

#: the catalogue of standard sections (IPE200, ...), imported on the first standard
#: designation: a scene of plain shapes never reads it (its import, with difflib's for the
#: nearest names, was ~2 ms of a small ``ancf run``'s start)
section_tables = LazyModule("ancfdrv.system.section_tables")


def rectangle_torsion_constant(width: float, height: float, terms: int = 50) -> float:
    """Saint-Venant torsion constant of a solid rectangle (Timoshenko & Goodier, Theory of
    Elasticity, ch. 10): with b <= h the short and long sides,
    J = b^3 h / 3 [1 - (192/pi^5)(b/h) sum_{n odd} tanh(n pi h / (2 b)) / n^5];
    the series' terms fall as n^-5 (50 terms: relative error below 1e-9)."""
    b, h = min(width, height), max(width, height)
    series = sum(math.tanh(n * math.pi * h / (2.0 * b)) / n**5 for n in range(1, 2 * terms, 2))
    return b**3 * h / 3.0 * (1.0 - 192.0 / math.pi**5 * (b / h) * series)


def box_torsion_constant(width: float, height: float, wall: float) -> float:
    """Torsion constant of a box of uniform wall t: Bredt-Batho on the wall's midline,
    4 A_m^2 / oint(ds / t) = 4 A_m^2 t / p (A_m = (w - t)(h - t), p = 2 (w - t + h - t)),
    plus the walls' own (open-section) share p t^3 / 3, which the thin-wall formula drops:
    it keeps J within a few percent up to the solid limit (t -> w/2 for a square: 0.146 w^4
    against the exact 0.1406 w^4, where Bredt-Batho alone gives 0.0625 w^4)."""
    bm, hm = width - wall, height - wall
    perimeter = 2.0 * (bm + hm)
    return 4.0 * (bm * hm) ** 2 * wall / perimeter + perimeter * wall**3 / 3.0


def _cowper_box(web: float, flange: float, wall: float, poisson: float) -> float:
    """Cowper's (1966, Table 1) shear factor of a thin-walled box for shear along the webs
    (depth h = web, width b = flange on the midline, equal walls: m = b t1/(h t) = b/h,
    n = b/h)."""
    m = n = flange / web
    nu = poisson
    return (10.0 * (1.0 + nu) * (1.0 + 3.0 * m) ** 2 /
            ((12.0 + 72.0 * m + 150.0 * m**2 + 90.0 * m**3)
             + nu * (11.0 + 66.0 * m + 135.0 * m**2 + 90.0 * m**3)
             + 10.0 * n**2 * ((3.0 + nu) * m + 3.0 * m**2)))


def _circle_points(radius: float, count: int = 16) -> np.ndarray:
    angles = 2.0 * math.pi * np.arange(count) / count
    return radius * np.column_stack([np.cos(angles), np.sin(angles)])


class Section:
    """A cross-section: :attr:`data` is its kernel rule, and the properties below are what
    the beam elements and the stress recovery use (docs/theory.md, "Sections")."""

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

    # -- properties (the stress recovery's and the elements' API) ----------------------
    @property
    def area(self) -> float:
        """Cross-section area A (m^2)."""
        return self.data.area

    @property
    def iy(self) -> float:
        """I_y = int z^2 dA (m^4): bending stiffness E I_y for bending along the width z."""
        return self.data.inertia_y

    @property
    def iz(self) -> float:
        """I_z = int y^2 dA (m^4): bending along the height y (about the width axis z)."""
        return self.data.inertia_z

    @property
    def polar(self) -> float:
        """Polar moment I_p = I_y + I_z (m^4)."""
        return self.data.polar

    @property
    def torsion_constant(self) -> float:
        """Saint-Venant torsion constant J (m^4): G J is the torsional stiffness."""
        raise NotImplementedError

    #: 'unit' (k = 1, the default: the elements' behaviour before issue 20, which the
    #: shipped scenes and their references keep) or 'cowper' (Cowper 1966)
    shear: str = "unit"

    def shear_factors(self, poisson: float) -> tuple[float, float]:
        """Shear factors (k_y, k_z) for shear along the height and the width, the shear
        stiffnesses being k G A: 1 unless the section was made with shear='cowper'
        (then :meth:`cowper_shear_factors`)."""
        if self.shear == "cowper":
            return self.cowper_shear_factors(poisson)
        if self.shear != "unit":
            raise InputError(f"{type(self).__name__.lower()} section: shear = {self.shear!r} "
                             "must be 'unit' or 'cowper'")
        return (1.0, 1.0)

    def cowper_shear_factors(self, poisson: float) -> tuple[float, float]:
        """Cowper's (1966) shear factors (k_y, k_z) of the section at Poisson's ratio."""
        raise NotImplementedError

    def fibre_points(self) -> np.ndarray:
        """(n, 2) points (y, z) of the outer fibres (corners, or the circumference), where
        the bending and torsion stresses of the section peak."""
        raise NotImplementedError

    def shear_scales(self, poisson: float) -> tuple[float, float, float]:
        """The continuum element's torsion and shear correction [c, d_y, d_z] (docs/theory.md):
        c = J / I_p scales G on the twist-carrying shears over the section, d = k - c adds
        the rest of k G A on the neutral axis."""
        c = self.torsion_constant / self.polar
        k_y, k_z = self.shear_factors(poisson)
        return (c, k_y - c, k_z - c)

    def mass_rule(self, density: float) -> tuple[kernel.SectionData, float]:
        """The rule and density that integrate the mass (and gravity): the section's own
        with the material's density, unless a general section gives its mass."""
        return self.data, density


@record(frozen=True)
class Rectangle(Section):
    """Solid rectangle: width along r_z, height along r_y (m)."""

    width: float
    height: float
    shear: str = "unit"
    kind = SECTION_RECTANGLE

    @property
    def dims(self) -> tuple[float, ...]:
        return (self.width, self.height)

    @property
    def extent(self) -> tuple[float, float]:
        return (0.5 * self.height, 0.5 * self.width)

    @property
    def torsion_constant(self) -> float:
        return rectangle_torsion_constant(self.width, self.height)

    def cowper_shear_factors(self, poisson: float) -> tuple[float, float]:
        k = 10.0 * (1.0 + poisson) / (12.0 + 11.0 * poisson)
        return (k, k)

    def fibre_points(self) -> np.ndarray:
        hy, hz = self.extent
        return np.array([[hy, hz], [-hy, hz], [-hy, -hz], [hy, -hz]])


@record(frozen=True)
class Box(Section):
    """Hollow rectangle (box girder): outer width and height, wall thickness (m)."""

    width: float
    height: float
    wall: float
    shear: str = "unit"
    kind = SECTION_BOX

    @property
    def dims(self) -> tuple[float, ...]:
        return (self.width, self.height, self.wall)

    @property
    def extent(self) -> tuple[float, float]:
        return (0.5 * self.height, 0.5 * self.width)

    @property
    def torsion_constant(self) -> float:
        return box_torsion_constant(self.width, self.height, self.wall)

    def cowper_shear_factors(self, poisson: float) -> tuple[float, float]:
        web, flange = self.height - self.wall, self.width - self.wall
        return (_cowper_box(web, flange, self.wall, poisson),
                _cowper_box(flange, web, self.wall, poisson))

    def fibre_points(self) -> np.ndarray:
        hy, hz = self.extent
        return np.array([[hy, hz], [-hy, hz], [-hy, -hz], [hy, -hz]])


@record(frozen=True)
class Tube(Section):
    """Circular tube: outer diameter and wall thickness (m)."""

    diameter: float
    wall: float
    shear: str = "unit"
    kind = SECTION_TUBE

    @property
    def dims(self) -> tuple[float, ...]:
        return (self.diameter, self.wall)

    @property
    def extent(self) -> tuple[float, float]:
        return (0.5 * self.diameter, 0.5 * self.diameter)

    @property
    def torsion_constant(self) -> float:
        return self.polar   # exact: a tube does not warp

    def cowper_shear_factors(self, poisson: float) -> tuple[float, float]:
        m = (0.5 * self.diameter - self.wall) / (0.5 * self.diameter)   # r_i / r_o
        nu, a = poisson, (1.0 + m * m) ** 2
        k = 6.0 * (1.0 + nu) * a / ((7.0 + 6.0 * nu) * a + (20.0 + 12.0 * nu) * m * m)
        return (k, k)

    def fibre_points(self) -> np.ndarray:
        return _circle_points(0.5 * self.diameter)


@record(frozen=True)
class Circle(Section):
    """Solid circle: diameter (m)."""

    diameter: float
    shear: str = "unit"
    kind = SECTION_CIRCLE

    @property
    def dims(self) -> tuple[float, ...]:
        return (self.diameter,)

    @property
    def extent(self) -> tuple[float, float]:
        return (0.5 * self.diameter, 0.5 * self.diameter)

    @property
    def torsion_constant(self) -> float:
        return self.polar   # exact: a circle does not warp

    def cowper_shear_factors(self, poisson: float) -> tuple[float, float]:
        k = 6.0 * (1.0 + poisson) / (7.0 + 6.0 * poisson)
        return (k, k)

    def fibre_points(self) -> np.ndarray:
        return _circle_points(0.5 * self.diameter)


def _positive_number(value, key: str, where: str) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{where}: {key} = {value!r} is not a number") from None
    if not (math.isfinite(number) and number > 0.0):
        raise InputError(f"{where}: {key} = {value!r} must be a positive number")
    return number


def _four_point_rule(area: float, iy: float, iz: float) -> kernel.SectionData:
    """Points (y, z) = (+-sqrt(iz/area), +-sqrt(iy/area)) with weights area/4: they integrate
    1, y^2, z^2 to area, iz, iy (and every odd moment to 0)."""
    half_y, half_z = math.sqrt(iz / area), math.sqrt(iy / area)
    y = np.array([-half_y, half_y, -half_y, half_y])
    z = np.array([-half_z, -half_z, half_z, half_z])
    return kernel.SectionData(SECTION_RECTANGLE, (2.0 * half_z, 2.0 * half_y, 0.0), y, z,
                              np.full(4, 0.25 * area), area, iy, iz, iy + iz)


class General(Section):
    """A section given by its properties, as a section table or a benchmark lists them:
    area A, I_y = int z^2 dA, I_z = int y^2 dA, the torsion constant J and the shear factors
    k_y, k_z (the shear stiffnesses are k G A; a benchmark's G A_s gives k = G A_s / (G A)).
    Optional: ``mass_per_length`` (kg/m; default density times A), ``rotary_inertia`` =
    (r_x, r_y, r_z) (kg m, per unit length; default density times (I_y + I_z, I_y, I_z)) and
    ``fibre_points`` ((y, z) pairs for the stresses; default the corners of the rectangle
    with the same I_y/A and I_z/A).

    ``rotary_inertia`` = (r_x, r_y, r_z): r_x = int rho (y^2 + z^2) dA about the beam's axis,
    r_y = int rho z^2 dA (turning about the height axis), r_z = int rho y^2 dA. The beam's
    section field is linear (its directors r_y, r_z carry the rotary inertia), so r_x =
    r_y + r_z is required.

    The elements integrate the section with four points (+-sqrt(I_z/A), +-sqrt(I_y/A)) of
    weight A/4 (the same A, I_y, I_z), and the mass with four points (+-sqrt(r_z/m),
    +-sqrt(r_y/m)) of weight m/4 (m the mass per length).
    """

    kind = SECTION_RECTANGLE

    def __init__(self, area: float, iy: float, iz: float, torsion_constant: float,
                 shear_factor_y: float, shear_factor_z: float, *,
                 mass_per_length: float | None = None, rotary_inertia=None, fibre_points=None,
                 where: str = "section 'general'") -> None:
        self._area = _positive_number(area, "area", where)
        self._iy = _positive_number(iy, "iy", where)
        self._iz = _positive_number(iz, "iz", where)
        self._torsion = _positive_number(torsion_constant, "torsion_constant", where)
        self._shear = (_positive_number(shear_factor_y, "shear_factor_y", where),
                       _positive_number(shear_factor_z, "shear_factor_z", where))
        self.mass_per_length = None if mass_per_length is None else \
            _positive_number(mass_per_length, "mass_per_length", where)
        self.rotary_inertia = None
        if rotary_inertia is not None:
            try:
                values = [float(v) for v in rotary_inertia]
            except (TypeError, ValueError):
                raise InputError(f"{where}: rotary_inertia = {rotary_inertia!r} must be three "
                                 "numbers r_x, r_y, r_z") from None
            if len(values) != 3:
                raise InputError(f"{where}: rotary_inertia = {rotary_inertia!r} must be three "
                                 "numbers r_x, r_y, r_z")
            rx, ry, rz = (_positive_number(v, k, where)
                          for v, k in zip(values, ("rotary_inertia r_x", "rotary_inertia r_y",
                                                   "rotary_inertia r_z")))
            if abs(rx - (ry + rz)) > 1e-9 * rx:
                raise InputError(f"{where}: rotary_inertia = {values}: r_x must equal r_y + r_z "
                                 f"(= {ry + rz:g}); the beam's section turns rigidly with its "
                                 "two directors, whose inertias add up about the axis")
            self.rotary_inertia = (rx, ry, rz)
        self._fibres = None
        if fibre_points is not None:
            points = np.asarray(fibre_points, dtype=float)
            if points.size == 0 or points.size % 2 or not np.all(np.isfinite(points)):
                raise InputError(f"{where}: fibre_points = {fibre_points!r} must be pairs (y, z)")
            self._fibres = points.reshape(-1, 2)
        self.where = where

    @property
    def dims(self) -> tuple[float, ...]:
        """Width and height of the rectangle with the same I_y / A and I_z / A."""
        return (math.sqrt(12.0 * self._iy / self._area), math.sqrt(12.0 * self._iz / self._area))

    @cached_property
    def data(self) -> kernel.SectionData:
        """Four points (+-sqrt(I_z/A), +-sqrt(I_y/A)) of weight A/4: the 2 x 2 Gauss rule of
        the rectangle with the same I_y/A and I_z/A, its weights scaled to the area A."""
        return _four_point_rule(self._area, self._iy, self._iz)

    @property
    def extent(self) -> tuple[float, float]:
        if self._fibres is not None:
            return (float(np.max(np.abs(self._fibres[:, 0]))),
                    float(np.max(np.abs(self._fibres[:, 1]))))
        width, height = self.dims
        return (0.5 * height, 0.5 * width)

    @property
    def area(self) -> float:
        return self._area

    @property
    def iy(self) -> float:
        return self._iy

    @property
    def iz(self) -> float:
        return self._iz

    @property
    def torsion_constant(self) -> float:
        return self._torsion

    @property
    def shear_factor_y(self) -> float:
        return self._shear[0]

    @property
    def shear_factor_z(self) -> float:
        return self._shear[1]

    def shear_factors(self, poisson: float) -> tuple[float, float]:
        return self._shear

    def fibre_points(self) -> np.ndarray:
        if self._fibres is not None:
            return self._fibres.copy()
        hy, hz = self.extent
        return np.array([[hy, hz], [-hy, hz], [-hy, -hz], [hy, -hz]])

    def mass_rule(self, density: float) -> tuple[kernel.SectionData, float]:
        if self.mass_per_length is None and self.rotary_inertia is None:
            return self.data, density
        mass = self.mass_per_length if self.mass_per_length is not None else density * self._area
        if self.rotary_inertia is not None:
            _, ry, rz = self.rotary_inertia
        else:
            ry, rz = density * self._iy, density * self._iz
        return _four_point_rule(mass, ry, rz), 1.0   # weights carry the mass: density 1

    def __repr__(self) -> str:
        return (f"General(area={self._area!r}, iy={self._iy!r}, iz={self._iz!r}, "
                f"torsion_constant={self._torsion!r}, shear_factor_y={self._shear[0]!r}, "
                f"shear_factor_z={self._shear[1]!r}, mass_per_length={self.mass_per_length!r}, "
                f"rotary_inertia={self.rotary_inertia!r})")


class Standard(General):
    """A standard steel section by its designation ('IPE200', 'HEB300', 'RHS200x100x8',
    'SHS100x5', 'CHS168.3x8'; :mod:`.section_tables` holds the sizes, their source and
    the formulas): exactly the :class:`General` section of the same numbers, A, I_y, I_z,
    J, the shear factors k = A_v / A of EN 1993-1-1's shear areas and the outer fibres,
    with the section's height along the web (the beam's ``height_axis``). So ``iz`` =
    int y^2 dA is the strong axis's moment (EN's I_y, bending in the plane of the web) and
    ``iy`` the weak one (EN's I_z). The mass comes from the material's density, as for
    every section; :attr:`nominal_mass` is the standards' (7850 kg/m^3)."""

    def __init__(self, designation: str, *, where: str | None = None) -> None:
        try:
            props = section_tables.lookup(designation)
        except LookupError as exc:
            raise InputError(str(exc)) from None
        self.properties = props
        self.designation = props.designation
        super().__init__(props.area, props.i_minor, props.i_major, props.torsion_constant,
                         props.shear_area_web / props.area,
                         props.shear_area_flange / props.area,
                         fibre_points=props.fibre_points,
                         where=where or f"section {props.designation!r}")

    @property
    def nominal_mass(self) -> float:
        """Mass per length at the standards' 7850 kg/m^3 (kg/m)."""
        return self.properties.mass_per_length

    def general_values(self) -> dict:
        """The keys of the equal ``section = 'general'`` input."""
        return dict(area=self.area, iy=self.iy, iz=self.iz,
                    torsion_constant=self.torsion_constant,
                    shear_factor_y=self.shear_factor_y, shear_factor_z=self.shear_factor_z,
                    fibre_points=[float(v) for v in self.fibre_points().ravel()])

    def label(self, height_axis=None) -> str:
        """The designation with its strong axis, for pictures and reports (``ancf show``):
        the web runs along the height (``height_axis``, global when given)."""
        if self.iz == self.iy:
            return self.designation
        where = "the height" if height_axis is None else \
            "(" + ", ".join(f"{v:.3g}" for v in np.asarray(height_axis, float) + 0.0) + ")"
        return f"{self.designation}, web along {where}: strong axis iz"

    def __repr__(self) -> str:
        return f"Standard({self.designation!r})"


SECTIONS = {"rectangle": Rectangle, "box": Box, "tube": Tube, "circle": Circle,
            "general": General}

#: the namelist keys of each section shape (required; then optional ones)
SECTION_KEYS = {"rectangle": ("width", "height"), "box": ("width", "height", "wall"),
                "tube": ("diameter", "wall"), "circle": ("diameter",),
                "general": ("area", "iy", "iz", "torsion_constant", "shear_factor_y",
                            "shear_factor_z")}
SECTION_OPTIONAL = {"general": ("mass_per_length", "rotary_inertia", "fibre_points")}


def section_name_problem(value) -> str | None:
    """Why a namelist ``section`` is refused (the key's check), or None: a shape's name or
    a standard designation (:mod:`.section_tables`) passes."""
    if value in SECTIONS or section_tables.is_standard(value):
        return None
    if section_tables.looks_standard(value):
        hint = section_tables.nearest(value)
        return ("is not a standard section of this catalogue"
                + (f"; nearest: {', '.join(repr(h) for h in hint)}" if hint else "")
                + " (docs/modelling.md lists the sizes)")
    return ("must be one of " + ", ".join(repr(k) for k in SECTIONS) + " or a standard "
            "section such as 'IPE200', 'HEB300', 'RHS200x100x8', 'SHS100x5', 'CHS168.3x8'")


def section_of(values: dict, label: str) -> Section | None:
    """The section of a beam's or cable's values: a Section object as it is (the Python
    API's; None: the body's default), or the namelist form, the shape's name under
    ``section`` with its keys (``section='rectangle', width=..., height=...``), or a
    standard designation alone (``section='IPE200'``)."""
    kind = values.get("section")
    every = {k for ks in SECTION_KEYS.values() for k in ks} | \
        {k for ks in SECTION_OPTIONAL.values() for k in ks} | {"shear"}
    if kind is None or isinstance(kind, Section):
        given = sorted(k for k in every if values.get(k) is not None)
        if given:
            raise InputError(f"{', '.join(given)} describe a section by its keys: give "
                             "section as its shape's name with them, or a Section object "
                             "alone", group=label, key="section")
        return kind
    if isinstance(kind, str) and kind not in SECTIONS and section_tables.looks_standard(kind):
        given = sorted(k for k in every if values.get(k) is not None)
        if given:
            raise InputError(f"section {kind!r} is a standard section: its properties come "
                             f"from the standard, so {', '.join(given)} must not be given",
                             group=label, key="section")
        problem = section_name_problem(kind)
        if problem:
            raise InputError(f"section = {kind!r} {problem}", group=label, key="section")
        return Standard(kind)
    if not isinstance(kind, str) or kind not in SECTIONS:
        raise InputError("expected a section (Rectangle, Box, Tube, Circle, General or a "
                         "standard name such as 'IPE200'), got "
                         f"{short_repr(kind)}", group=label, key="section")
    keys = SECTION_KEYS[kind]
    optional = SECTION_OPTIONAL.get(kind, ())
    missing = [k for k in keys if values.get(k) is None]
    if missing:
        raise InputError(f"section {kind!r} needs {', '.join(missing)}")
    extra = sorted(k for k in every - {"shear"} if k not in keys and k not in optional and
                   values.get(k) is not None)
    if extra:
        raise InputError(f"section {kind!r} does not take {', '.join(extra)}")
    if kind == "general":
        if values.get("shear") is not None:
            raise InputError("section 'general' does not take shear (give shear_factor_y, "
                             "shear_factor_z)")
        return SECTIONS[kind](*(values[k] for k in keys),
                              mass_per_length=values.get("mass_per_length"),
                              rotary_inertia=values.get("rotary_inertia"),
                              fibre_points=values.get("fibre_points"))
    return SECTIONS[kind](*(values[k] for k in keys), shear=values.get("shear") or "unit")
