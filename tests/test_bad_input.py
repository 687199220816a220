"""A corpus of bad scenes and command lines (issue 14, item 6).

Every case must end with exit status 2 and one line on stderr that names the problem and
where it is (the file, the group -- ``&beam[boom]`` for a named group -- and the key), with
no traceback, without allocating the model (tracemalloc's peak stays small: the huge meshes
are refused from an estimate) and without creating, changing or removing any file. Most
cases run in-process through :func:`ancfdrv.cli.main`; a few run ``python -m ancfdrv.cli``.

``python tests/test_bad_input.py`` runs the whole corpus, each case in its own process with
a memory limit, and prints the table of the outcomes (clean exit 2, tracebacks, silent
acceptances, other) that issue 14 asks to re-measure.
"""
from __future__ import annotations

import hashlib
import os
import subprocess
import sys
import tracemalloc
from dataclasses import dataclass, field
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
INPUTS = ROOT / "inputs"

# -- base scenes: each runs as given (test_base_scenes_are_valid) ----------------------------

BOOM = """&scene title = 'boom', analysis = 'static', formulation = 'ffr',
       effects = 'gravity', 'tip_mass', 'bending_moment' /
&beam length = 7.791, width = 0.1, height = 0.1, nodes = 10, segments = 1.791, 3.0, 3.0 /
&material youngs_modulus = 2.1e11, density = 7850.0 /
&boom angle_deg = 15 /
&loads tip_mass = 50.0, moment = 1000.0 /
&solver static_method = 'split' /
"""

LUFFING = """&scene title = 'luffing', analysis = 'static+dynamic', formulation = 'ffr',
       effects = 'gravity' /
&beam length = 7.791, width = 0.1, height = 0.1, nodes = 4, segments = 1.791, 3.0, 3.0 /
&material youngs_modulus = 2.1e11, density = 7850.0 /
&boom angle_deg = 0.0, angle_end_deg = 60.0, omega = 0.2, t_start = 1.0, t_brake = 1.0 /
&loads gravity = 9.81 /
&solver static_method = 'split', dt = 1e-3, t_end = 0.01, max_newton = 10 /
&output chunk_steps = 100 /
"""

PLATE = """&scene title = 'plate', analysis = 'dynamic', formulation = 'nonlinear',
       effects = 'gravity' /
&plate length_x = 0.3, length_y = 0.3, thickness = 0.01, nx = 2, ny = 2 /
&material youngs_modulus = 1.0e5, density = 7810.0, poisson_ratio = 0.3 /
&loads gravity = 9.81 /
&solver integrator = 'generalized_alpha', rho_inf = 1.0, dt = 1e-3, t_end = 0.005 /
"""

LEAF = """&scene title = 'leaf', analysis = 'dynamic', formulation = 'nonlinear', effects = '' /
&leaf arc_length = 0.8, radius = 1.986, width = 0.07, thickness = 0.014, nx = 8 /
&material youngs_modulus = 2.1e11, density = 7810.0, poisson_ratio = 0.3 /
&solver integrator = 'generalized_alpha', rho_inf = 0.5, dt = 1e-4, t_end = 0.001 /
"""

SPRING = (INPUTS / "leaf_spring.nml").read_text().replace("t_end = 5.0", "t_end = 0.002")

GENERAL = """&scene title = 'general', analysis = 'dynamic', formulation = 'nonlinear' /
&material name = 'steel', youngs_modulus = 2.1e11, density = 7850.0 /
&drive name = 'wave', type = 'sine', amplitude = 10.0, frequency = 2.0 /
&beam name = 'arm', material = 'steel', start = 0.0, 0.0, 0.0, end = 2.0, 0.0, 0.0,
      nodes = 5, width = 0.05, height = 0.05, height_axis = 0.0, 1.0, 0.0 /
&rigid_body name = 'box', mass = 2.0, inertia = 0.1, 0.1, 0.1, 0.0, 0.0, 0.0,
            position = 2.0, 0.0, 0.0 /
&joint name = 'root', type = 'weld', body1 = 'ground', body2 = 'arm', point = 0.0, 0.0, 0.0 /
&joint name = 'tip', type = 'spherical', body1 = 'arm', body2 = 'box', point = 2.0, 0.0, 0.0 /
&load name = 'push', type = 'force', body = 'arm', point = 2.0, 0.0, 0.0,
      vector = 0.0, 1.0, 0.0, drive = 'wave' /
&probe name = 'tip', body = 'arm', point = 2.0, 0.0, 0.0 /
&solver integrator = 'generalized_alpha', rho_inf = 0.8, dt = 1e-3, t_end = 0.005 /
"""

TABLE = """&scene title = 'table', analysis = 'dynamic', formulation = 'nonlinear' /
&material name = 'steel', youngs_modulus = 2.1e11, density = 7850.0 /
&drive name = 'lift', type = 'table', file = 'lift.csv' /
&beam name = 'arm', material = 'steel', start = 0.0, 0.0, 0.0, end = 1.0, 0.0, 0.0,
      nodes = 3, width = 0.05, height = 0.05 /
&joint name = 'root', type = 'weld', body1 = 'ground', body2 = 'arm', point = 0.0, 0.0, 0.0 /
&load name = 'push', type = 'force', body = 'arm', point = 1.0, 0.0, 0.0,
      vector = 0.0, 0.0, 1.0, drive = 'lift' /
&probe name = 'tip', body = 'arm', point = 1.0, 0.0, 0.0 /
&solver integrator = 'generalized_alpha', dt = 1e-3, t_end = 0.003 /
"""
CSV = "t, value\n0.0, 0.0\n0.002, 5.0\n1.0, 5.0\n"

