"""Is a computed result physically plausible? (issue 35, items 5 and the "no physical
bounds" cases.)

A run whose input has a unit slipped (Young's modulus typed in MPa, 2.1e5 instead of
2.1e11) converges as well as a correct one: the solvers cannot tell. Two checks of the
result can:

* **Warnings** (``model.warnings``: the file's root attribute ``warnings`` and the
  terminal), lifted by ``scene.bounds = 'off'``:

  - a beam whose largest strain, its largest von Mises stress over Young's modulus (the
    stresses the run stores: /static/stress, the dynamic envelope /dynamic/stress),
    exceeds :data:`ELASTIC_STRAIN`, 0.5 %, more than an elastic metal takes (structural
    steel yields at about 0.1 to 0.3 %, the strongest steels and titanium below 1 %);
  - a probe displaced by more than the structure's size (:func:`structure_size`: the
    diagonal of the bounding box of the undeformed model). Static results: every probe;
    dynamic results: the probes whose deflection is measured in a beam's moving frame
    (the elastic part of the motion: a frame with a drive, :func:`moving_frame`), as a
    pendulum or a dropped body legitimately moves farther than its size.

* **Failures** (:class:`~ancfdrv.errors.SolverError`, exit 3, status 'failed', the rows
  kept), whatever ``scene.bounds`` says: a result that is not finite, or a displacement
  above :data:`ABSURD_FACTOR` times the structure's size (a box of 2 kg on a spring of
  1e-300 N/m hung 2e301 m down): no unit slip or load makes that a result to vouch for.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Iterable

import numpy as np

from ..errors import SolverError

if TYPE_CHECKING:
    from ..system import Model

#: the largest strain an elastic metal takes (0.5 %): beyond it, a unit is off
ELASTIC_STRAIN = 0.005
#: a displacement above this multiple of the structure's size is no result (exit 3)
ABSURD_FACTOR = 1e3
#: the words every warning of this module carries ("static result implausible: ...")
IMPLAUSIBLE = "result implausible"
#: what every warning and failure suggests
UNITS = ("check the units (SI: Young's modulus in Pa, e.g. 2.1e11 for steel, not 2.1e5 in "
         "MPa; lengths in m; forces in N; stiffnesses in N/m)")
#: what every warning says last
UNITS_HINT = f"{UNITS}; scene.bounds = 'off' silences this warning"


def structure_size(model: "Model") -> float:
    """The diagonal of the bounding box of the undeformed model (m): the points the result
    files draw (plate and beam nodes, rigid bodies' frames and inertia boxes, the points of
    force elements, point masses and joints) and the probes, at least the model's length
    scale (a lone rigid body: 1 m)."""
    from .xdmf import MeshLayout
    points = [np.array(list(model.probe_positions(model.e0).values())).reshape(-1, 3)]
    layout = MeshLayout.from_model(model)
    if layout is not None:
        points.append(np.asarray(layout.points, dtype=float).reshape(-1, 3))
    cloud = np.concatenate(points)
    diagonal = float(np.linalg.norm(np.ptp(cloud, axis=0))) if len(cloud) else 0.0
    return max(diagonal, float(model.length_scale))


def _body_words(model: "Model", name: str) -> str:
    body = next((b for b in model.bodies if b.name == name), None)
    kind = "body" if body is None else type(body).__name__.lower().replace("rigidbody",
                                                                         "rigid body")
    return f"{kind} {name!r}"


def check_finite(model: "Model", values: Iterable[tuple[str, np.ndarray]], when: str) -> None:
    """SolverError naming the first quantity (name, values) that is not finite."""
    for name, value in values:
        if not np.all(np.isfinite(value)):
            raise SolverError(f"the {when} result is not finite ({name}): a stiffness, a load "
                              f"or a unit is off by orders of magnitude; {UNITS}")


def strain_warnings(model: "Model", peaks: dict[str, tuple[float, str]], when: str
                    ) -> list[str]:
    """The warnings of beams whose peak von Mises stress (Pa, with where it is, by beam
    name) over their Young's modulus exceeds :data:`ELASTIC_STRAIN`."""
    beams = {b.name: b for b in model.bodies if hasattr(b, "material")
             and hasattr(b, "section")}
    out = []
    for name, (stress, where) in peaks.items():
        beam = beams.get(name)
        if beam is None:
            continue
        modulus = float(beam.material.youngs_modulus)
        strain = stress / modulus
        if strain > ELASTIC_STRAIN:
            out.append(f"{when} {IMPLAUSIBLE}: beam {name!r} is strained by {strain:.3g} "
                       f"({strain:.2%}; von Mises stress {stress:.4g} Pa over Young's modulus "
                       f"{modulus:.4g} Pa{where}), more than an elastic metal takes "
                       f"({ELASTIC_STRAIN:.1%}): {UNITS_HINT}")
    return out


