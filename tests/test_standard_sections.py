"""Standard steel sections (issue 37, item 8; SPEC 8.2): ``section = 'IPE200'`` and the other
sizes of EN 10365 (IPE, HEA, HEB) and EN 10219-2 (RHS, SHS, CHS).

The references are independent of the code: the values published in the producers' section
tables (ArcelorMittal's tables for the rolled sections; a cold-formed EN 10219 table, corner
radius 2 t / 2.5 t / 3 t, for the RHS; the ring's exact values for the CHS), the closed-form
Euler-Bernoulli and Saint-Venant frequencies of a cantilever, sigma = N/A + M c / I, and the
same model given as ``section = 'general'`` with the same numbers.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from ancfdrv import General, Standard, System
from ancfdrv.cli import main
from ancfdrv.errors import InputError
from ancfdrv.solvers.modal import modal_analysis
from ancfdrv.system import section_tables

E, RHO, NU = 2.1e11, 7850.0, 0.3

#: published values (cm^2, cm^4, kg/m), each with its number of significant digits:
#: A, I_y (strong, EN's y-y), I_z (weak), I_t
TABULATED = {
    "IPE200": dict(A=(28.48, 4), Iy=(1943, 4), Iz=(142.4, 4), It=(6.98, 3), Avz=(14.00, 4),
                   G=(22.4, 3)),
    "HEB200": dict(A=(78.08, 4), Iy=(5696, 4), Iz=(2003, 4), It=(59.28, 4), G=(61.3, 3)),
    "HEA300": dict(A=(112.5, 4), Iy=(18260, 4), Iz=(6310, 3), It=(85.17, 4), G=(88.3, 3)),
    "IPE600": dict(A=(156.0, 4), Iy=(92080, 4), Iz=(3387, 4), It=(165.4, 4)),
    # cold-formed EN 10219 (b2bmetal.eu's EN 10219 table, r_o = 2 t for t <= 6 mm)
    "RHS40x20x2": dict(A=(2.14, 3), Iy=(4.05, 3), Iz=(1.34, 3), It=(3.45, 3), G=(1.68, 3)),
    "RHS50x30x3": dict(A=(4.21, 3), Iy=(12.83, 4), Iz=(5.70, 3), It=(13.53, 4), G=(3.30, 3)),
    "RHS60x40x4": dict(A=(6.95, 3), Iy=(30.99, 4), G=(5.45, 3)),
    "CHS168.3x8": dict(A=(40.29, 4), Iy=(1297, 4), Iz=(1297, 4), It=(2595, 4), G=(31.6, 3)),
}

#: tabulated areas (cm^2) of every rolled size offered, in the order of the data tables:
#: a transcription check of the dimensions h, b, t_w, t_f, r
AREAS = {
    "IPE": [7.64, 10.32, 13.21, 16.43, 20.09, 23.95, 28.48, 33.37, 39.12, 45.95, 53.81, 62.61,
            72.73, 84.46, 98.82, 115.5, 134.4, 156.0],
    "HEA": [21.24, 25.34, 31.42, 38.77, 45.25, 53.83, 64.34, 76.84, 86.82, 97.26, 112.5,
            124.4, 133.5, 142.8, 159.0, 178.0, 197.5, 211.8, 226.5],
    "HEB": [26.04, 34.01, 42.96, 54.25, 65.25, 78.08, 91.04, 106.0, 118.4, 131.4, 149.1,
            161.3, 170.9, 180.6, 197.8, 218.0, 238.6, 254.1, 270.0],
}
#: tabulated strong-axis second moments (cm^4) of the IPE sizes, same order
IPE_IY = [80.14, 171.0, 317.8, 541.2, 869.3, 1317, 1943, 2772, 3892, 5790, 8356, 11770, 16270,
          23130, 33740, 48200, 67120, 92080]


def rounds_to(value: float, tabulated: float, digits: int) -> bool:
    """Whether ``value`` rounded to ``digits`` significant digits is the tabulated figure
    (within half a unit of its last digit)."""
    unit = 10.0 ** (math.floor(math.log10(abs(tabulated))) - digits + 1)
    return abs(value - tabulated) <= 0.5 * unit * (1.0 + 1e-9)


@pytest.mark.parametrize("name", list(TABULATED))
def test_properties_match_the_published_tables(name):
    """A, I_y, I_z, I_t (and A_vz, mass) computed from the dimensions round to the tables'
    figures; the library's section carries EN's strong I_y as iz (the web along the
    height) and the weak I_z as iy."""
    props = section_tables.lookup(name)
    section = Standard(name)
    computed = dict(A=props.area * 1e4, Iy=props.i_major * 1e8, Iz=props.i_minor * 1e8,
                    It=props.torsion_constant * 1e8, Avz=props.shear_area_web * 1e4,
                    G=props.mass_per_length)
    for key, (tabulated, digits) in TABULATED[name].items():
        assert rounds_to(computed[key], tabulated, digits), (name, key, computed[key])
    assert section.iz == props.i_major and section.iy == props.i_minor
    assert section.area == props.area and section.torsion_constant == props.torsion_constant
    assert section.nominal_mass == pytest.approx(RHO * props.area, rel=1e-15)


@pytest.mark.parametrize("family", list(AREAS))
def test_every_rolled_size_matches_its_tabulated_area(family):
    names = [f"{family}{size}" for size in section_tables.ROLLED[family]]
    assert len(names) == len(AREAS[family])
    for name, area in zip(names, AREAS[family]):
        digits = 3 if area < 10 else 4   # as printed: 7.64, 10.32, 115.5
        assert rounds_to(section_tables.lookup(name).area * 1e4, area, digits), name
    if family == "IPE":
        for name, inertia in zip(names, IPE_IY):
            assert rounds_to(section_tables.lookup(name).i_major * 1e8, inertia, 4), name


def test_names_fibres_and_shear_areas():
    """Spelling is free of case and spaces; the fibres are the flange tips (I) or lie on
    the outer corner arcs (RHS) or the circle (CHS); the shear factors are EN 1993-1-1's
    shear areas over A."""
    assert Standard("ipe 200").designation == "IPE200"
    assert Standard("CHS168.3x8.0").designation == "CHS168.3x8"
    ipe = Standard("IPE200")
    tips = sorted(map(tuple, ipe.fibre_points()))
    assert np.allclose(tips, [(-0.1, -0.05), (-0.1, 0.05), (0.1, -0.05), (0.1, 0.05)])
    assert ipe.extent == pytest.approx((0.1, 0.05))
    assert ipe.shear_factor_y == pytest.approx(14.00e-4 / 28.48e-4, rel=1e-3)
    rhs = section_tables.lookup("RHS200x100x8")
    points = np.array(rhs.fibre_points)
    r_o = 0.02   # 2.5 t for 6 < t <= 10 mm
    centre = np.array([0.1 - r_o, 0.05 - r_o])
    assert np.allclose(np.hypot(*(np.abs(points) - centre).T), r_o)
    assert np.max(np.abs(points), axis=0) == pytest.approx([0.1, 0.05])
    assert rhs.shear_area_web == pytest.approx(rhs.area * 200 / 300)
    chs = Standard("CHS168.3x8")
    assert np.allclose(np.hypot(*chs.fibre_points().T), 0.08415)
    assert chs.shear_factor_y == pytest.approx(2 / math.pi)


@pytest.mark.parametrize("name, nearest", [("IPE201", "'IPE200'"), ("HEB 1000", "'HEB600'"),
                                           ("RHS200x100x7", "'RHS200x100x8'"),
                                           ("CHS170x8", "'CHS168.3x8'")])
def test_unknown_name_is_refused_with_the_nearest(name, nearest, tmp_path, capsys):
    scene = tmp_path / "bad.nml"
    scene.write_text(CANTILEVER.format(section=f"'{name}'", extra=""))
    out = tmp_path / "bad.h5"
    assert main(["run", str(scene), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "beam" in err and "section" in err and "not a standard section" in err
    assert nearest in err
    assert not out.exists()
    with pytest.raises(InputError, match="nearest"):
        Standard(name)


def test_standard_section_takes_no_other_section_keys(tmp_path, capsys):
    scene = tmp_path / "extra.nml"
    scene.write_text(CANTILEVER.format(section="'IPE200'", extra=", width = 0.1"))
    assert main(["run", str(scene), "-o", str(tmp_path / "x.h5")]) == 2
    assert "width must not be given" in capsys.readouterr().err


CANTILEVER = """
&scene title = 'IPE cantilever', analysis = 'modal' /
&material name = 'steel', youngs_modulus = 2.1e11, density = 7850.0, poisson_ratio = 0.3 /
&beam name = 'arm', material = 'steel', start = 0, 0, 0, end = 4, 0, 0, nodes = 9,
      section = {section}{extra}, height_axis = 0, 1, 0, bending = 'cubic' /
