"""The schema of scenes: every group and key a namelist may use, with its type, default,
physical range and a one-line meaning.

Template scenes (SPEC section 3) use :data:`SCHEMA`: one model group (``&boom``,
``&cantilever``, ``&spinup``, ``&plate``, ``&leaf``, ``&spring``) and the common groups. General
scenes (SPEC section 8) use the repeatable, named groups of :data:`GENERAL_SCHEMA` (each
one call of the System API, :mod:`ancfdrv.builders.general`) with ``&scene``, ``&solver`` and
``&output``.
"""
from __future__ import annotations

import math
from typing import Any, Callable

from ..records import record
from ..errors import InputError
from .validate import INT32_MAX, MAX_MAGNITUDE, check_int32, check_magnitude, check_name

REQUIRED = object()
#: the longest title accepted: it heads every plot (a 100 kB title took half a minute to
#: draw) and the HDF5 attributes
MAX_TITLE_CHARACTERS = 1000


def title_problem(title: str) -> str | None:
    """Why a title is refused (too long, several lines), or None."""
    if len(title) > MAX_TITLE_CHARACTERS:
        return (f"is {len(title)} characters long; at most {MAX_TITLE_CHARACTERS} are "
                "accepted")
    return None
#: the material damping key (both schemas)
DAMPING_TIME_DOC = ("Kelvin-Voigt retardation time tau (s): stress D (strain + tau strain rate), "
                    "modal damping ratio tau omega / 2; needs the effect 'damping'")

#: Effects a scene may list in ``&scene effects``; what is not listed is never computed.
#: the FFR P-delta option of &beam (template and general scenes)
GEOMETRIC_STIFFNESS_DOC = (
    "'ffr' beams: add the geometric stiffness of the current axial force (P-delta: each "
    "element's axial force N = EA eps from its frame displacement, force N int u' . du' dx; "
    "docs/theory.md, 'FFR geometric stiffness'); needs solver.static_method = 'newton' for a "
    "static start; off (default): the paper's linear model; 'nonlinear' beams have it anyway "
    "and ignore the key")
#: the FFR modal reduction of &beam (template and general scenes)
MODES_DOC = (
    "'ffr' beams, dynamic runs from the static start: 0 (default) integrates every "
    "coordinate; N > 0 integrates the modally reduced model (the N lowest constrained modes "
    "about the static state plus static corrections, constant matrices; docs/theory.md, "
    "'Modal reduction of FFR bodies') and writes the full coordinates back (lambda, the "
    "drive's work and reactions are not provided). Needs the beam the model's only "
    "flexible body, in a frame turned by a drive, Newmark with fixed steps")
EFFECTS_AVAILABLE = ("gravity", "tip_mass", "bending_moment", "tip_force", "end_moment",
                     "point_loads", "pressure", "prestress", "contact", "friction", "load_cycle",
                     "damping")
#: Effects of later capabilities, recognised so the message can say so.
EFFECTS_PLANNED: tuple[str, ...] = ()


@record(frozen=True)
class Key:
    """One namelist key: its type, default (or REQUIRED), check and meaning."""

    kind: str  # 'float', 'int', 'str', 'bool', 'floats', 'strs'
    default: Any = REQUIRED
    check: Callable[[Any], str | None] | None = None
    doc: str = ""
    size: int | None = None  # exact length for list kinds


def positive(v: Any) -> str | None:
    return None if v > 0 else "must be positive"


def non_negative(v: Any) -> str | None:
    return None if v >= 0 else "must not be negative"


def one_of(*choices: str) -> Callable[[Any], str | None]:
    def check(v: Any) -> str | None:
        return None if v in choices else f"must be one of {', '.join(repr(c) for c in choices)}"
    check.choices = choices  # type: ignore[attr-defined]  (listed by docs/scenes.md)
    return check


def within(lo: float, hi: float, *, open_hi: bool = False) -> Callable[[Any], str | None]:
    def check(v: Any) -> str | None:
        ok = lo <= v < hi if open_hi else lo <= v <= hi
        return None if ok else f"must lie in [{lo}, {hi}{')' if open_hi else ']'}"
    return check


def at_least(n: int) -> Callable[[Any], str | None]:
    def check(v: Any) -> str | None:
        return None if v >= n else f"must be at least {n}"
    return check