GENERAL_SPRING = (INPUTS / "general" / "leaf_spring.nml").read_text().replace(
    "t_end = 5.0", "t_end = 0.002").replace("file = 'results/general_leaf_spring.h5', ", "")
BASES = {"BOOM": BOOM, "LUFFING": LUFFING, "PLATE": PLATE, "LEAF": LEAF, "SPRING": SPRING,
         "GENERAL": GENERAL, "TABLE": TABLE, "GENERAL_SPRING": GENERAL_SPRING}


def edit(base: str, *changes: tuple[str, str]) -> str:
    """The base scene with each (old, new) replaced; old must occur exactly once."""
    text = BASES[base]
    for old, new in changes:
        assert text.count(old) == 1, (base, old)
        text = text.replace(old, new)
    return text


@dataclass
class Case:
    """A bad input: the scene text (None: no scene file), the command after ``ancf``
    (``{scene}``, ``{dir}`` are replaced by the paths), extra files, and the fragments the
    one-line message must contain (with the same replacements)."""

    id: str
    scene: str | None
    argv: list[str]
    expect: tuple[str, ...]
    files: dict[str, str | bytes] = field(default_factory=dict)
    #: found while the model is assembled (the others are refused before it is built)
    assembles: bool = False


def run(id: str, scene: str, *expect: str, args: tuple[str, ...] = (),
        files: dict | None = None, where: str = "{scene}") -> Case:
    """``ancf run SCENE ARGS``; the message names ``where`` (default the scene file)."""
    return Case(id, scene, ["run", "{scene}", *args], (where,) + expect, files or {})


def sets(id: str, base: str, items: list[str], *expect: str, files: dict | None = None) -> Case:
    args = [a for item in items for a in ("--set", item)]
    return run(id, BASES[base], *expect, args=tuple(args), files=files)


HUGE = "the model is too large for this machine"