&joint name = 'root', type = 'weld', body1 = 'ground', body2 = 'arm', point = 0, 0, 0 /
&modal modes = 4 /
"""


def _cantilever(section, nodes: int = 9) -> System:
    s = System("IPE cantilever")
    s.material("steel", youngs_modulus=E, density=RHO, poisson_ratio=NU)
    s.beam("arm", material="steel", start=(0, 0, 0), end=(4.0, 0, 0), nodes=nodes,
           section=section, height_axis=(0, 1, 0), formulation="ffr", bending="cubic")
    s.joint("root", "weld", "ground", "arm", point=(0, 0, 0))
    return s


def test_cantilever_frequencies_closed_form():
    """An IPE200 cantilever (L = 4 m, web along y): the lowest mode bends about the web's
    axis (weak, iy) and moves along z; the first bending along y (strong, iz) and the
    first torsion mode are the closed forms with the library's I and J:
    f = 1.8751^2/(2 pi L^2) sqrt(E I / rho A), f_t = 1/(4 L) sqrt(G J / rho I_p)."""
    section = Standard("IPE200")
    model = _cantilever(section).assemble()
    modes = modal_analysis(model, 4)
    beta = 1.875104069
    weak, strong = (beta**2 / (2 * math.pi * 16.0) * math.sqrt(E * i / (RHO * section.area))
                    for i in (section.iy, section.iz))
    shear_modulus = E / (2 * (1 + NU))
    torsion = math.sqrt(shear_modulus * section.torsion_constant / (RHO * section.polar)) / 16.0
    f = modes.frequency
    assert f[0] == pytest.approx(weak, rel=2e-3)
    assert f[1] == pytest.approx(torsion, rel=5e-3)
    # strong axis: 0.6 % below Euler-Bernoulli, the shear flexibility of the web (k = 0.49)
    assert f[2] == pytest.approx(strong, rel=1e-2)
    tip = [model.bodies[0].node_first(model.bodies[0].nodes - 1)]
    for mode, axis in ((0, 2), (2, 1)):
        r = modes.full_shapes[mode][tip[0]:tip[0] + 3]
        assert abs(r[axis]) > 0.99 * np.linalg.norm(r)


def _portal(section) -> System:
    """A fixed-base portal frame in the x-z plane: columns 4 m, beam 6 m, welded corners,
    every member's web in the frame's plane."""
    s = System("IPE portal")
    s.material("steel", youngs_modulus=E, density=RHO, poisson_ratio=NU)
    s.beam("left", material="steel", start=(0, 0, 0), end=(0, 0, 4), nodes=5,
           section=section, height_axis=(1, 0, 0), formulation="ffr", bending="cubic")
    s.beam("right", material="steel", start=(6, 0, 0), end=(6, 0, 4), nodes=5,
           section=section, height_axis=(1, 0, 0), formulation="ffr", bending="cubic")
    s.beam("top", material="steel", start=(0, 0, 4), end=(6, 0, 4), nodes=7,
           section=section, height_axis=(0, 0, 1), formulation="ffr", bending="cubic")
    for name, body, point in (("base l", "left", (0, 0, 0)), ("base r", "right", (6, 0, 0))):
        s.joint(name, "weld", "ground", body, point=point)
    s.joint("corner l", "weld", "left", "top", point=(0, 0, 4))
    s.joint("corner r", "weld", "right", "top", point=(6, 0, 4))
    return s


def test_portal_frame_sway_equals_the_general_section():
    """The IPE200 portal's lowest frequencies (the first a sway out of the frame's plane,
    the columns bending about their weak axes) from section = 'IPE200' equal those from
    section = 'general' with the same numbers, to round-off."""
    library = Standard("IPE200")
    general = General(**library.general_values())
    model = _portal(library).assemble()
    modes = modal_analysis(model, 3)
    a = modes.frequency
    b = modal_analysis(_portal(general).assemble(), 3).frequency
    assert np.all(a > 0.5)
    assert a == pytest.approx(b, rel=1e-10)
    top = next(body for body in model.bodies if body.name == "top")
    corner = modes.full_shapes[0][top.first:top.first + 3]
    assert abs(corner[1]) > 0.99 * np.linalg.norm(corner)   # sway along y


def test_namelist_modal_equals_the_general_input(tmp_path):
    """``section = 'IPE200'`` in a scene gives the frequencies of the 'general' scene with
    the library's numbers."""
    import h5py
    values = Standard("IPE200").general_values()
    general = ("'general', " + ", ".join(
        f"{k} = {v!r}" for k, v in values.items() if k != "fibre_points")
        + ", fibre_points = " + ", ".join(repr(v) for v in values["fibre_points"]))
    runs = {}
    for label, section in (("library", "'IPE200'"), ("general", general)):
        scene = tmp_path / f"{label}.nml"
        scene.write_text(CANTILEVER.format(section=section, extra=""))
        out = tmp_path / f"{label}.h5"
        assert main(["run", str(scene), "-o", str(out)]) == 0
        with h5py.File(out) as f:
            runs[label] = f["/modal/frequency"][()]
    assert runs["library"] == pytest.approx(runs["general"], rel=1e-10)


