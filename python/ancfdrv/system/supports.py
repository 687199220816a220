"""Deflection relative to the rigid motion of a beam's supports (issue 22 item 3).

In a mechanism a beam's probe moves mostly with the mechanism; what an engineer calls its
deflection is what is left after that rigid motion. Each beam with joints gets a *support
frame*, following the beam's joints (its supports) as a rigid body would:

* origin A: the beam's point of its first joint (in the order the joints were defined);
* x: along the chord from A to the beam's joint point farthest from A (the other support),
  or, when all the beam's joints act at one point (a cantilever), the section normal
  r_y x r_z at A;
* y: the section's height director r_y at A's node, made normal to x; z = x cross y.

The deflection of a probe on the beam is R(t)^T (p(t) - A(t)) - R(0)^T (p(0) - A(0)):
its displacement relative to that frame from the assembled configuration, resolved along
the frame's axes (x along the chord: axial; y: transverse in the height direction; z:
lateral). A beam whose joints move only rigidly (no elastic deformation) has zero support
deflection at every probe; the displacement from t = 0 (``deflection``) keeps the rigid
motion. Probes on beams without joints, rigid bodies, plates and leaves get none.
"""
from __future__ import annotations


import numpy as np

from ..records import record
from .bodies import Attachment
from .kinds import Beam
from .expressions import Vec3

#: what the support deflection is (the HDF5 attribute 'reference' of deflection_support)
SUPPORT_REFERENCE = (
    "displacement relative to the rigid motion of the beam's supports: origin at the beam's "
    "first joint point A, x along the chord from A to its farthest other joint point (one "
    "joint point: the section normal at A), y the section height director at A made normal "
    "to x, z = x cross y; components along (x, y, z) = (axial, transverse, lateral), zero "
    "in the assembled configuration")
#: what the plain deflection of a general scene's probes is (attribute 'reference')
DISPLACEMENT_REFERENCE = (
    "displacement from the assembled configuration (t = 0), resolved in the frame of the "
    "probe's beam (fixed at its t = 0 orientation unless the beam has a frame_drive), global "
    "axes for other bodies; includes the mechanism's rigid motion")


@record(eq=False)
class SupportFrame:
    """The support frame of one beam (see the module documentation)."""

    beam: str
    joints: tuple[str, ...]
    origin: Vec3
    end: Vec3 | None
    height: Vec3
    width: Vec3

    def describe(self) -> str:
        kind = "chord" if self.end is not None else "section at"
        return f"{self.beam}: {kind} joints {', '.join(self.joints)}"

    def axes(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Origin (nt, 3) and axes R (nt, 3, 3) (columns x, y, z) from full coordinates q
        (nt, nfull)."""
        a = evaluate(self.origin, q)
        height = evaluate(self.height, q)
        if self.end is not None:
            x = evaluate(self.end, q) - a
        else:
            x = np.cross(height, evaluate(self.width, q))
        x /= np.linalg.norm(x, axis=1)[:, None]
        y = height - np.einsum("ij,ij->i", height, x)[:, None] * x
        y /= np.linalg.norm(y, axis=1)[:, None]
        z = np.cross(x, y)
        return a, np.stack([x, y, z], axis=2)


def evaluate(vector: Vec3, q: np.ndarray) -> np.ndarray:
    """An affine 3-vector of the full coordinates at every row of q (nt, nfull): (nt, 3)."""
    q = np.atleast_2d(q)
    out = np.tile(vector.const, (len(q), 1))
    for first, coef in vector.terms.items():
        out += coef * q[:, first:first + 3]
    return out


def _joint_points(joint, beam: Beam) -> list[np.ndarray]:
    if joint.type == "distance":
        return [p for body, p in ((joint.body1, joint.point1), (joint.body2, joint.point2))
                if body is beam and p is not None]
    return list(joint.points) if beam in (joint.body1, joint.body2) else []


def support_frames(system) -> dict[str, SupportFrame]:
    """The support frame of every beam of an assembled System that has a joint (the bodies
    must be numbered: call after ``System.assemble``)."""
    out = {}
    for beam in system.bodies.values():
        if not beam.section_directors:  # no section (not a beam) for the frame to follow
            continue
        points: list[tuple[str, np.ndarray]] = []
        for joint in system.joints.values():
            points += [(joint.name, np.asarray(p, dtype=float))
                       for p in _joint_points(joint, beam)]
        if not points:
            continue
        name_a, a = points[0]
        far = max(points, key=lambda item: float(np.linalg.norm(item[1] - a)))
        has_end = float(np.linalg.norm(far[1] - a)) > 1e-6 * beam.length
        where = f"support frame of beam {beam.name!r}"
        at_a = beam.locate(a, node=False, what=where)
        node = at_a.node if at_a.node is not None else \
            int(np.argmin(np.abs(beam.stations - (a - beam.start) @ beam.orientation[:, 0])))
        at_node = Attachment(node=node)
        end = beam.position(beam.locate(far[1], node=False, what=where)) if has_end else None
        joints = (name_a, far[0]) if has_end and far[0] != name_a else (name_a,)
        out[beam.name] = SupportFrame(beam.name, joints, beam.position(at_a), end,
                                      *(beam.vector(at_node, w) for w in beam.section_directors))
    return out


def support_deflections(model, frames: dict[str, SupportFrame], q: np.ndarray
                        ) -> dict[str, np.ndarray]:
    """Support deflections (nt, 3) of the model's probes on beams with a support frame, from
    the full coordinates q (nt, nfull); relative to the assembled configuration model.e0."""
    q = np.atleast_2d(q)
    q0 = model.expand(model.e0)[None, :]
    out = {}
    for name, probe in model.probes.items():
        frame = frames.get(probe.body)
        if frame is None:
            continue
        p = np.zeros((len(q), 3))
        p0 = np.zeros((1, 3))
        for first, coef in probe.terms:
            p += coef * q[:, first:first + 3]
            p0 += coef * q0[:, first:first + 3]
        a, rotation = frame.axes(q)
        a0, rotation0 = frame.axes(q0)
        local = np.einsum("tji,tj->ti", rotation, p - a)
        local0 = np.einsum("tji,tj->ti", rotation0, p0 - a0)
        out[name] = local - local0
    return out