SCHEMA: dict[str, dict[str, Key]] = {
    "scene": {
        "title": Key("str", check=lambda v: title_problem(v), doc="a line describing the "
                     "scene (at most 1000 characters)"),
        "analysis": Key("str", "static", one_of("static", "dynamic", "static+dynamic", "modal",
                                                "buckling"),
                        "which analysis runs ('modal' and 'buckling': about the static state, "
                        "settings in &modal and &buckling)"),
        "formulation": Key("str", "ffr", one_of("ffr", "nonlinear"), "elastic model"),
        "effects": Key("strs", [], doc="force effects to compute; nothing else is computed "
                       "(general scenes: default every effect their items belong to)"),
        "response": Key("str", None, doc="general scenes: the probe sweeps compare (default: "
                        "a sweep compares the probe and component that move most in its "
                        "--reference or first case and says so; a run's file names the first "
                        "probe)"),
        "bounds": Key("str", "check", one_of("check", "off"),
                      "'check': drives, loads, force elements and modal.spin_rate must stay "
                      "within physical bounds (ancfdrv.io.validate.PHYSICAL_BOUNDS, e.g. a "
                      "rate of at most 1e4 rad/s, a stiffness of at most 1e12 N/m), a nonzero "
                      "stiffness and every body's length and section above physical minima "
                      "(PHYSICAL_MINIMA: 1e-3 N/m, 1 mm, 10 micrometres: beyond them the input "
                      "is a typo or a unit slip), and a static or dynamic result strained "
                      "beyond 0.5 % (more than an elastic metal takes) or displaced by more "
                      "than the structure's size warns, naming the body "
                      "(ancfdrv.results.plausibility); 'off' accepts any finite value and "
                      "silences the warning (also: ancf run --force). A result not finite or "
                      "displaced by more than 1000 times the structure's size fails (exit 3) "
                      "either way"),
        "planar": Key("str", "off", one_of("off", "auto", "xy", "yz", "zx"),
                      "planar reduction (docs/theory.md, system/planar.py): 'xy', 'yz', 'zx' "
                      "declare that the motion stays in planes parallel to that one (data "
                      "leaving it are refused) and solve only the in-plane coordinates (a "
                      "beam node 7 of 12, a cable node 4 of 6); 'auto' reduces when every "
                      "body, joint and load keeps the motion in a coordinate plane; 'off' "
                      "solves every coordinate"),
        "response_component": Key("int", 2, within(0, 2), "general scenes: the component of the "
                                  "response probe's deflection compared (0, 1, 2 = x, y, z; beams "
                                  "in their frame)"),
    },
    "beam": {
        "length": Key("float", check=positive, doc="length of the neutral axis (m)"),
        "width": Key("float", check=positive, doc="section width w, along z (m)"),
        "height": Key("float", check=positive, doc="section height h, along y (m)"),
        "nodes": Key("int", check=lambda v: None if v >= 2 else "must be at least 2",
                     doc="total nodes on the beam"),
        "segments": Key("floats", None, doc="segment lengths between fixed nodes (m); "
                        "each is split into equal elements"),
        "bending": Key("str", "continuum", one_of("continuum", "cubic", "cable"),
                       "'continuum': the paper's element (curvature constant per element); "
                       "'cubic': curvature from the cubic centre line r_xx, higher accuracy "
                       "(docs/theory.md section 12); 'cable' (boom, cantilever and spin-up "
                       "scenes, formulation 'nonlinear'): the ANCF cable, r and r_x per node, "
                       "Euler-Bernoulli "
                       "(a section with I_y != I_z bends about r3 and needs scene.planar = "
                       "'xy')"),
        "geometric_stiffness": Key("bool", False, doc=GEOMETRIC_STIFFNESS_DOC),
        "modes": Key("int", 0, non_negative, MODES_DOC),
    },
    "material": {
        "youngs_modulus": Key("float", check=positive, doc="E (Pa)"),
        "density": Key("float", check=positive, doc="rho (kg/m^3)"),
        "poisson_ratio": Key("float", 0.0, within(0.0, 0.5, open_hi=True),
                             doc="nu in the elastic law; 0 avoids Poisson locking"),
        "damping_time": Key("float", 0.0, non_negative, DAMPING_TIME_DOC),
    },
    "boom": {
        "pivot_offset": Key("float", 0.295, positive, "H = |O A1| (m)"),
        "angle_deg": Key("float", 0.0, within(-180.0, 180.0),
                         "luffing angle phi of the rigid configuration at t = 0 (deg)"),
        "omega": Key("float", 0.2, non_negative, "luffing rate (rad/s); 0 holds phi fixed"),
        "t_start": Key("float", 1.0, positive, "t_s: duration of the smooth start (s)"),
        "t_brake": Key("float", 1.0, positive, "t_b: duration of the smooth braking (s)"),
        "angle_end_deg": Key("float", 60.0, within(-180.0, 180.0),
                             "luffing angle reached at the end of braking (deg)"),
    },
    "cantilever": {
        "clamp": Key("str", "section", one_of("section", "full", "pin"),
                     "'section' fixes r, r_y, r_z of the root node; 'full' also r_x; 'pin' "
                     "fixes r and r_z (a hinge about r3)"),
    },
    "spinup": {
        "omega": Key("float", 6.0, positive, "final hub speed W (rad/s)"),
        "period": Key("float", 15.0, positive, "spin-up time T (s)"),
    },
    "plate": {
        "length_x": Key("float", check=positive, doc="side along r1 (m)"),
        "length_y": Key("float", check=positive, doc="side along r2 (m)"),
        "thickness": Key("float", check=positive, doc="plate thickness h (m)"),
        "nx": Key("int", 4, positive, "elements along r1"),
        "ny": Key("int", 4, positive, "elements along r2"),
        "variant": Key("str", "completed", one_of("plain", "completed"),
                       "thin plate element (seed 003): 'plain' (Dufva-Shabana) or "
                       "'completed' (unit normal as third gradient)"),
        "support": Key("str", "corner_spherical",
                       one_of("corner_spherical", "simply_supported", "clamped_edge"),
                       "'corner_spherical': spherical joint at the corner (0, 0, 0); "
                       "'simply_supported': w = 0 on all edges; 'clamped_edge': edge x = 0 "
                       "clamped"),
    },
    "leaf": {
        "arc_length": Key("float", None, positive, "mid-surface arc length (m); required "
                          "in &leaf scenes (in &spring scenes the leaves' lengths are in &spring)"),
        "radius": Key("float", None, positive, "mid-surface radius of the initial "
                      "(assembled) shape (m); concave up, symmetric about r1 = 0; required in "
                      "&leaf scenes"),
        "prestress": Key("bool", False, doc="&spring scenes: the lower leaf's stress-free "
                         "radius is free_radius (needs the effect 'prestress'); off: it is "
                         "stress-free as assembled"),
        "free_radius": Key("float", None, positive, "radius of the stress-free shape (m); "
                           "differs from radius only with the effect 'prestress' "
                           "(default: radius)"),
        "width": Key("float", check=positive, doc="leaf width along r2 (m)"),
        "thickness": Key("float", check=positive, doc="leaf thickness (m)"),
        "nx": Key("int", 8, lambda v: None if v >= 2 and v % 2 == 0 else
                  "must be even (the middle of the leaf is a node line)",
                  "elements along the arc"),
        "ny": Key("int", 1, positive, "elements across the width"),
        "variant": Key("str", "completed", one_of("plain", "completed"),
                       "'completed' removes the initial strain of the curved reference; "
                       "'plain' springs back toward flat (seed 003's motivation)"),
        "support": Key("str", "middle_clamp", one_of("middle_clamp", "free"),
                       "'middle_clamp': r and r_x of the middle node line fixed (the "
                       "axle's U-bolts, seed 003); 'free': unsupported"),
    },
    "spring": {
        "main_arc_length": Key("float", 1.2, positive, "main (upper) leaf arc length (m)"),
        "main_radius": Key("float", 2.0, positive, "main leaf mid-surface radius (m)"),
        "main_nx": Key("int", 12, lambda v: None if v >= 2 and v % 2 == 0 else
                       "must be even (the middle of the leaf is a node line)",
                       "main leaf elements along the arc"),
        "lower_arc_length": Key("float", 0.8, positive, "lower leaf arc length (m)"),
        "lower_radius": Key("float", None, positive, "lower leaf mid-surface radius as "
                            "assembled (m); default main_radius + thickness (concentric, "
                            "touching)"),
        "lower_nx": Key("int", 8, lambda v: None if v >= 2 and v % 2 == 0 else
                        "must be even (the middle of the leaf is a node line)",
                        "lower leaf elements along the arc"),
        "chassis_mass": Key("float", 500.0, positive, "chassis mass (kg)"),
        "chassis_inertia": Key("float", 50.0, positive, "chassis inertia about r2 (kg m^2)"),
        "shackle_length": Key("float", 0.1, positive, "shackle length, eye to chassis (m)"),
        "shackle_mass": Key("float", 2.0, positive, "shackle mass (kg)"),
        "guide": Key("str", "planar", one_of("planar", "vertical"),
                     "'planar': chassis free in the r1-r3 plane; 'vertical': it translates "
                     "without turning (load cycle; its horizontal drift stays free, as the "
                     "axle and the front eye are both held along r1)"),
        "contact_stiffness": Key("float", 1.0e6, positive, "penalty stiffness K (N/m)"),
        "contact_damping": Key("float", 1.0e4, non_negative,
                               "contact damping C in F_n = K d - C d' d"),
        "friction_coefficient": Key("float", 0.3, non_negative, "Coulomb coefficient mu"),
        "slip_velocity": Key("float", 0.08, positive, "critical slip velocity V_t (m/s)"),
        "contact_points": Key("int", 3, lambda v: None if v >= 2 else "must be at least 2",
                              "contact points per end edge of the lower leaf"),
        "cycle_force": Key("float", 0.0, non_negative, "effect 'load_cycle': peak downward "
                           "force on the chassis (N)"),
        "cycle_period": Key("float", 4.0, positive, "effect 'load_cycle': duration of the "
                            "cycle 0 -> peak -> 0 (s)"),
        "settle": Key("str", "prestress", one_of("prestress", "gravity", "none"),
                      "dynamic start at rest: 'prestress' from the equilibrium of the "
                      "assembled spring without gravity (the prestress carried by contact), "
                      "'gravity' from the static equilibrium under gravity as well (road "
                      "input, load cycles), 'none' from the assembled configuration"),
        "road": Key("str", "none", one_of("none", "sine", "table"),
                    "vertical road input at the axle clamp: 'sine' (road_amplitude, "
                    "road_frequency, raised over road_ramp) or 'table' (road_file)"),
        "road_amplitude": Key("float", 0.0, non_negative, "road = 'sine': amplitude (m)"),
        "road_frequency": Key("float", 1.0, positive, "road = 'sine': frequency (Hz)"),
        "road_ramp": Key("float", 1.0, non_negative, "road = 'sine': time over which the "
                         "amplitude rises smoothly from 0 (s)"),
        "road_file": Key("str", None, doc="road = 'table': CSV of (t in s, z in m) rows, "
                         "linear in between; relative to the scene file"),
    },
    "loads": {
        "gravity": Key("float", 9.81, non_negative, "gravitational acceleration (m/s^2)"),
        "tip_mass": Key("float", 0.0, non_negative, "lumped mass at the tip (kg)"),
        "moment": Key("float", 0.0, doc="boom: moment M_B about +r3 on the section at A2 (N m)"),
        "tip_force": Key("floats", [0.0, 0.0, 0.0], size=3, doc="force at the tip (N)"),
        "end_moment": Key("float", 0.0, doc="moment about +r3 on the tip section (N m)"),
        "pressure": Key("float", 0.0, doc="plate: dead pressure along -r3 (Pa)"),
    },
    "solver": {
        "static_method": Key("str", "auto", one_of("auto", "split", "newton", "arc_length"),
                             "static solver: 'split' (the split iteration of seed 000: "
                             "'ffr' bodies, dead loads, no force element, no contact), "
                             "'newton' (Newton-Raphson, any scene), 'auto' (default: "
                             "'split' where it applies, 'newton' otherwise; /static "
                             "attributes method and method_setting record the choice), "
                             "'arc_length' (path-following with the load factor an "
                             "unknown: passes limit points and snap-backs, writes "
                             "/static/path; keys arc_length, max_steps, target_load_factor, "
                             "control_probe); a load-controlled state ('split', 'newton') "
                             "that is an unstable equilibrium (/static stability_index > 0) "
                             "ends the run with exit 3, status 'unstable', the state kept"),
        "arc_length": Key("float", 0.0, non_negative,
                          "static_method = 'arc_length': the first step's length in the "
                          "coordinates (m; adapted to the iteration count after; 0: a "
                          "twentieth of the linear response to the target load)"),
        "max_steps": Key("int", 200, positive,
                         "static_method = 'arc_length': steps allowed before the path ends "
                         "short of target_load_factor (exit 3, the path written)"),
        "target_load_factor": Key("float", 1.0, lambda v: None if v != 0 else "must not be 0",
                                  "static_method = 'arc_length': the load factor (multiple "
                                  "of the scene's loads) where the path ends, at its first "
                                  "crossing; the static result is the state there"),
        "control_probe": Key("str", "", doc="static_method = 'arc_length': the probe whose "
                             "displacement is the path's abscissa (/static/path/"
                             "displacement; '': the scene's first probe)"),
        "tol": Key("float", 1e-10, lambda v: None if 0 < v < 1 else "must lie in (0, 1)",
                   "relative tolerance of the static solve"),
        "max_iter": Key("int", 50, positive, "iteration limit of the static solve"),
        "load_steps": Key("int", 1, positive, "load increments of the static Newton solve "
                          "(large deformation)"),
        "split_p": Key("float", 0.0, within(0.0, 1.0, open_hi=True),
                       "splitting parameter p of K_RR = K_RR1 + K_RR2, in [0, 1)"),
        "dt": Key("float", 1e-3, positive, "time step (s), dynamic analyses"),
        "t_end": Key("float", 10.0, non_negative, "end time (s), dynamic analyses"),
        "integrator": Key("str", "newmark", one_of("newmark", "generalized_alpha",
                                                   "energy_momentum"),
                          "time integrator: 'newmark', 'generalized_alpha' (rho_inf), or "
                          "'energy_momentum' (the midpoint rule with a discrete gradient of "
                          "the strain energy: conserves the energy of an undamped, undriven "
                          "system to the Newton tolerance at any step, and its momenta; "
                          "nonlinear beams, cables, ropes, masses, gravity, pins and revolute "
                          "joints only, fixed steps; docs/theory.md)"),
        "rho_inf": Key("float", 0.9, within(0.0, 1.0),
                       "generalized-alpha: spectral radius at infinite frequency (1: no "
                       "numerical damping)"),
        "beta": Key("float", 0.25, lambda v: None if 0 < v <= 0.5 else "must lie in (0, 0.5]",
                    "Newmark beta (1/4: average acceleration, the paper's choice)"),
        "gamma": Key("float", 0.5, within(0.5, 1.0), "Newmark gamma (1/2: no damping)"),
        "newton_tol": Key("float", 1e-10, lambda v: None if 0 < v < 1 else "must lie in (0, 1)",
                          "a step ends when its Newton correction is below newton_tol * length "
                          "(without contact also below 1 % of the step's motion; with jacobian "
                          "= 'reuse' a correction of a matrix kept from earlier steps needs a "
                          "measured contraction too: docs/theory.md, 'Loose tolerances')"),
        "max_newton": Key("int", 10, positive, "Newton iterations allowed per step"),
        "jacobian": Key("str", "reuse", one_of("step", "iteration", "reuse"),
                        "when a refactorized model's iteration matrix is refreshed: 'reuse' "
                        "(kept across steps while Newton contracts; docs/theory.md section "
                        "14), 'step' (at each step, and when a correction does not halve), "
                        "'iteration' (full Newton); pure FFR systems factorize once whatever "
                        "this says"),
        "contraction": Key("float", 0.25, lambda v: None if 0 < v < 1 else "must lie in (0, 1)",
                           "jacobian = 'reuse': refresh when a correction exceeds this fraction "
                           "of the previous one (0.25: an old matrix that contracts more slowly "
                           "costs more corrections than a new one costs to factorize); from a "
                           "step's third correction on the smaller of this and 0.1"),
        "carry": Key("str", "rotation", one_of("rotation", "off"),
                     "jacobian = 'reuse': 'rotation' turns the kept iteration matrix with the "
                     "system's rotation since it was factorized (absolute-coordinate models "
                     "without contact; docs/theory.md section 28), so a spinning or swinging "
                     "body keeps its matrix; 'off' reuses it unturned"),
        "settle": Key("str", "none", one_of("none", "unloaded", "loaded"),
                      "dynamic runs start at rest from: 'none' the assembled configuration; "
                      "'unloaded' the equilibrium of the internal forces alone (prestress "
                      "carried by contact, loads off); 'loaded' the static equilibrium under "
                      "every load (written to /static)"),
        "linear_joints": Key("str", "auto", one_of("auto", "eliminate", "multipliers"),
                             "linear joint equations: eliminated (q = B e + q0, seed 003) or "
                             "kept with multipliers (seed 000); 'auto' eliminates when the "
                             "system has rigid bodies"),
        "dt_min": Key("float", 0.0, non_negative,
                      "smallest step (s) a failed step is cut to (halved from dt, doubled "
                      "back after 4 successes; 0: dt / 1024; dt_min = dt: no cuts; at most "
                      "dt); a step failing at dt_min, or whose error estimate exceeds "
                      "solver.tolerance there (step = 'adaptive'), ends the run (exit 3)"),
        "step": Key("str", "fixed", one_of("fixed", "adaptive"),
                    "'fixed': steps of dt, cut where one fails; 'adaptive': each step sized "
                    "by the local error estimate (Zienkiewicz & Xie 1991) to "
                    "solver.tolerance, at most dt (the output interval), at least dt_min"),
        "tolerance": Key("float", 1e-6, lambda v: None if 0 < v < 1 else "must lie in (0, 1)",
                         "step = 'adaptive': local position error allowed per step, relative "
                         "to the model's length"),
        "energy_tolerance": Key("float", 0.01, positive,
                                "dynamic runs: the energy the integrator may make (the balance "
                                "total - total(0) - works rising), relative to the run's energy "
                                "scale (the largest kinetic, kinetic plus strain energy, "
                                "potential-energy change or work so far); beyond it the run "
                                "ends with exit 3, status 'unstable', the rows kept"),
    },
    "output": {
        "file": Key("str", None, doc="HDF5 result file (default results/<scene>.h5)"),
        "q": Key("bool", False, doc="store the coordinates q at every step"),
        "plot": Key("bool", False, doc="ancf run: write the plot beside the result (OUT.png, "
                    "as ancf run --plot does; ancf plot draws any result file later)"),
        "chunk_steps": Key("int", 1000, positive,
                           "steps per kernel call at most; the rows reach the file at least "
                           "once a second"),
        "xdmf": Key("bool", True, doc="write OUT.xdmf beside the result for ParaView: the "
                    "motion of a dynamic run (stores q), the static state, or the modal or "
                    "buckling shapes, with every body (plates as quadrilaterals, beams and "
                    "cables as polylines, rigid bodies as their centre, axes and inertia "
                    "box, force elements and distance joints as lines, point masses and "
                    "joints as points)"),
        "xdmf_frames": Key("int", 250, at_least(2), "the most frames the XDMF holds: longer "
                           "runs show every k-th step (and the last); each frame costs "
                           "about 0.4 ms of output"),
        "stations": Key("int", 3, at_least(2), "points per beam element where the section "
                        "forces and stresses are evaluated (both ends included); their "
                        "memory (about 4 kB per element and station, with sections = "
                        ".true. 192 B more per dynamic row) is estimated before the run and "
                        "refused above half the memory available"),
        "sections": Key("bool", False, doc="dynamic runs: store the section forces of every "
                        "beam at every step (/dynamic/sections); the stress envelope is kept "
                        "either way"),
        "answers": Key("bool", True, doc="dynamic runs: record the joint reactions and the "
                       "stress envelope at every step (/dynamic/reactions, /dynamic/stress; "
                       "about 10 microseconds of CPU per row for the 28-node FFR boom)"),
    },
}