CASES: list[Case] = [
    # -- namelist structure ----------------------------------------------------------------
    run("unknown-group", BOOM + "&wind speed = 3.0 /\n", "&wind", "unknown group"),
    run("unknown-key", edit("BOOM", ("angle_deg = 15", "angle_deg = 15, angel = 3")),
        "&boom angel", "unknown key"),
    run("key-twice-same-line", edit("BOOM", ("nodes = 10,", "nodes = 10, nodes = 4,")),
        "&beam nodes", "given twice", "lines 3 and 3"),
    run("key-twice-other-line", edit("BOOM", ("&boom angle_deg = 15 /",
                                              "&boom angle_deg = 15,\n angle_deg = 30 /")),
        "&boom angle_deg", "given twice", "lines 5 and 6"),
    run("key-twice-other-case", edit("BOOM", ("nodes = 10,", "Nodes = 10, NODES = 4,")),
        "&beam nodes", "given twice"),
    run("effects-twice", edit("BOOM", ("effects = 'gravity', 'tip_mass', 'bending_moment'",
                                       "effects = 'gravity', effects = 'tip_mass'")),
        "&scene effects", "given twice"),
    run("indexed-and-whole", edit("BOOM", ("segments = 1.791, 3.0, 3.0",
                                           "segments = 1.791, 3.0, 3.0, segments(2) = 2.0")),
        "&beam segments", "given twice"),
    run("group-twice", BOOM + "&boom angle_deg = 30 /\n", "&boom", "group given twice",
        "lines 5 and 8"),
    run("scene-group-twice", BOOM + "&scene effects = 'gravity' /\n", "&scene",
        "group given twice"),
    run("solver-group-twice-general", GENERAL + "&solver dt = 2e-3 /\n", "&solver",
        "group given twice"),
    run("missing-slash", edit("BOOM", ("&boom angle_deg = 15 /", "&boom angle_deg = 15")),
        "line 6: group &loads starts before group &boom (line 5) ended (missing '/')"),
    run("missing-slash-general", edit("GENERAL", ("frequency = 2.0 /", "frequency = 2.0")),
        "line 4: group &beam starts before group &drive (line 3) ended (missing '/')"),
    run("missing-last-slash", BOOM.rstrip().removesuffix("/"),
        "line 7: group &solver has no '/' before the end of the file"),
    run("not-a-namelist", "this is not a namelist\n&beam nodes == 4 /\n",
        "&beam nodes", "got no value"),
    run("unterminated-string", edit("BOOM", ("title = 'boom'", "title = 'boom")),
        "&scene title", "expected a string"),
    run("binary-file", None, "not a text file", files={"scene.nml": b"\x89HDF\r\n\x1a\n\xff\xfe"}),
    run("empty-file", "", "a scene needs exactly one of the groups"),
    Case("missing-file", None, ["run", "{dir}/nope.nml"], ("{dir}/nope.nml", "not found")),
    Case("scene-is-directory", None, ["run", "{dir}"], ("{dir}", "not a regular file")),
    run("no-model-group", edit("BOOM", ("&boom angle_deg = 15 /\n", "")),
        "needs exactly one of the groups"),
    run("two-model-groups", BOOM + "&cantilever clamp = 'full' /\n",
        "needs exactly one of the groups", "&boom, &cantilever"),
    run("missing-required-key", edit("BOOM", ("density = 7850.0", "")),
        "&material density", "required key is missing"),
    run("missing-required-group", edit("BOOM", (
        "&material youngs_modulus = 2.1e11, density = 7850.0 /\n", "")),
        "&material", "required group is missing"),
    run("beam-in-plate-scene", PLATE + "&beam length = 1.0, width = 0.1, height = 0.1, "
        "nodes = 4 /\n", "&beam", "does not apply"),
    # -- types and sizes -------------------------------------------------------------------
    run("int-is-string", edit("BOOM", ("nodes = 10", "nodes = 'ten'")), "&beam nodes",
        "expected an integer"),
    run("int-is-fraction", edit("BOOM", ("nodes = 10", "nodes = 10.5")), "&beam nodes",
        "expected an integer"),
    run("float-is-string", edit("BOOM", ("youngs_modulus = 2.1e11", "youngs_modulus = 'steel'")),
        "&material youngs_modulus", "expected a number"),
    run("float-is-logical", edit("BOOM", ("density = 7850.0", "density = .true.")),
        "&material density", "expected a number"),
    run("float-overflows", edit("BOOM", ("youngs_modulus = 2.1e11", "youngs_modulus = 1e400")),
        "&material youngs_modulus", "finite"),
    run("string-is-number", edit("BOOM", ("static_method = 'split'", "static_method = 3")),
        "&solver static_method", "expected a string"),
    run("vector-wrong-size", edit("BOOM", ("moment = 1000.0", "moment = 1000.0, tip_force = 1, 2")),
        "&loads tip_force", "expected 3 values"),
    run("scalar-given-list", edit("BOOM", ("angle_deg = 15", "angle_deg = 15, 30")),
        "&boom angle_deg", "expected a number"),
    run("bool-is-number", edit("LUFFING", ("chunk_steps = 100", "chunk_steps = 100, q = 2")),
        "&output q", ".true. or .false."),
    run("int-beyond-32-bit", edit("LUFFING", ("max_newton = 10", "max_newton = 99999999999")),
        "&solver max_newton", "32-bit"),
    run("nodes-beyond-32-bit", edit("BOOM", ("nodes = 10", "nodes = 3000000001")),
        "&beam nodes", "32-bit"),
    run("chunk-steps-beyond-32-bit", edit("LUFFING", ("chunk_steps = 100",
                                                       "chunk_steps = 2147483648")),
        "&output chunk_steps", "32-bit"),
    # -- non-physical values -----------------------------------------------------------------
    run("negative-youngs", edit("BOOM", ("youngs_modulus = 2.1e11", "youngs_modulus = -2.1e11")),
        "&material youngs_modulus", "positive"),
    run("zero-density", edit("BOOM", ("density = 7850.0", "density = 0.0")),
        "&material density", "positive"),
    run("zero-width", edit("BOOM", ("width = 0.1", "width = 0.0")), "&beam width", "positive"),
    run("poisson-half", edit("BOOM", ("density = 7850.0", "density = 7850.0, poisson_ratio = 0.5")),
        "&material poisson_ratio", "must lie in"),
    run("negative-tip-mass", edit("BOOM", ("tip_mass = 50.0", "tip_mass = -50.0")),
        "&loads tip_mass", "must not be negative"),
    run("nodes-one", edit("BOOM", ("nodes = 10", "nodes = 1")), "&beam nodes", "at least 2"),
    run("nodes-not-3k+1", edit("BOOM", ("nodes = 10", "nodes = 12")), "&beam nodes", "3j+1"),
    run("segments-wrong-sum", edit("BOOM", ("segments = 1.791, 3.0, 3.0",
                                            "segments = 1.791, 3.0, 2.0")),
        "&beam segments", "add up to"),
    run("segment-negative", edit("BOOM", ("segments = 1.791, 3.0, 3.0",
                                          "segments = 7.791, 3.0, -3.0")),
        "&beam segments", "positive"),
    run("unknown-effect", edit("BOOM", ("'bending_moment'", "'wind'")), "&scene effects",
        "unknown effect 'wind'"),
    run("negative-damping-time", edit("BOOM", ("density = 7850.0 /",
                                               "density = 7850.0, damping_time = -1e-3 /")),
        "&material damping_time", "negative"),
    run("split-with-nonlinear", edit("BOOM", ("formulation = 'ffr'", "formulation = 'nonlinear'")),
        "&solver static_method", "needs"),
    run("unknown-integrator", edit("LUFFING", ("max_newton = 10",
                                               "max_newton = 10, integrator = 'rk4'")),
        "&solver integrator", "must be one of"),
    run("luffing-backwards", edit("LUFFING", ("angle_end_deg = 60.0", "angle_end_deg = -10.0")),
        "&boom angle_end_deg", "angle_end_deg > angle_deg"),
    run("luffing-too-fast", edit("LUFFING", ("omega = 0.2", "omega = 20.0")), "&boom omega",
        "sweeps"),
    run("plate-nx-zero", edit("PLATE", ("nx = 2", "nx = 0")), "&plate nx", "positive"),
    run("plate-ffr", edit("PLATE", ("formulation = 'nonlinear'", "formulation = 'ffr'")),
        "&scene formulation", "needs formulation = 'nonlinear'"),
    run("plate-static-free", edit("PLATE", ("analysis = 'dynamic'", "analysis = 'static'"),
                                  ("&solver ", "&solver static_method = 'newton', ")),
        "&plate support", "no static equilibrium"),
    run("plate-contact-effect", edit("PLATE", ("effects = 'gravity'",
                                               "effects = 'gravity', 'contact'")),
        "&scene effects", "applies to &spring scenes"),
    run("leaf-nx-odd", edit("LEAF", ("nx = 8", "nx = 7")), "&leaf nx", "even"),
    run("leaf-longer-than-circle", edit("LEAF", ("arc_length = 0.8", "arc_length = 13.0")),
        "&leaf arc_length", "shorter than the circle"),
    run("spring-static", edit("SPRING", ("analysis = 'dynamic'", "analysis = 'static'"),
                              ("rho_inf = 0.8", "rho_inf = 0.8, static_method = 'newton'")),
        "&scene analysis", "dynamics only"),
    run("spring-lower-longer", edit("SPRING", ("lower_arc_length = 0.8", "lower_arc_length = 1.3")),
        "&spring lower_arc_length", "shorter than the main leaf"),
    run("spring-prestress-without-effect", edit("SPRING", (
        "effects = 'gravity', 'contact', 'friction', 'prestress'",
        "effects = 'gravity', 'contact', 'friction'")), "&leaf prestress", "needs the effect"),
    # -- huge models (refused from the estimate, nothing allocated) ----------------------------
    run("huge-beam", edit("BOOM", ("nodes = 10", "nodes = 10000000")), "&beam nodes", HUGE,
        "limit"),
    run("huge-plate", edit("PLATE", ("nx = 2, ny = 2", "nx = 3000, ny = 3000")), "&plate nx",
        HUGE),
    run("plate-beyond-32-bit-numbering", edit("PLATE", ("nx = 2, ny = 2",
                                                        "nx = 100000, ny = 100000")),
        "&plate nx", "32-bit numbering"),
    run("huge-leaf", edit("LEAF", ("nx = 8", "nx = 2000, ny = 2000")), "&leaf nx", HUGE),
    run("huge-spring", edit("SPRING", ("main_nx = 12", "main_nx = 4000000")),
        "&spring main_nx", HUGE),
    run("huge-general-beam", edit("GENERAL", ("nodes = 5", "nodes = 10000001")),
        "&beam[arm] nodes", HUGE),
    run("huge-general-plate", edit("GENERAL_SPRING", ("nx = 12, ny = 1", "nx = 3000, ny = 3000")),
        "&leaf[main] nx", HUGE),
    run("huge-contact-points", edit("GENERAL_SPRING", ("points = 3", "points = 1000000000")),
        "&leaf[main] nx", HUGE),
    run("run-of-years", edit("LUFFING", ("dt = 1e-3, t_end = 0.01", "dt = 1e-8, t_end = 10.0")),
        "&solver dt", "at most"),
    run("run-of-months", edit("PLATE", ("nx = 2, ny = 2", "nx = 50, ny = 50"),
                              ("dt = 1e-3, t_end = 0.005", "dt = 1e-5, t_end = 500.0")),
        "&solver dt", "days"),
    # -- time settings -------------------------------------------------------------------------
    run("t-end-zero", edit("LUFFING", ("t_end = 0.01", "t_end = 0.0")), "&solver t_end",
        "needs t_end > 0"),
    run("t-end-negative", edit("LUFFING", ("t_end = 0.01", "t_end = -1.0")), "&solver t_end",
        "must not be negative"),
    run("dt-zero", edit("LUFFING", ("dt = 1e-3", "dt = 0.0")), "&solver dt", "positive"),
    run("dt-negative", edit("PLATE", ("dt = 1e-3", "dt = -1e-3")), "&solver dt", "positive"),
    run("dt-tiny", edit("LUFFING", ("dt = 1e-3, t_end = 0.01", "dt = 1e-300, t_end = 1e-299")),
        "&solver dt", "below the smallest step"),
    run("dt-tiny-many-steps", edit("LUFFING", ("dt = 1e-3", "dt = 1e-300")), "&solver dt"),
    run("dt-longer-than-t-end", edit("LUFFING", ("dt = 1e-3", "dt = 0.5")), "&solver dt",
        "longer than t_end"),
    run("dt-min-longer-than-dt", edit("LUFFING", ("dt = 1e-3", "dt = 1e-3, dt_min = 2e-3")),
        "&solver dt_min", "is longer than dt =", "cannot exceed the step"),
    run("t-end-not-whole-steps", edit("LUFFING", ("dt = 1e-3", "dt = 3e-3")), "&solver t_end",
        "not a whole number of steps", "use t_end = 0.009 or 0.012 s"),
    run("t-end-not-whole-steps-general", edit("GENERAL", ("t_end = 0.005", "t_end = 0.0055")),
        "&solver t_end", "not a whole number of steps"),
    # -- command lines: --set --------------------------------------------------------------------
    sets("set-smuggles-group", "BOOM", ["beam.length=7.791 / &beam nodes=7"], "&beam length",
         "is not a number"),
    sets("set-smuggles-key", "BOOM", ["beam.nodes=4, width=0.2"], "&beam nodes",
         "is not an integer"),
    sets("set-smuggles-string", "BOOM", ["scene.title='a' / &beam nodes=7 /"], "&scene title",
         "nothing after its closing quote"),
    sets("set-unquoted-string-with-ampersand", "BOOM", ["solver.static_method=newton &beam"],
         "&solver static_method", "quote it"),
    sets("set-string-list-smuggles", "BOOM", ["scene.effects=gravity, tip_mass / &x y=1"],
         "&scene effects", "quote it"),
    sets("set-two-values", "BOOM", ["beam.nodes=4,7"], "&beam nodes", "is not an integer"),
    sets("set-empty-value", "BOOM", ["beam.nodes="], "&beam nodes", "is not an integer"),
    sets("set-word-for-int", "BOOM", ["beam.nodes=four"], "&beam nodes", "is not an integer"),
    sets("set-fraction-for-int", "BOOM", ["beam.nodes=4.5"], "&beam nodes", "is not an integer"),
    sets("set-nan", "BOOM", ["beam.length=nan"], "&beam length", "is not a number"),
    sets("set-inf", "BOOM", ["beam.length=1e999"], "&beam length", "not finite"),
    sets("set-bool-word", "LUFFING", ["output.q=maybe"], "&output q", ".true. or .false."),
    sets("set-vector-wrong-size", "BOOM", ["loads.tip_force=1,2"], "&loads tip_force",
         "expected 3 values"),
    sets("set-vector-with-slash", "BOOM", ["loads.tip_force=1,2,3 / &x"], "&loads tip_force",
         "numbers separated by commas"),
    sets("set-newline", "BOOM", ["scene.title=a\n&beam nodes=7"], "&scene title",
         "control characters"),
    sets("set-no-group", "BOOM", ["nodes=4"], "is not GROUP.KEY"),
    sets("set-no-equals", "BOOM", ["beam.nodes"], "not of the form GROUP.KEY=VALUE"),
    sets("set-unknown-group", "BOOM", ["wind.speed=3"], "&wind", "unknown group"),
    sets("set-unknown-key", "BOOM", ["beam.nodez=10"], "&beam nodez", "unknown key"),
    sets("set-twice", "BOOM", ["beam.nodes=4", "beam.nodes=7"], "&beam nodes",
         "given twice on the command line"),
    sets("set-name-on-template", "BOOM", ["beam[x].nodes=4"], "&beam[x] nodes",
         "only the repeated groups of general scenes"),
    sets("set-int-beyond-32-bit", "LUFFING", ["solver.max_newton=99999999999"],
         "&solver max_newton", "32-bit"),
    sets("set-huge-nodes", "LUFFING", ["beam.nodes=10000000"], "&beam nodes", HUGE),
    sets("set-huge-plate", "PLATE", ["plate.nx=100000", "plate.ny=100000"], "&plate nx",
         "32-bit numbering"),
    sets("set-dt-tiny", "LUFFING", ["solver.dt=1e-300"], "&solver dt"),
    sets("set-t-end-zero", "LUFFING", ["solver.t_end=0"], "&solver t_end", "t_end > 0"),
    sets("set-t-end-not-whole", "PLATE", ["solver.t_end=0.0055"], "&solver t_end",
         "not a whole number of steps"),
    # -- general scenes --------------------------------------------------------------------------
    run("general-unknown-group", GENERAL + "&wind speed = 3.0 /\n", "&wind", "unknown group"),
    run("general-unknown-key", edit("GENERAL", ("nodes = 5", "nodes = 5, colour = 'red'")),
        "&beam[arm] colour", "unknown key"),
    run("general-key-twice", edit("GENERAL", ("nodes = 5", "nodes = 5, nodes = 9")),
        "&beam[arm] nodes", "given twice", "lines 5 and 5"),
    run("general-name-twice",
        GENERAL + "&probe name = 'tip', body = 'arm', point = 1.0, 0.0, 0.0 /\n",
        "&probe[tip] name", "used twice"),
    run("general-name-missing", edit("GENERAL", ("&probe name = 'tip', ", "&probe ")),
        "&probe name", "required key is missing"),
    run("general-no-body", "&scene title = 'x', analysis = 'static' /\n"
        "&material name = 'steel', youngs_modulus = 2.1e11, density = 7850.0 /\n",
        "needs at least one body"),
    run("general-body-named-ground", edit("GENERAL", ("&rigid_body name = 'box'",
                                                      "&rigid_body name = 'ground'")),
        "&rigid_body[ground]", "reserved"),
    run("general-unknown-material", edit("GENERAL", ("material = 'steel', start",
                                                     "material = 'stel', start")),
        "&beam[arm]", "unknown material 'stel'"),
    run("general-unknown-body", edit("GENERAL", ("body2 = 'box'", "body2 = 'bx'")),
        "&joint[tip]", "unknown body 'bx'"),
    run("general-unknown-drive", edit("GENERAL", ("drive = 'wave'", "drive = 'wav'")),
        "&load[push]", "unknown drive 'wav'"),
    run("general-unknown-joint-type", edit("GENERAL", ("type = 'spherical'", "type = 'ball'")),
        "&joint[tip] type", "must be one of"),
    run("general-joint-edge-of-a-beam", edit("GENERAL", (
        "type = 'weld', body1 = 'ground', body2 = 'arm', point = 0.0, 0.0, 0.0",
        "type = 'weld', body1 = 'ground', body2 = 'arm', edge = 'x0'")),
        "&joint[root]", "edge selects a side of a plate or leaf"),
    run("general-joint-off-the-body", edit("GENERAL", (
        "body2 = 'box', point = 2.0, 0.0, 0.0", "body2 = 'box', point = 5.0, 0.0, 0.0")),
        "&joint[tip]", "is not a material point of beam 'arm'"),
    run("general-joint-point-wrong-size", edit("GENERAL", (
        "body2 = 'box', point = 2.0, 0.0, 0.0", "body2 = 'box', point = 2.0, 0.0")),
        "&joint[tip] point", "multiple of 3"),
    run("general-joint-same-body", edit("GENERAL", ("body1 = 'arm', body2 = 'box'",
                                                    "body1 = 'box', body2 = 'box'")),
        "&joint[tip]", "the same body"),
    run("general-revolute-without-axis", edit("GENERAL", ("type = 'spherical'",
                                                          "type = 'revolute'")),
        "&joint[tip]", "needs an axis"),
    run("general-probe-off-the-body", edit("GENERAL", (
        "&probe name = 'tip', body = 'arm', point = 2.0, 0.0, 0.0",
        "&probe name = 'tip', body = 'arm', point = 2.0, 1.0, 0.0")),
        "&probe[tip]", "not a material point"),
    run("general-drive-missing-parameter", edit("GENERAL", (", frequency = 2.0", "")),
        "&drive[wave]", "needs frequency"),
    run("general-drive-extra-parameter", edit("GENERAL", ("frequency = 2.0",
                                                          "frequency = 2.0, omega = 3.0")),
        "&drive[wave]", "does not take omega"),
    run("general-drive-unknown-type", edit("GENERAL", ("type = 'sine'", "type = 'saw'")),
        "&drive[wave] type", "must be one of"),
    run("general-section-missing-wall", edit("GENERAL", ("width = 0.05, height = 0.05,",
                                                         "section = 'box', width = 0.05, "
                                                         "height = 0.05,")),
        "&beam[arm]", "needs wall"),
    run("general-beam-zero-length", edit("GENERAL", ("end = 2.0, 0.0, 0.0",
                                                     "end = 0.0, 0.0, 0.0")),
        "&beam[arm]", "start and end coincide"),
    run("general-height-along-axis", edit("GENERAL", ("height_axis = 0.0, 1.0, 0.0",
                                                      "height_axis = 1.0, 0.0, 0.0")),
        "&beam[arm]", "parallel to the beam axis"),
    run("general-inertia-wrong-size", edit("GENERAL", ("inertia = 0.1, 0.1, 0.1, 0.0, 0.0, 0.0",
                                                       "inertia = 0.1, 0.1, 0.1")),
        "&rigid_body[box] inertia", "expected 6 values"),
    run("general-load-on-ground", edit("GENERAL", ("body = 'arm', point = 2.0, 0.0, 0.0,\n",
                                                   "body = 'ground', point = 2.0, 0.0, 0.0,\n")),
        "&load[push]", "does nothing"),
    run("general-contact-on-beam", GENERAL + "&contact name = 'c', body1 = 'arm', "
        "body2 = 'box', stiffness = 1e6 /\n", "&contact[c]", "not a plate or leaf"),
    run("general-unknown-response", edit("GENERAL", ("formulation = 'nonlinear' /",
                                                     "formulation = 'nonlinear', "
                                                     "response = 'end' /")),
        "&scene response", "is not a probe"),
    run("general-set-unknown-name", GENERAL, "&beam[beam] nodes", "no &beam named 'beam'",
        args=("--set", "beam[beam].nodes=9")),
    run("general-set-ambiguous", GENERAL_SPRING, "&leaf nx", "occurs 2 times",
        args=("--set", "leaf.nx=4")),
    run("general-set-huge", GENERAL, "&beam[arm] nodes", HUGE,
        args=("--set", "beam[arm].nodes=10000000")),
    Case("general-distance-points-coincide", edit("GENERAL", (
        "type = 'spherical', body1 = 'arm', body2 = 'box', point = 2.0, 0.0, 0.0",
        "type = 'distance', body1 = 'arm', body2 = 'box', point1 = 2.0, 0.0, 0.0, "
        "point2 = 2.0, 0.0, 0.0")), ["run", "{scene}"],
        ("{scene}", "&joint[tip]", "point1 and point2 coincide"), assembles=True),
    Case("general-drive-contradicts-joint", GENERAL + (
        "&drive name = 'length', type = 'constant', value = 5.0 /\n"
        "&joint name = 'cylinder', type = 'distance', body1 = 'ground', body2 = 'box', "
        "point1 = 2.0, 1.0, 0.0, point2 = 2.0, 0.0, 0.0, drive = 'length' /\n"),
        ["run", "{scene}"], ("{scene}", "&joint[cylinder]", "gives the length 5 m at t = 0"),
        assembles=True),
    run("general-name-with-slash", edit("GENERAL", ("&probe name = 'tip'",
                                                    "&probe name = 'tip/x'")),
        "&probe[tip/x] name", "must not contain '/'"),
    run("general-name-with-bracket", edit("GENERAL", ("name = 'box'", "name = 'b]x'")),
        "&rigid_body[b]x] name", "must not contain"),
    run("general-name-dot", edit("GENERAL", ("&probe name = 'tip'", "&probe name = '.'")),
        "&probe[.] name", "nor be '.'"),
    run("general-inertia-zero", edit("GENERAL", ("inertia = 0.1, 0.1, 0.1, 0.0, 0.0, 0.0",
                                                 "inertia = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0")),
        "&rigid_body[box] inertia", "positive Ixx"),
    run("huge-youngs-modulus", edit("BOOM", ("youngs_modulus = 2.1e11", "youngs_modulus = 1e300")),
        "&material youngs_modulus", "largest magnitude"),
    run("huge-position", edit("GENERAL", ("end = 2.0, 0.0, 0.0", "end = 1e300, 0.0, 0.0")),
        "&beam[arm] end", "largest magnitude"),
    sets("set-huge-force", "BOOM", ["loads.moment=1e300"], "&loads moment", "largest magnitude"),
    run("general-leaf-prestress-plain", edit("GENERAL_SPRING", (
        "nx = 8, ny = 1           !", "nx = 8, ny = 1, variant = 'plain'           !")),
        "&leaf[lower]", "completed"),
    # -- table drives ----------------------------------------------------------------------------
    run("table-csv-missing", TABLE, "&drive[lift]", "not found"),
    run("table-csv-text", TABLE, "&drive[lift]", "line 3", "expected numbers",
        files={"lift.csv": "t, value\n0.0, 0.0\nhello, world\n"}),
    run("table-csv-binary", TABLE, "&drive[lift]", "not a text file",
        files={"lift.csv": b"\x00\xff\xfe\x00"}),
    run("table-csv-times-decrease", TABLE, "&drive[lift]", "increase strictly",
        files={"lift.csv": "0.0, 0.0\n1.0, 1.0\n0.5, 2.0\n"}),
    run("table-csv-empty", TABLE, "&drive[lift]", "at least one",
        files={"lift.csv": "t, value\n"}),
    run("table-csv-nan", TABLE, "&drive[lift]", "finite",
        files={"lift.csv": "0.0, 0.0\n1.0, nan\n"}),
    run("table-file-and-times", edit("TABLE", ("file = 'lift.csv'",
                                               "file = 'lift.csv', times = 0.0, 1.0, "
                                               "values = 0.0, 1.0")),
        "&drive[lift]", "either file or times", files={"lift.csv": CSV}),
    run("table-csv-is-directory", edit("TABLE", ("file = 'lift.csv'", "file = '.'")),
        "&drive[lift]", "not found"),
    # -- output paths ----------------------------------------------------------------------------
    run("output-is-scene", BOOM, "the output is the input file", args=("-o", "{scene}")),
    run("output-is-csv", TABLE, "the output is the input file",
        args=("-o", "{dir}/lift.csv"), files={"lift.csv": CSV}, where="{dir}/lift.csv"),
    run("output-is-directory", BOOM, "the output is a directory", args=("-o", "{dir}"),
        where="{dir}"),
    run("output-below-a-file", BOOM, "notes.txt is not a directory",
        args=("-o", "{dir}/notes.txt/out.h5"), files={"notes.txt": "keep me\n"},
        where="{dir}/notes.txt/out.h5"),
    run("output-not-hdf5", BOOM, "not an HDF5 file", args=("-o", "{dir}/notes.h5"),
        files={"notes.h5": "keep me\n"}, where="{dir}/notes.h5"),
    run("output-colon-with-xdmf", LUFFING, "must not contain ':'", "output.xdmf = .false.",
        args=("-o", "{dir}/a:b.h5"), where="{dir}/a:b.h5"),
    run("output-ends-in-png", BOOM, "must not end in .png", args=("-o", "{dir}/out.png"),
        where="{dir}/out.png"),
    run("output-file-in-scene-is-scene", edit("BOOM", ("&solver", "&output file = 'scene.nml' /\n"
                                                                  "&solver")),
        "the output is the input file", files={}),
    # -- other commands ---------------------------------------------------------------------------
    Case("info-missing", None, ["info", "{dir}/nope.h5"], ("{dir}/nope.h5", "not found")),
    Case("info-not-hdf5", None, ["info", "{dir}/notes.txt"], ("{dir}/notes.txt", "not an HDF5"),
         files={"notes.txt": "keep me\n"}),
    Case("plot-missing", None, ["plot", "{dir}/nope.h5"], ("{dir}/nope.h5", "not found")),
    Case("sweep-smuggled-value", BOOM, ["sweep", "{scene}", "--vary",
                                        "beam.nodes=4,7 / &beam width=1", "-o", "{dir}/sw"],
         ("{scene}", "&beam nodes", "is not an integer")),
    Case("sweep-set-and-vary-same-key", BOOM, ["sweep", "{scene}", "--vary", "beam.nodes=4,7",
                                               "--set", "beam.nodes=10", "-o", "{dir}/sw"],
         ("{scene}", "&beam nodes", "given twice on the command line")),
    Case("sweep-huge", BOOM, ["sweep", "{scene}", "--vary", "beam.nodes=4,10000000",
                              "-o", "{dir}/sw"], ("{scene}", "&beam nodes", HUGE)),
]

