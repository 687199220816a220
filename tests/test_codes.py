"""The integer codes and layouts of ancfdrv.codes against the Fortran sources they mirror:
every `integer, parameter` the Python side relies on is read from its module's source and
compared, so a renumbering on either side fails here instead of silently mislabelling
results."""
from __future__ import annotations

import re
from pathlib import Path

import pytest

from ancfdrv import codes

SRC = Path(__file__).resolve().parents[1] / "fortran" / "src"


def parameters(relative: str) -> dict[str, int]:
    """name -> value of every integer parameter declared in a Fortran source file
    (continuation lines joined, comments dropped)."""
    text = (SRC / relative).read_text()
    lines = [line.split("!")[0].rstrip() for line in text.splitlines()]
    joined = re.sub(r"&\s*\n\s*&?", " ", "\n".join(lines))
    values: dict[str, int] = {}
    for declaration in re.findall(r"integer\s*,\s*parameter[^:]*::(.*)", joined, re.I):
        for name, value in re.findall(r"(\w+)\s*=\s*(-?\d+)\b", declaration):
            values[name.lower()] = int(value)
    return values


def layout(params: dict[str, int], names: list[str]) -> tuple[int, ...]:
    return tuple(params[n] for n in names)


def test_constraint_kinds():
    p = parameters("system/constraints.f90")
    assert (codes.CONSTRAINT_COORDINATE, codes.CONSTRAINT_DISTANCE, codes.CONSTRAINT_CROSS,
            codes.CONSTRAINT_DOT) == layout(p, [f"constraint_kind_{k}" for k in
                                                ("coordinate", "distance", "cross", "dot")])


def test_drive_kinds():
    p = parameters("system/drives.f90")
    kinds = ("constant", "luffing", "spinup", "cycle", "sine", "table")
    assert (codes.DRIVE_CONSTANT, codes.DRIVE_LUFFING, codes.DRIVE_SPINUP, codes.DRIVE_CYCLE,
            codes.DRIVE_SINE, codes.DRIVE_TABLE) == layout(p, [f"drive_{k}" for k in kinds])


def test_section_kinds():
    p = parameters("elements/beam_section.f90")
    kinds = ("rectangle", "box", "tube", "circle")
    assert (codes.SECTION_RECTANGLE, codes.SECTION_BOX, codes.SECTION_TUBE,
            codes.SECTION_CIRCLE) == layout(p, [f"section_{k}" for k in kinds])
    assert codes.MAX_SECTION_POINTS == p["max_section_points"]


def test_policies_energy_and_power_layouts():
    p = parameters("system/mechanical_system.f90")
    assert (codes.POLICY_CONSTANT, codes.POLICY_REFACTOR) == \
        layout(parameters("system/system_iteration.f90"), ["policy_constant", "policy_refactor"])
    energy = ["energy_kinetic", "energy_strain", "energy_loads", "energy_moment", "energy_total",
              "work_drive", "work_frame", "energy_contact", "work_contact_damping",
              "work_friction", "work_material_damping"]
    assert layout(p, energy) == tuple(range(1, len(codes.ENERGY_NAMES) + 1))
    assert p["energy_count"] == len(codes.ENERGY_NAMES)
    power = ["power_drive", "power_frame", "power_contact_damping", "power_friction",
             "power_material_damping"]
    assert layout(p, power) == tuple(range(1, len(codes.POWER_NAMES) + 1))
    assert p["power_count"] == len(codes.POWER_NAMES)
    # the Python names follow the Fortran order
    assert [n.split("_", 1)[1] for n in power] == list(codes.POWER_NAMES)


def test_jacobian_policies_and_step_statistics():
    assert (codes.JACOBIAN_STEP, codes.JACOBIAN_ITERATION, codes.JACOBIAN_REUSE) == \
        layout(parameters("solvers/stepper.f90"),
               ["jacobian_step", "jacobian_iteration", "jacobian_reuse"])
    p = parameters("solvers/time_integrator.f90")
    stats = ["stat_corrections", "stat_factorizations", "stat_jacobians"]
    assert layout(p, stats) == tuple(range(1, len(codes.STAT_NAMES) + 1))
    assert p["stat_count"] == len(codes.STAT_NAMES)
    assert [n.split("_", 1)[1] for n in stats] == list(codes.STAT_NAMES)


