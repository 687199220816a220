"""Standard steel sections as data with their source (issue 37, item 8; SPEC 8.2).

Dimensions (mm) of the rolled I and H sections of EN 10365:2017 ("Hot rolled steel
channels, I and H sections - Dimensions and masses"; the sizes of the former Euronorm
19-57 and 53-62 / DIN 1025-2, -3, -5): IPE 80-600, HE A and HE B 100-600, as h, b, t_w,
t_f, r (depth, flange width, web and flange thickness, root radius). Cold-formed hollow
sections of EN 10219-2:2006 ("Cold formed welded structural hollow sections of non-alloy
and fine grain steels - Part 2: Tolerances, dimensions and sectional properties"): the
designation gives the dimensions (RHS H x B x t, SHS B x t, CHS D x t); the lists below
are the sizes offered here.

The properties are computed from the geometry, by the formulas of the tables the
producers publish for these standards (tests/test_standard_sections.py checks them
against tabulated values to 4 digits):

* rolled I and H: area and second moments of the two flanges, the web and the four root
  fillets (each fillet the square r x r less a quarter circle: area (1 - pi/4) r^2,
  centroid (10 - 3 pi)/(12 - 3 pi) r from the corner, own moment (1 - 5 pi/16) r^4 about
  the corner's edge); the torsion constant of the producers' tables (ArcelorMittal
  "Sales programme", technical notes), flanges and web as thin rectangles plus the two
  web-flange junctions:
  I_t = 2/3 (b - 0.63 t_f) t_f^3 + 1/3 (h - 2 t_f) t_w^3 + 2 (t_w/t_f)(0.145 + 0.1 r/t_f) D^4,
  D = ((t_f + r)^2 + t_w (r + t_w/4)) / (2 r + t_f);
* RHS and SHS: EN 10219-2 Annex B with the corner radii it prescribes for the
  calculation, outer r_o = 2 t (t <= 6 mm), 2.5 t (6 < t <= 10 mm), 3 t (t > 10 mm),
  inner r_i = r_o - t: A = 2 t (B + H - 2 t) - (4 - pi)(r_o^2 - r_i^2), the second moments
  of the outer rectangle less the inner one with the corners' spandrels taken off, and
  I_t = t^3 h/3 + 2 K A_h (h = 2 (B - t + H - t) - 2 R_c (4 - pi), A_h = (B - t)(H - t)
  - R_c^2 (4 - pi), K = 2 A_h t / h, R_c = (r_o + r_i)/2);
* CHS: exact, A = pi (D - t) t, I = pi (D^4 - (D - 2 t)^4)/64, I_t = 2 I.

Shear areas by EN 1993-1-1, 6.2.6(3): rolled I and H along the web
A - 2 b t_f + (t_w + 2 r) t_f (at least h_w t_w), along the flanges A - h_w t_w
(h_w = h - 2 t_f); RHS and SHS A H/(B + H) along the depth, A B/(B + H) along the width;
CHS 2 A / pi. Mass per length at EN 10365's and EN 10219's 7850 kg/m^3.

Axes: ``major`` is the bending about the axis across the web (EN's y-y; the web runs
along the section's height), ``minor`` about the web's axis (EN's z-z). A beam places the
height along its ``height_axis`` (docs/modelling.md): I_major is its ``iz``, I_minor its
``iy``.
"""
from __future__ import annotations

import difflib
import math
import re
from ..records import record

#: density of the standards' tabulated masses (kg/m^3)
STEEL_DENSITY = 7850.0