#: cases that also run as a separate process (the console entry point, real exit status)
SUBPROCESS = ("huge-beam", "set-smuggles-group", "t-end-not-whole-steps", "group-twice",
              "general-joint-edge-of-a-beam", "table-csv-binary", "output-is-scene",
              "general-drive-contradicts-joint")


def _prepare(case: Case, directory: Path) -> tuple[list[str], tuple[str, ...]]:
    for name, content in case.files.items():
        path = directory / name
        (path.write_bytes if isinstance(content, bytes) else path.write_text)(content)
    scene = directory / "scene.nml"
    if case.scene is not None:
        scene.write_text(case.scene)

    def fill(text: str) -> str:
        return text.replace("{scene}", str(scene)).replace("{dir}", str(directory))
    return [fill(a) for a in case.argv], tuple(fill(e) for e in case.expect)


def _snapshot(directory: Path) -> dict[str, str]:
    """Every file and directory below (relative path -> content hash or 'dir')."""
    out = {}
    for path in sorted(directory.rglob("*")):
        key = str(path.relative_to(directory))
        out[key] = "dir" if path.is_dir() else hashlib.sha256(path.read_bytes()).hexdigest()
    return out


def _check_message(err: str, expect: tuple[str, ...]) -> None:
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert "Traceback" not in err and "internal error" not in err, err
    for fragment in expect:
        assert fragment in err, (fragment, err)