def test_flange_tip_stress_is_n_over_a_plus_m_c_over_i():
    """A 4 m IPE200 cantilever under a tip force (N = 10 kN, F_y = -1 kN, F_z = 100 N): at
    the root sigma_x = N/A + M_strong (h/2)/I_z + M_weak (b/2)/I_y at a flange tip."""
    section = Standard("IPE200")
    s = _cantilever(section, nodes=5)
    s.load("tip", "force", body="arm", point=(4, 0, 0), vector=(1e4, -1000.0, 100.0))
    results = s.static()
    sigma = results.stress["arm"]["sigma_x"][0]
    expected = 1e4 / section.area + 4000.0 * 0.1 / section.iz + 400.0 * 0.05 / section.iy
    assert sigma == pytest.approx(expected, rel=1e-9)


def test_show_labels_the_section_and_its_strong_axis():
    """``ancf show`` names a beam's standard section and where its web (strong axis) lies."""
    from ancfdrv import preview
    system = _portal(Standard("IPE200"))
    model = system.assemble()
    try:
        bodies = preview.geometry(system, model)["bodies"]
        words = {name: body["word"] for name, body in bodies.items()}
    finally:
        model.close()
    assert words["left"] == "beam, IPE200, web along (1, 0, 0): strong axis iz"
    assert words["top"] == "beam, IPE200, web along (0, 0, 1): strong axis iz"