#: Groups that define what is built; a scene has exactly one of them.
MODEL_GROUPS = ("boom", "cantilever", "spinup", "plate", "leaf", "spring")
#: Models built from thin plate elements (seed 003); the others are beams (seed 000).
PLATE_KINDS = ("plate", "leaf", "spring")
COMMON_GROUPS = ("scene", "material", "loads", "solver", "output")


def coerce(kind: str, raw: Any, where: dict) -> Any:
    def bad(expected: str) -> InputError:
        got = "no value" if raw is None else short_repr(raw)
        return InputError(f"expected {expected}, got {got}", **where)

    def as_float(x: Any) -> float:
        x = plain_value(x)  # numpy scalars (np.float32 too) count as numbers
        if isinstance(x, bool) or not isinstance(x, (int, float)):
            raise bad("a number")
        if not math.isfinite(float(x)):
            raise bad("a finite number")
        return check_magnitude(float(x), where)

    if kind == "float":
        return as_float(raw)
    if kind == "int":
        raw = plain_value(raw)
        if isinstance(raw, bool) or not isinstance(raw, int):
            if not (isinstance(raw, float) and raw.is_integer()):
                raise bad("an integer")
            raw = int(raw)
        return check_int32(raw, where)
    if kind == "str":
        if not isinstance(raw, str):
            raise bad("a string")
        return raw.strip()
    if kind == "bool":
        if not isinstance(raw, bool):
            raise bad(".true. or .false.")
        return raw
    if kind == "floats":
        items = raw if isinstance(raw, list) else [raw]
        return [as_float(x) for x in items]
    if kind == "strs":
        items = raw if isinstance(raw, list) else [raw]
        if not all(isinstance(x, str) for x in items):
            raise bad("a list of strings")
        return [x.strip() for x in items if x is not None and x.strip()]  # '' = none
    raise AssertionError(kind)