#: EN 10365:2017 IPE: h, b, t_w, t_f, r (mm)
IPE = {
    80: (80, 46, 3.8, 5.2, 5), 100: (100, 55, 4.1, 5.7, 7), 120: (120, 64, 4.4, 6.3, 7),
    140: (140, 73, 4.7, 6.9, 7), 160: (160, 82, 5.0, 7.4, 9), 180: (180, 91, 5.3, 8.0, 9),
    200: (200, 100, 5.6, 8.5, 12), 220: (220, 110, 5.9, 9.2, 12),
    240: (240, 120, 6.2, 9.8, 15), 270: (270, 135, 6.6, 10.2, 15),
    300: (300, 150, 7.1, 10.7, 15), 330: (330, 160, 7.5, 11.5, 18),
    360: (360, 170, 8.0, 12.7, 18), 400: (400, 180, 8.6, 13.5, 21),
    450: (450, 190, 9.4, 14.6, 21), 500: (500, 200, 10.2, 16.0, 21),
    550: (550, 210, 11.1, 17.2, 24), 600: (600, 220, 12.0, 19.0, 24),
}
#: EN 10365:2017 HE A (HEA): h, b, t_w, t_f, r (mm)
HEA = {
    100: (96, 100, 5.0, 8.0, 12), 120: (114, 120, 5.0, 8.0, 12),
    140: (133, 140, 5.5, 8.5, 12), 160: (152, 160, 6.0, 9.0, 15),
    180: (171, 180, 6.0, 9.5, 15), 200: (190, 200, 6.5, 10.0, 18),
    220: (210, 220, 7.0, 11.0, 18), 240: (230, 240, 7.5, 12.0, 21),
    260: (250, 260, 7.5, 12.5, 24), 280: (270, 280, 8.0, 13.0, 24),
    300: (290, 300, 8.5, 14.0, 27), 320: (310, 300, 9.0, 15.5, 27),
    340: (330, 300, 9.5, 16.5, 27), 360: (350, 300, 10.0, 17.5, 27),
    400: (390, 300, 11.0, 19.0, 27), 450: (440, 300, 11.5, 21.0, 27),
    500: (490, 300, 12.0, 23.0, 27), 550: (540, 300, 12.5, 24.0, 27),
    600: (590, 300, 13.0, 25.0, 27),
}
#: EN 10365:2017 HE B (HEB): h, b, t_w, t_f, r (mm)
HEB = {
    100: (100, 100, 6.0, 10.0, 12), 120: (120, 120, 6.5, 11.0, 12),
    140: (140, 140, 7.0, 12.0, 12), 160: (160, 160, 8.0, 13.0, 15),
    180: (180, 180, 8.5, 14.0, 15), 200: (200, 200, 9.0, 15.0, 18),
    220: (220, 220, 9.5, 16.0, 18), 240: (240, 240, 10.0, 17.0, 21),
    260: (260, 260, 10.0, 17.5, 24), 280: (280, 280, 10.5, 18.0, 24),
    300: (300, 300, 11.0, 19.0, 27), 320: (320, 300, 11.5, 20.5, 27),
    340: (340, 300, 12.0, 21.5, 27), 360: (360, 300, 12.5, 22.5, 27),
    400: (400, 300, 13.5, 24.0, 27), 450: (450, 300, 14.0, 26.0, 27),
    500: (500, 300, 14.5, 28.0, 27), 550: (550, 300, 15.0, 29.0, 27),
    600: (600, 300, 15.5, 30.0, 27),
}
ROLLED = {"IPE": IPE, "HEA": HEA, "HEB": HEB}

