"""The kernel's boundary stays narrow (issue 36): no f2py routine of the binding
(fortran/src/api/element_api.f90, system_api.f90) takes more than 15 arguments, the handle
check is written once (api_support.f90 api_system) and no routine is a damped twin of
another. Read from the sources, independent of the build."""
from __future__ import annotations

import re
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "fortran" / "src"
BINDING = ("api/element_api.f90", "api/system_api.f90")


def routines() -> dict[str, list[str]]:
    """name -> dummy arguments of every subroutine of the binding (continuation lines
    joined, comments dropped)."""
    found: dict[str, list[str]] = {}
    for source in BINDING:
        lines = [line.split("!")[0].rstrip() for line in (SRC / source).read_text().splitlines()]
        text = re.sub(r"&\s*\n\s*&?", " ", "\n".join(lines))
        for name, args in re.findall(r"^\s*subroutine\s+(\w+)\s*\(([^)]*)\)", text, re.M | re.I):
            found[name.lower()] = [a.strip() for a in args.split(",") if a.strip()]
    return found


def test_parser_reads_the_binding():
    """The count below is of the real routines: a known signature read back exactly."""
    found = routines()
    assert len(found) > 50
    assert found["system_destroy"] == ["handle", "info", "message"]
    assert found["drive_values"] == ["kind", "nparams", "params", "nt", "t", "phi", "dphi",
                                     "ddphi", "info"]


def test_no_routine_takes_more_than_15_arguments():
    widest = {name: len(args) for name, args in routines().items() if len(args) > 15}
    assert widest == {}
    assert max(len(args) for args in routines().values()) <= 15


def test_the_handle_check_is_written_once():
    """No system routine looks its handle up itself (store_get and handle_text appear only
    in api_support's api_system, and system_destroy names a dead handle)."""
    text = (SRC / "api" / "system_api.f90").read_text()
    assert "store_get" not in text
    assert text.count("handle_text(handle)") == 1   # system_destroy's refusal
    assert "subroutine api_system" in (SRC / "api" / "api_support.f90").read_text()


def test_no_damped_twins():
    """Damping is an argument of the undamped routines, not a routine of its own: no
    routine's name without 'damped' names another routine (cable_damped_forces beside
    cable_forces, point_energy_damped beside point_energy). The damped Gauss-point loops
    (damped_points, damped_terms) stay apart from the elastic ones on purpose (module docs:
    one loop behind a flag compiles to a slower undamped force)."""
    sources = "\n".join(path.read_text() for path in SRC.rglob("*.f90"))
    names = {n.lower() for n in re.findall(r"subroutine\s+(\w+)\s*\(", sources, re.I)}
    assert "cable_forces" in names and "point_energy" in names
    twins = {n for n in names for plain in (n.replace("_damped", ""), n.replace("damped_", ""))
             if plain != n and plain in names}
    assert twins == set()
