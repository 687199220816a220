"""Small builders the tests share: beams and plates made through the System API."""
from __future__ import annotations

import numpy as np

from ancfdrv import kernel
from ancfdrv.codes import SECTION_RECTANGLE
from ancfdrv.system import Rectangle, System


def rect(width: float, height: float) -> kernel.SectionData:
    """The kernel's rule and properties of a width x height rectangle."""
    return kernel.section_data(SECTION_RECTANGLE, (width, height))


def beam_model(nodes: int = 5, length: float = 2.0, *, width: float = 0.1, height: float = 0.08,
               rotation=np.eye(3), offset=(0.0, 0.0, 0.0), formulation: str = "ffr",
               bending: str = "continuum", youngs: float = 2.1e11, poisson: float = 0.0,
               density: float = 7850.0, effects: tuple[str, ...] = (), gravity=None,
               node_s=None):
    """A free beam (no joints) whose frame is ``rotation``: axis rotation e1, section height
    rotation e2, its start at rotation @ offset (the old BeamModel's origin_offset)."""
    rotation = np.asarray(rotation, dtype=float)
    s = System("test beam", effects=effects)
    steel = s.material("steel", youngs_modulus=youngs, density=density, poisson_ratio=poisson)
    start = rotation @ np.asarray(offset, dtype=float)
    segments = None if node_s is None else np.diff(node_s)
    if segments is not None:
        nodes, length = len(node_s), float(node_s[-1] - node_s[0])
        segments = list(segments)
    s.beam("beam", material=steel, start=start, end=start + length * rotation[:, 0], nodes=nodes,
           section=Rectangle(width, height), height_axis=rotation[:, 1], formulation=formulation,
           bending=bending, segments=segments)
    if gravity is not None:
        s.load("gravity", "gravity", vector=gravity)
    return s.assemble(effects=effects if gravity is None else tuple(effects) + ("gravity",))


def frame_coordinates(model) -> np.ndarray:
    """The first beam's rigid configuration in its frame (positions from its start)."""
    body = model.sets[0].body
    frame = model.frames[model.sets[0].frame - 1]
    q = model.q0[body.first:body.first + body.ncoordinates].reshape(-1, 4, 3).copy()
    q[:, 0, :] -= frame.pivot
    return (q.reshape(-1, 3) @ frame.rotation(0.0)).ravel()