def displacement_check(model: "Model", largest: dict[str, float], when: str, *,
                       warn: bool) -> list[str]:
    """The warnings of probes (their largest displacement component, m, by probe name)
    displaced by more than the structure's size (``warn``), after the failure of one
    displaced by more than :data:`ABSURD_FACTOR` times it (SolverError)."""
    if all(value <= model.length_scale for value in largest.values()):
        return []   # (NaN compares False: checked below) within a size no structure is below
    size = structure_size(model)
    out = []
    for name, value in largest.items():
        body = _body_words(model, model.probes[name].body)
        if not np.isfinite(value) or value > ABSURD_FACTOR * size:
            raise SolverError(f"the {when} result is not physical: probe {name!r} on {body} "
                              f"is displaced by {value:.3g} m, more than {ABSURD_FACTOR:g} "
                              f"times the structure's size ({size:.3g} m): a stiffness, a load "
                              f"or a unit is off by orders of magnitude; {UNITS}")
        if warn and value > size:
            out.append(f"{when} {IMPLAUSIBLE}: probe {name!r} on {body} is displaced by "
                       f"{value:.4g} m, more than the structure's size ({size:.4g} m, the "
                       f"diagonal of the undeformed model's bounding box): {UNITS_HINT}")
    return out


def check_static(model: "Model", e: np.ndarray, stress: dict, *, warn: bool) -> list[str]:
    """The plausibility of a static state ``e`` with its stresses (``Answers.stress``, by
    beam name): SolverError for a state not finite or absurdly displaced, else the
    warnings (none unless ``warn``)."""
    check_finite(model, [("q", e)], "static")
    moved = {name: float(np.abs(value).max())   # the largest component: no overflow
             for name, value in model.deflections(e).items()}
    out = displacement_check(model, moved, "static", warn=warn)
    if warn:
        peaks = {}
        for name, s in stress.items():
            if len(s.von_mises):
                k = int(np.argmax(s.von_mises))
                peaks[name] = (float(s.von_mises[k]), "")
        out += strain_warnings(model, peaks, "static")
    return out


def moving_frame(model: "Model", frame: int) -> bool:
    """Whether a probe's deflection (frame: its 1-based frame, 0 none) is resolved in a
    frame that turns with its body (a beam frame with a drive: the FFR frame, a luffing
    boom's), so that it is the elastic part of the motion. A beam's constant frame (no
    drive: a free, hinged or clamped 'nonlinear' beam) resolves its whole motion, which a
    pendulum legitimately carries farther than its size (issue 39: the double pendulum's
    tip, 3.66 m on a 2 m model, was flagged as a unit slip)."""
    return frame != 0 and model.frames[frame - 1].drive >= 0


def check_dynamic(model: "Model", deflection: dict[str, np.ndarray],
                  envelope: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]], *,
                  warn: bool) -> list[str]:
    """The plausibility of a dynamic run from its probes' deflection series (nt, 3) by
    name and its stress envelope (``DynamicAnswers.envelope``: s, peak, time by beam):
    SolverError for a series not finite or a beam-frame deflection absurdly large, else
    the warnings (none unless ``warn``)."""
    check_finite(model, [(f"deflection of probe {name!r}", value)
                         for name, value in deflection.items()], "dynamic")
    framed = {name: float(np.abs(value).max(initial=0.0))   # the largest component
              for name, value in deflection.items()
              if moving_frame(model, model.probes[name].frame)}
    out = displacement_check(model, framed, "dynamic", warn=warn)
    if warn:
        peaks = {}
        for name, (_, best, times) in envelope.items():
            if len(best):
                k = int(np.argmax(best))
                peaks[name] = (float(best[k]), f" at t = {float(times[k]):.6g} s")
        out += strain_warnings(model, peaks, "dynamic")
    return out