#: EN 10219-2 sizes offered: RHS H x B x t (mm), H the depth (along the height)
RHS = (
    (40, 20, 2), (50, 30, 3), (60, 40, 3), (60, 40, 4), (80, 40, 3), (80, 40, 4),
    (80, 60, 4), (100, 50, 4), (100, 50, 5), (100, 60, 4), (100, 60, 5), (120, 60, 4),
    (120, 60, 5), (120, 80, 5), (120, 80, 6), (140, 80, 5), (140, 80, 6), (150, 100, 5),
    (150, 100, 6), (150, 100, 8), (160, 80, 5), (160, 80, 6), (160, 80, 8),
    (180, 100, 6), (180, 100, 8), (200, 100, 5), (200, 100, 6), (200, 100, 8),
    (200, 100, 10), (200, 120, 8), (250, 150, 6), (250, 150, 8), (250, 150, 10),
    (300, 200, 8), (300, 200, 10), (300, 200, 12), (400, 200, 10), (400, 200, 12),
)
#: EN 10219-2 sizes offered: SHS B x t (mm)
SHS = (
    (40, 3), (40, 4), (50, 3), (50, 4), (50, 5), (60, 3), (60, 4), (60, 5), (70, 4),
    (70, 5), (80, 4), (80, 5), (80, 6), (90, 4), (90, 5), (90, 6), (100, 4), (100, 5),
    (100, 6), (100, 8), (120, 5), (120, 6), (120, 8), (120, 10), (140, 5), (140, 6),
    (140, 8), (140, 10), (150, 6), (150, 8), (150, 10), (160, 6), (160, 8), (160, 10),
    (180, 8), (180, 10), (200, 6), (200, 8), (200, 10), (200, 12), (250, 8), (250, 10),
    (250, 12), (300, 8), (300, 10), (300, 12),
)
#: EN 10219-2 sizes offered: CHS D x t (mm)
CHS = (
    (33.7, 3.2), (42.4, 3.2), (48.3, 3.2), (48.3, 4), (60.3, 3.2), (60.3, 4), (76.1, 3.2),
    (76.1, 4), (88.9, 3.2), (88.9, 4), (88.9, 5), (114.3, 4), (114.3, 5), (114.3, 6),
    (139.7, 5), (139.7, 6), (139.7, 8), (168.3, 5), (168.3, 6), (168.3, 8), (168.3, 10),
    (193.7, 6), (193.7, 8), (193.7, 10), (219.1, 6), (219.1, 8), (219.1, 10),
    (244.5, 8), (244.5, 10), (273, 8), (273, 10), (323.9, 8), (323.9, 10), (355.6, 10),
    (406.4, 10), (457, 10), (508, 12.5),
)

SOURCES = {"IPE": "EN 10365:2017", "HEA": "EN 10365:2017", "HEB": "EN 10365:2017",
           "RHS": "EN 10219-2:2006", "SHS": "EN 10219-2:2006", "CHS": "EN 10219-2:2006"}


@record(frozen=True)
class StandardProperties:
    """A standard section's properties (SI: m, m^2, m^4, kg/m). ``major`` bends about the
    axis across the web (EN's y-y), ``minor`` about the web's own axis (EN's z-z);
    ``shear_area_web`` carries shear along the web (the height), ``shear_area_flange``
    across it (the width); ``fibre_points`` are (along the height, along the width)
    points of the outer fibres."""

    designation: str
    family: str
    source: str
    height: float
    width: float
    area: float
    i_major: float
    i_minor: float
    torsion_constant: float
    shear_area_web: float
    shear_area_flange: float
    fibre_points: tuple[tuple[float, float], ...]

    @property
    def mass_per_length(self) -> float:
        """Nominal mass per length (kg/m) at the standards' 7850 kg/m^3."""
        return STEEL_DENSITY * self.area


def _fillet(r: float) -> tuple[float, float, float]:
    """Area, centroid distance from the corner and own second moment (about its centroid,
    parallel to an edge) of a spandrel: the square r x r less its quarter circle."""
    area = (1.0 - math.pi / 4.0) * r * r
    centroid = (10.0 - 3.0 * math.pi) / (12.0 - 3.0 * math.pi) * r
    own = (1.0 - 5.0 * math.pi / 16.0) * r**4 - area * centroid**2
    return area, centroid, own


def _number(x: float) -> str:
    return f"{x:g}"