def vector3(v: Any) -> str | None:
    return None if len(v) == 3 else f"must be three numbers (x, y, z), got {len(v)}"


def points3(v: Any) -> str | None:
    return None if len(v) and len(v) % 3 == 0 else \
        f"must be x, y, z (or several points: a multiple of 3 numbers), got {len(v)} numbers"


def name_key(doc: str = "a unique name of the item") -> Key:
    return Key("str", check=check_name, doc=doc)


def principal_positive(v: Any) -> str | None:
    return None if min(v[:3]) > 0 else "must have positive Ixx, Iyy and Izz"


#: Repeatable, named groups of general scenes (SPEC section 8); list kinds are checked as a
#: whole (vector3, points3) rather than per item. The kinds' groups (&beam, &cable, &plate,
#: &leaf, &rigid_body, &force_element) are declared by the kinds (system/kinds/) and added
#: by :func:`register_group`.
GENERAL_SCHEMA: dict[str, dict[str, Key]] = {
    "material": {
        "name": name_key(),
        "youngs_modulus": Key("float", check=positive, doc="E (Pa)"),
        "density": Key("float", check=positive, doc="rho (kg/m^3)"),
        "poisson_ratio": Key("float", 0.0, within(0.0, 0.5, open_hi=True), "nu"),
        "damping_time": Key("float", 0.0, non_negative, DAMPING_TIME_DOC),
    },
    "joint": {
        "name": name_key(),
        "type": Key("str", check=one_of("weld", "revolute", "spherical", "distance", "prescribed",
                                        "fix", "arm", "hub", "prismatic", "cylindrical",
                                        "universal"), doc="joint type (SPEC section 8)"),
        "body1": Key("str", "ground", doc="first body (or 'ground')"),
        "body2": Key("str", doc="second body"),
        "point": Key("floats", None, points3, "joint point(s): any material points of the bodies "
                     "(between nodes, off a beam's axis)"),
        "axis": Key("floats", None, vector3, "hinge axis / direction ('prismatic', "
                    "'cylindrical': the slide axis; 'universal': the cross's axis on body1)"),
        "axis2": Key("floats", None, vector3, "'universal': the cross's axis on body2 (normal "
                     "to axis at t = 0)"),
        "drive": Key("str", None, doc="drive of 'distance', 'prescribed', 'hub', 'prismatic' "
                     "(its relative translation along axis, from the value at t = 0)"),
        "point1": Key("floats", None, vector3, "'distance': point on body1"),
        "point2": Key("floats", None, vector3, "'distance': point on body2"),
        "pivot": Key("floats", None, vector3, "'prescribed', 'arm', 'hub': centre of rotation"),
        "vector": Key("str", "r", one_of("r", "r_x", "r_y", "r_z"), "'fix': the nodal vector held"),
        "edge": Key("str", None, one_of("x0", "x1", "y0", "y1"),
                    "instead of point: every node of a plate's or leaf's side (x0, x1: the ends "
                    "along edge_x; y0, y1: the sides along edge_y), whatever the mesh"),
        "box": Key("floats", None, size=6, doc="instead of point: every node of the flexible body "
                   "in the box x0, y0, z0, x1, y1, z1 (m), whatever the mesh"),
    },
    "drive": {
        "name": name_key(),
        "type": Key("str", check=one_of("constant", "luffing", "spinup", "cycle", "sine", "table",
                                        "ramp"),
                    doc="drive type"),
        "value": Key("float", None, doc="'constant': the value"),
        "omega": Key("float", None, doc="'luffing', 'spinup': rate (rad/s, or the drive's "
                      "unit per s)"),
        "t_start": Key("float", None, positive, "'luffing': smooth start (s)"),
        "t_brake": Key("float", None, positive, "'luffing': smooth braking (s)"),
        "start_deg": Key("float", None, doc="'luffing': angle at t = 0 (deg)"),
        "end_deg": Key("float", None, doc="'luffing': angle after braking (deg)"),
        "period": Key("float", None, positive, "'spinup': spin-up time; 'cycle': duration (s)"),
        "start": Key("float", None, doc="'spinup', 'ramp', 'luffing' (with sweep): value at "
                      "the start (rad, or the drive's unit)"),
        "amplitude": Key("float", None, doc="'cycle', 'sine': amplitude"),
        "t0": Key("float", None, doc="'cycle', 'sine', 'ramp': start time (s)"),
        "frequency": Key("float", None, non_negative, "'sine': frequency (Hz)"),
        "phase": Key("float", None, doc="'sine': phase (rad)"),
        "offset": Key("float", None, doc="'sine': offset"),
        "ramp": Key("float", None, non_negative, "'sine': smooth ramp-in time (s)"),
        "file": Key("str", None, doc="'table': CSV file of (t, value) rows, relative to the scene"),
        "times": Key("floats", None, doc="'table': times (s), increasing"),
        "values": Key("floats", None, doc="'table': values at the times"),
        "interpolation": Key("str", None, one_of("linear", "cubic", "pchip"),
                             "'table': 'linear' (default; the rate jumps at the points), "
                             "'cubic' (C2 cubic spline) or 'pchip' (monotone piecewise cubic); "
                             "both cubic kinds start and end with zero rate"),
        "rate": Key("float", None, doc="'ramp': the rate reached (units/s)"),
        "t_ramp": Key("float", None, non_negative, "'ramp': time to reach the rate smoothly (s)"),
        "sweep": Key("float", None, doc="'luffing' (as the Python API): total change (rad, or "
                     "the drive's unit, e.g. m for a cylinder length), instead of "
                     "start_deg/end_deg; with start"),
    },
    "load": {
        "name": name_key(),
        "type": Key("str", check=one_of("gravity", "force", "moment", "point_mass", "pressure"),
                    doc="load type"),
        "body": Key("str", None, doc="the loaded body"),
        "point": Key("floats", None, vector3, "material point (m)"),
        "vector": Key("floats", None, vector3, "gravity (m/s^2), force (N), moment (N m)"),
        "mass": Key("float", None, non_negative, "'point_mass': mass (kg)"),
        "value": Key("float", None, doc="'pressure': pressure (Pa) against the normal"),
        "drive": Key("str", None, doc="'force', 'moment': scales the vector with the drive's "
                     "value (a pulse, a table)"),
        "follower": Key("bool", False, doc="'force', 'moment': the vector is fixed in the body's "
                        "material frame at the point (given at t = 0) and turns with it"),
        "effect": Key("str", None, doc="the effect it belongs to (default by type: gravity, "
                      "point_loads, point_loads, tip_mass, pressure)"),
    },
    "contact": {
        "name": name_key(),
        "body1": Key("str", doc="the searched (upper) plate or leaf"),
        "body2": Key("str", doc="the plate or leaf whose end edges carry the points"),
        "stiffness": Key("float", check=positive, doc="penalty K (N/m)"),
        "damping": Key("float", 0.0, non_negative, "C in F_n = K d - C d' d"),
        "friction": Key("float", 0.0, non_negative, "Coulomb mu"),
        "slip_speed": Key("float", 0.08, positive, "critical slip speed V_t (m/s)"),
        "points": Key("int", 3, at_least(2), "contact points per end edge"),
    },
    "probe": {
        "name": name_key(),
        "body": Key("str", doc="the body"),
        "point": Key("floats", check=vector3, doc="material point (m)"),
    },
}
#: the groups of the kinds (system/registry.py), in registration order: GENERAL_SCHEMA lists
#: them after &material, before the groups above that refer to them
_KIND_GROUPS: list[str] = []