def test_contact_layouts():
    p = parameters("system/leaf_contact.f90")
    assert p["contact_record"] == len(codes.CONTACT_RECORD)
    counters = ["cc_points", "cc_active", "cc_friction", "cc_iterations", "cc_fallbacks",
                "cc_dropped"]
    assert layout(p, counters) == tuple(range(1, len(codes.CONTACT_COUNTERS) + 1))
    assert p["contact_counters"] == len(codes.CONTACT_COUNTERS)
    params = [f"cp_{n}" for n in codes.CONTACT_PARAMS]
    assert layout(p, params) == tuple(range(1, len(codes.CONTACT_PARAMS) + 1))
    assert p["cp_count"] >= len(codes.CONTACT_PARAMS)


@pytest.mark.parametrize("code", range(1, 10))
def test_every_step_failure_code_has_its_text(code):
    """The stepper's failure codes (integrator_chunk's 1 .. 8, system_advance's 9): each is
    set by the kernel, and each of 1 .. 8 has its own text (time_integrator's
    step_failure_text, kernel_errors' failure_text) that system_advance returns with it."""
    sources = "\n".join(path.read_text() for path in SRC.rglob("*.f90"))
    assert re.search(rf"\b(info|status\(as_info\))\s*=\s*{code}\b", sources), code
    if code == 9:
        return
    texts = (SRC / "solvers" / "time_integrator.f90").read_text()
    texts = texts[texts.index("function step_failure_text"):]
    texts += (SRC / "core" / "kernel_errors.f90").read_text()
    assert re.search(rf"case \({code}\)", texts), code


@pytest.mark.parametrize("prefix", sorted(codes.KERNEL_LAYOUTS))
def test_kernel_argument_layouts(prefix):
    """Each grouped-argument layout of the f2py binding (api_support.f90 <prefix>_<name>,
    <prefix>_count) has the Python names in the same order and the same length."""
    p = parameters("api/api_support.f90")
    names = codes.KERNEL_LAYOUTS[prefix]
    assert layout(p, [f"{prefix}_{n}" for n in names]) == tuple(range(1, len(names) + 1))
    assert p[f"{prefix}_count"] == len(names)
    # no index of the prefix that Python does not name
    assert {k for k in p if k.startswith(prefix + "_")} == \
        {f"{prefix}_{n}" for n in names} | {f"{prefix}_count"}


def test_binding_declares_each_layout_with_its_length():
    """f2py cannot read a used module's parameters, so the binding declares a grouped array
    with a literal length: each dummy whose elements a routine names with a layout's indices
    (``name(<prefix>_...)``, or ``name(:, <prefix>_...)`` for a column layout) is declared
    with a length (its first dimension, or its last for the columns) that holds every index
    the routine uses and no more than the layout: the layout's length, or a leading part of
    it (reduced_ffr_energy_rows takes the frame's motion without psi'')."""
    p = parameters("api/api_support.f90")
    checked = 0
    for source in ("api/element_api.f90", "api/system_api.f90"):
        text = (SRC / source).read_text()
        for body in re.findall(r"\nsubroutine .*?\nend subroutine", text, re.S):
            joined = re.sub(r"&\s*\n\s*", " ", body)
            uses = re.findall(r"\b(\w+)\((?:[:\w ]+, )?([a-z]{2})_(\w+)\)", joined)
            for name, prefix in {(n, x) for n, x, _ in uses if f"{x}_count" in p}:
                used = max(p[f"{prefix}_{i}"] for n, x, i in uses if (n, x) == (name, prefix))
                decl = re.search(rf"::[^\n]*\b{name}\(([^)]*)\)", joined)
                assert decl, (source, name)
                dims = [d.strip() for d in decl.group(1).split(",")]
                lengths = [int(d) for d in (dims[0], dims[-1]) if d.isdigit()]
                assert any(used <= n <= p[f"{prefix}_count"] for n in lengths), \
                    (source, name, dims, prefix)
                checked += 1
    assert checked >= 20


def test_kernel_layout_prefixes_are_unique():
    """Each layout prefix of codes.KERNEL_LAYOUTS names one layout: a dict literal keeps the
    last of two equal keys silently (two branches once both chose 'sk', and the section
    layout was packed as the step control's)."""
    import ast
    source = Path(codes.__file__).read_text()
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.AnnAssign) and getattr(node.target, "id", "") == \
                "KERNEL_LAYOUTS":
            keys = [k.value for k in node.value.keys]
            assert len(keys) == len(set(keys)), sorted(k for k in keys if keys.count(k) > 1)
            break
    else:
        raise AssertionError("KERNEL_LAYOUTS not found in codes.py")