def test_corpus_is_large_and_names_are_unique():
    assert len(CASES) >= 100
    assert len({c.id for c in CASES}) == len(CASES)
    assert set(SUBPROCESS) <= {c.id for c in CASES}


@pytest.mark.parametrize("name", sorted(BASES))
def test_base_scenes_are_valid(name, tmp_path):
    """The corpus breaks valid scenes: each base scene itself loads (and builds)."""
    from ancfdrv.builders import build_model
    from ancfdrv.io.scene import load_scene
    (tmp_path / "lift.csv").write_text(CSV)
    path = tmp_path / "scene.nml"
    path.write_text(BASES[name])
    build_model(load_scene(path)).close()


#: a model that is refused before it is built allocates nothing large (bytes, as traced
#: by tracemalloc, which also sees numpy's buffers)
PEAK_LIMIT = 64 * 2**20


@pytest.mark.parametrize("case", CASES, ids=[c.id for c in CASES])
def test_bad_input_exits_2_naming_where(case, tmp_path, monkeypatch, capsys):
    from ancfdrv.cli import main
    import ancfdrv.runner  # noqa: F401 - imported before memory is traced
    import ancfdrv.plots  # noqa: F401
    import ancfdrv.sweep  # noqa: F401
    monkeypatch.chdir(tmp_path)  # a default output (results/...) would appear here

    def built(scene):  # the other cases must be refused before the model is built
        raise AssertionError(f"case {case.id!r} got past validation: the model was built")
    if not case.assembles:
        monkeypatch.setattr(ancfdrv.runner, "build_model", built)
    argv, expect = _prepare(case, tmp_path)
    before = _snapshot(tmp_path)
    tracemalloc.start()
    try:
        code = main(argv)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    err = capsys.readouterr().err
    assert code == 2, err
    _check_message(err, expect)
    assert peak < PEAK_LIMIT, f"{peak / 2**20:.0f} MiB traced"
    assert _snapshot(tmp_path) == before  # nothing created, changed or removed