def register_group(group: str, keys: dict[str, Key]) -> None:
    """A kind's repeatable group of general scenes (``system.registry.register``: each kind
    declares its keys once, in its own module); GENERAL_SCHEMA keeps its order: &material,
    the kinds' groups, then the others."""
    if group in GENERAL_SCHEMA:
        raise ValueError(f"the general scene group {group!r} is declared twice")
    _KIND_GROUPS.append(group)
    others = {g: k for g, k in GENERAL_SCHEMA.items() if g != "material"}
    material = GENERAL_SCHEMA.pop("material")
    GENERAL_SCHEMA.clear()   # (in place: the modules that imported it see the kinds)
    GENERAL_SCHEMA["material"] = material
    GENERAL_SCHEMA.update({g: keys if g == group else others[g] for g in _KIND_GROUPS})
    GENERAL_SCHEMA.update({g: k for g, k in others.items() if g not in _KIND_GROUPS})


#: Groups of general scenes that occur once (shared with the template scenes).
GENERAL_SINGLE_GROUPS = ("scene", "solver", "output")
#: Modal analysis and linear buckling (SPEC section 10; solvers/modal.py, buckling.py): groups
#: of both kinds of scene, read when scene.analysis is 'modal' or 'buckling'.
SCHEMA["modal"] = {
    "modes": Key("int", 10, at_least(1), "number of modes (lowest frequencies first)"),
    "solver": Key("str", "auto", one_of("auto", "dense", "sparse"),
                  "eigensolver: 'dense' (null space of the constraints, LAPACK), 'sparse' "
                  "(shift-invert Lanczos on the multiplier form, MUMPS + ARPACK), 'auto' (dense "
                  "up to 150 free coordinates)"),
    "rigid_tol": Key("float", 1e-9, lambda v: None if 0 < v < 1e-3 else
                     "must lie in (0, 1e-3)", "modes with |omega^2| below rigid_tol times "
                     "max diag K / max diag M are rigid-body modes, reported at 0 Hz"),
    "spin_rate": Key("float", 0.0, doc="modes in a frame turning steadily at this rate "
                     "(rad/s) about spin_axis through spin_centre, with the centrifugal and "
                     "Coriolis forces (0: no rotation); at most 1e4 rad/s in magnitude "
                     "(scene.bounds: about 95,000 rpm, beyond the fastest turbines)"),
    "spin_axis": Key("floats", [0.0, 0.0, 1.0], vector3, "axis of the steady rotation"),
    "spin_centre": Key("floats", [0.0, 0.0, 0.0], vector3, "a point of the rotation axis (m)"),
}
SCHEMA["buckling"] = {
    "modes": Key("int", 3, at_least(1), "number of load factors (lowest positive first)"),
    "fixed_loads": Key("strs", [], doc="loads (by name) or effects (e.g. 'gravity') kept at "
                       "their value; the others are the reference loads the factor multiplies"),
    "method": Key("str", "nonlinear", one_of("nonlinear", "linear"),
                  "both start from the scene's static state (factor 1); 'nonlinear': the "
                  "stability limit on the static path, followed by arc length until the lowest "
                  "stiffness vanishes (a limit point or a bifurcation); 'linear': "
                  "(K_1 + nu K_g) phi = 0 once, factor "
                  "1 + nu, K_g from the tangents at factors 1 and 1 + reference_factor"),
    "solver": Key("str", "auto", one_of("auto", "dense", "sparse"),
                  "eigensolver, as modal.solver"),
    "rtol": Key("float", 1e-6, lambda v: None if 0 < v < 0.1 else "must lie in (0, 0.1)",
                "method 'nonlinear': relative change of the load factor that ends the location of "
                "the stability limit on the arc"),
    "load_steps": Key("int", 1, positive, "Newton load increments of the load-controlled "
                      "static solves (the scene's state; method 'linear''s states)"),
    "reference_factor": Key("float", 1.0, positive, "the first state on the path past "
                            "the scene's own: its load factor is 1 + this ('linear'; "
                            "'nonlinear': the first arc's increment of the factor along the "
                            "tangent; larger when the scene's loads are far below the limit)"),
}
#: &modal and &buckling occur once in general scenes too
GENERAL_SINGLE_GROUPS = GENERAL_SINGLE_GROUPS + ("modal", "buckling")
#: Groups of any scene that define names the other groups' values use (SPEC section 8.2;
#: :mod:`ancfdrv.io.parameters`), read before them and never built: ``&parameters`` (any
#: keys: each a named number or an expression over earlier ones) and ``&point``; both may
#: repeat.
DEFINITION_GROUPS = ("parameters", "point")
POINT_SCHEMA: dict[str, Key] = {
    "name": name_key("a unique name of the point; the point keys of any group "
                     "(ancfdrv.io.parameters.POINT_KEYS) may give it instead of x, y, z"),
    "at": Key("floats", check=vector3, doc="the point's coordinates x, y, z (m; numbers, "
              "expressions or an earlier point's name)"),
}
#: Groups only general scenes have.
GENERAL_ONLY_GROUPS = ("rigid_body", "joint", "drive", "load", "contact", "probe", "cable",
                       "force_element")