def rolled(family: str, size: int) -> StandardProperties:
    """The properties of a rolled I or H section of EN 10365 (module docstring)."""
    h, b, tw, tf, r = (float(v) for v in ROLLED[family][size])
    hw = h - 2.0 * tf
    fa, fc, fi = _fillet(r)
    area = 2.0 * b * tf + hw * tw + 4.0 * fa
    i_major = (b * h**3 - (b - tw) * hw**3) / 12.0 + 4.0 * (fi + fa * (hw / 2.0 - fc) ** 2)
    i_minor = (2.0 * tf * b**3 + hw * tw**3) / 12.0 + 4.0 * (fi + fa * (tw / 2.0 + fc) ** 2)
    d = ((tf + r) ** 2 + tw * (r + tw / 4.0)) / (2.0 * r + tf)
    torsion = (2.0 / 3.0 * (b - 0.63 * tf) * tf**3 + hw * tw**3 / 3.0
               + 2.0 * (tw / tf) * (0.145 + 0.1 * r / tf) * d**4)
    web = max(area - 2.0 * b * tf + (tw + 2.0 * r) * tf, hw * tw)
    tips = tuple((sy * h / 2e3, sz * b / 2e3) for sy in (1.0, -1.0) for sz in (1.0, -1.0))
    return StandardProperties(f"{family}{size}", family, SOURCES[family], h / 1e3, b / 1e3,
                              area * 1e-6, i_major * 1e-12, i_minor * 1e-12, torsion * 1e-12,
                              web * 1e-6, (area - hw * tw) * 1e-6, tips)


def corner_radius(t: float) -> float:
    """EN 10219-2's outer corner radius for the calculation of the properties (mm)."""
    return 2.0 * t if t <= 6.0 else (2.5 * t if t <= 10.0 else 3.0 * t)


def hollow_rectangle(depth: float, width: float, t: float) -> StandardProperties:
    """The properties of a cold-formed RHS (depth along the height) or SHS of EN 10219-2
    (module docstring)."""
    h_, b_, t = float(depth), float(width), float(t)
    r_o = corner_radius(t)
    r_i = r_o - t
    area = 2.0 * t * (b_ + h_ - 2.0 * t) - (4.0 - math.pi) * (r_o**2 - r_i**2)

    def second_moment(h: float, b: float) -> float:
        oa, oc, oi = _fillet(r_o)
        ia, ic, ii = _fillet(r_i)
        return ((b * h**3 - (b - 2.0 * t) * (h - 2.0 * t) ** 3) / 12.0
                - 4.0 * (oi + oa * (h / 2.0 - oc) ** 2)
                + 4.0 * (ii + ia * (h / 2.0 - t - ic) ** 2))

    r_c = 0.5 * (r_o + r_i)
    perimeter = 2.0 * ((b_ - t) + (h_ - t)) - 2.0 * r_c * (4.0 - math.pi)
    enclosed = (b_ - t) * (h_ - t) - r_c**2 * (4.0 - math.pi)
    k = 2.0 * enclosed * t / perimeter
    torsion = t**3 * perimeter / 3.0 + 2.0 * k * enclosed
    family = "SHS" if h_ == b_ else "RHS"
    name = f"SHS{_number(b_)}x{_number(t)}" if family == "SHS" else \
        f"RHS{_number(h_)}x{_number(b_)}x{_number(t)}"
    # outer fibres: five points on each outer corner arc (its ends lie on the flat faces)
    points = []
    for sy in (1.0, -1.0):
        for sz in (1.0, -1.0):
            cy, cz = h_ / 2.0 - r_o, b_ / 2.0 - r_o
            for angle in (0.0, 22.5, 45.0, 67.5, 90.0):
                a = math.radians(angle)
                points.append((sy * (cy + r_o * math.cos(a)) / 1e3,
                               sz * (cz + r_o * math.sin(a)) / 1e3))
    return StandardProperties(name, family, SOURCES[family], h_ / 1e3, b_ / 1e3,
                              area * 1e-6, second_moment(h_, b_) * 1e-12,
                              second_moment(b_, h_) * 1e-12, torsion * 1e-12,
                              area * h_ / (b_ + h_) * 1e-6, area * b_ / (b_ + h_) * 1e-6,
                              tuple(points))