@pytest.mark.parametrize("name", SUBPROCESS)
def test_bad_input_in_a_process(name, tmp_path):
    case = next(c for c in CASES if c.id == name)
    argv, expect = _prepare(case, tmp_path)
    before = _snapshot(tmp_path)
    done = subprocess.run([sys.executable, "-m", "ancfdrv.cli", *argv], cwd=tmp_path,
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 2, done.stderr
    _check_message(done.stderr, expect)
    assert done.stdout == ""
    assert _snapshot(tmp_path) == before


# -- measuring the corpus: python tests/test_bad_input.py [PYTHONPATH of the code to test] ----

_PROBE = """
import resource, sys
resource.setrlimit(resource.RLIMIT_AS, (6 * 2**30, 6 * 2**30))
from ancfdrv.cli import main
sys.exit(main(sys.argv[1:]))
"""


def measure(timeout: float = 300.0) -> dict[str, list[str]]:
    """Run every case in its own process (address space limited to 6 GiB, so a huge
    allocation fails quickly) and sort the outcomes."""
    import tempfile
    import time
    outcome: dict[str, list[str]] = {"clean exit 2": [], "traceback": [],
                                     "silently accepted": [], "other": []}
    for case in CASES:
        with tempfile.TemporaryDirectory() as tmp:
            directory = Path(tmp)
            argv, expect = _prepare(case, directory)
            start = time.perf_counter()
            try:
                done = subprocess.run([sys.executable, "-c", _PROBE, *argv], cwd=directory,
                                      capture_output=True, text=True, timeout=timeout)
                code, err = done.returncode, done.stderr
            except subprocess.TimeoutExpired:
                code, err = None, "timeout"
            seconds = time.perf_counter() - start
        if code == 2 and "Traceback" not in err and "internal error" not in err:
            kind = "clean exit 2"
        elif code == 0:
            kind = "silently accepted"
        elif code == 1 or "Traceback" in err or "internal error" in err:
            kind = "traceback"
        else:
            kind = "other"
        outcome[kind].append(case.id)
        last = err.strip().splitlines()[-1] if err.strip() else ""
        print(f"{case.id:40s} {str(code):5s} {seconds:6.2f} s  {kind:18s} {last[:110]}",
              flush=True)
    return outcome


if __name__ == "__main__":
    result = measure()
    print(f"\n| cases | clean exit 2 | tracebacks | silently accepted | other |")
    print("|---|---|---|---|---|")
    print(f"| {len(CASES)} | " + " | ".join(str(len(v)) for v in result.values()) + " |")
    for kind in ("traceback", "silently accepted", "other"):
        if result[kind]:
            print(f"{kind}: {', '.join(result[kind])}")