#: checks that take a list key's whole value (the others take each item)
WHOLE_LIST_CHECKS = (vector3, points3, principal_positive)


def checked_value(spec: Key, raw: Any, where: dict[str, Any]) -> Any:
    """A key's value typed (:func:`coerce`), of its size and passing its check, else an
    InputError at ``where`` (the namelist's and the Python API's one rule)."""
    kind, plain = spec.kind, type(raw)
    # a namelist's plain values that coerce would return as they are (a finite float of
    # an accepted magnitude, a 32-bit int, a bool), or stripped (a string), at once
    if kind == "float" and plain is float and abs(raw) <= MAX_MAGNITUDE:
        value = raw
    elif kind == "int" and plain is int and abs(raw) <= INT32_MAX:
        value = raw
    elif kind == "str" and plain is str:
        value = raw.strip()
    elif kind == "bool" and plain is bool:
        value = raw
    elif kind == "floats" and plain is list and all(
            type(x) is float and abs(x) <= MAX_MAGNITUDE for x in raw):
        value = list(raw)   # (coerce's list: each float as it is)
    else:
        value = coerce(kind, raw, where)
    if spec.size is not None and len(value) != spec.size:
        raise InputError(f"expected {spec.size} values, got {len(value)}", **where)
    if spec.check is not None:
        whole = spec.check in WHOLE_LIST_CHECKS
        items = [value] if whole or spec.kind != "floats" else value
        for item in items:
            message = spec.check(item)
            if message:
                raise InputError(f"{short_repr(value)} {message}", **where)
    return value