def hollow_circle(diameter: float, t: float) -> StandardProperties:
    """The properties of a CHS of EN 10219-2 (exact for the circular ring)."""
    d, t = float(diameter), float(t)
    area = math.pi * (d - t) * t
    inertia = math.pi * (d**4 - (d - 2.0 * t) ** 4) / 64.0
    angles = [2.0 * math.pi * k / 16 for k in range(16)]
    points = tuple((d / 2e3 * math.cos(a), d / 2e3 * math.sin(a)) for a in angles)
    shear = 2.0 * area / math.pi
    return StandardProperties(f"CHS{_number(d)}x{_number(t)}", "CHS", SOURCES["CHS"],
                              d / 1e3, d / 1e3, area * 1e-6, inertia * 1e-12,
                              inertia * 1e-12, 2.0 * inertia * 1e-12, shear * 1e-6,
                              shear * 1e-6, points)


def _catalogue() -> dict[str, tuple]:
    """Every designation offered: name -> (builder, arguments)."""
    out: dict[str, tuple] = {}
    for family, table in ROLLED.items():
        for size in table:
            out[f"{family}{size}"] = (rolled, (family, size))
    for h, b, t in RHS:
        out[f"RHS{_number(h)}x{_number(b)}x{_number(t)}"] = (hollow_rectangle, (h, b, t))
    for b, t in SHS:
        out[f"SHS{_number(b)}x{_number(t)}"] = (hollow_rectangle, (b, b, t))
    for d, t in CHS:
        out[f"CHS{_number(d)}x{_number(t)}"] = (hollow_circle, (d, t))
    return out


CATALOGUE = _catalogue()
_FAMILY = re.compile(r"^(IPE|HEA|HEB|RHS|SHS|CHS)(.*)$")


def canonical(name: str) -> str:
    """The catalogue spelling of a designation: case and spaces ignored ('ipe 200' ->
    'IPE200'), the numbers of a hollow section as numbers ('CHS168.3x8.0' ->
    'CHS168.3x8')."""
    text = re.sub(r"\s+", "", str(name)).upper()
    match = _FAMILY.match(text)
    if not match:
        return text
    family, rest = match.groups()
    parts = rest.split("X")
    try:
        numbers = [_number(float(p)) for p in parts]
    except ValueError:
        return family + rest.lower()
    return family + "x".join(numbers)


def is_standard(name: str) -> bool:
    """Whether ``name`` names a section of the catalogue."""
    return canonical(name) in CATALOGUE


def looks_standard(name: str) -> bool:
    """Whether ``name`` starts like a standard designation (IPE, HEA, ... in any case)."""
    return _FAMILY.match(re.sub(r"\s+", "", str(name)).upper()) is not None


def _numbers(text: str) -> list[float]:
    return [float(x) for x in re.findall(r"\d+(?:\.\d+)?", text)]


def nearest(name: str, count: int = 3) -> list[str]:
    """The designations closest to ``name`` (for a refusal's hint): of its family, the
    nearest in its dimensions (relative differences, the first one first); else the
    closest spellings."""
    key = canonical(name)
    match = _FAMILY.match(key)
    wanted = _numbers(key)
    if match and wanted:
        same = [n for n in CATALOGUE if n.startswith(match.group(1))]

        def distance(candidate: str) -> tuple[float, ...]:
            have = _numbers(candidate[3:])
            return tuple(abs(h - w) / max(h, w, 1e-9) for h, w in zip(have, wanted))
        return sorted(same, key=distance)[:count]
    return difflib.get_close_matches(key, list(CATALOGUE), n=count, cutoff=0.5)


def lookup(name: str) -> StandardProperties:
    """The properties of a designation; LookupError (its text naming the nearest
    designations) for a name not in the catalogue."""
    key = canonical(name)
    if key not in CATALOGUE:
        hint = nearest(name)
        raise LookupError(f"{name!r} is not a standard section of this catalogue"
                       + (f"; nearest: {', '.join(hint)}" if hint else "")
                       + " (IPE, HEA, HEB of EN 10365; RHS, SHS, CHS of EN 10219-2: "
                       "docs/modelling.md lists the sizes)")
    builder, args = CATALOGUE[key]
    return builder(*args)