# -- the Python API's door: the same types, ranges and messages as the namelist -----------

#: the types plain_value returns unchanged at once (exactly these; subclasses such as numpy
#: scalars take the general way)
_PLAIN_TYPES = frozenset((int, float, str, bool, type(None)))


def plain_value(value: Any) -> Any:
    """A value as plain Python for checks and messages: numpy scalars become int/float
    (messages print ``2.2``, not ``np.float64(2.2)``), arrays and tuples become lists;
    anything else is returned unchanged (and refused by the type check that follows)."""
    if type(value) in _PLAIN_TYPES:   # (the namelist's values: returned at once)
        return value
    import numpy as np
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return [plain_value(x) for x in value.ravel().tolist()]
    if isinstance(value, (list, tuple)):
        out: list[Any] = []
        for item in value:
            item = plain_value(item)
            out.extend(item if isinstance(item, list) else [item])
        return out
    return value


def short_repr(value: Any, limit: int = 60) -> str:
    """repr of a value cut to ``limit`` characters (a message never echoes a whole file)."""
    text = repr(plain_value(value))
    if len(text) <= limit:
        return text
    return text[:limit - 4] + "..." + text[-1]


def check_call(group: str, label: str, values: dict[str, Any]) -> dict[str, Any]:
    """The values of one System API call checked against the general scene schema's key of
    the same name (type, finiteness, magnitude, size and range): the checks and messages of
    a namelist group (``&material[steel] youngs_modulus: expected a number, got 'abc'``).
    Keys given as None (not given) and keys the schema does not have are passed through
    unchanged; returns the checked values (plain Python numbers and lists)."""
    schema = GENERAL_SCHEMA[group]
    out = dict(values)
    for key, raw in values.items():
        spec = schema.get(key)
        if spec is None or raw is None:
            continue
        where = dict(group=label, key=key)
        raw = plain_value(raw)
        if spec.kind == "str" and not isinstance(raw, str):
            raise InputError(f"expected a string, got {short_repr(raw)}", **where)
        if spec.kind == "floats" and not isinstance(raw, list):
            raw = [raw]
        out[key] = checked_value(spec, raw, where)
    return out


def check_keywords(function: str, values: dict[str, Any],
                   keys: dict[str, str]) -> dict[str, Any]:
    """Keyword arguments of a Python API function that stand for namelist keys, checked
    with those keys' rules and messages: ``keys`` maps each argument to the group of
    :data:`SCHEMA` whose key of the same name it is (``modes(): &modal rigid_tol: -1.0 must
    lie in (0, 1e-3)``). An argument ``keys`` does not name is refused with the ones the
    function takes. Returns the checked values (plain Python numbers, strings and lists)."""
    unknown = sorted(set(values) - set(keys))
    if unknown:
        raise InputError(f"{function}: unknown keyword argument "
                         f"{', '.join(map(repr, unknown))}; it takes "
                         f"{', '.join(sorted(keys))} (the namelist keys of the same name, "
                         "docs/scenes.md)")
    return {name: checked_value(SCHEMA[keys[name]][name], plain_value(raw),
                                dict(file=function, group=keys[name], key=name))
            for name, raw in values.items()}
