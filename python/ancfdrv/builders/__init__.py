"""Template scenes as thin builders over the System API (one module per template): each
turns a validated template scene into a :class:`~ancfdrv.system.System`, and
:func:`build_model` assembles it with the scene's effects. General scenes (SPEC section 8)
are read by :mod:`ancfdrv.io.general` into the same API."""
from __future__ import annotations

from ..errors import InputError
from ..system import Model, System
from . import boom, cantilever, leaf, plate, spinup, spring
from .common import BuiltSystem, check_ffr_validity

BUILDERS = {"boom": boom.build, "cantilever": cantilever.build, "spinup": spinup.build,
            "plate": plate.build, "leaf": leaf.build, "spring": spring.build}


def build_system(scene) -> BuiltSystem:
    """The System a template scene describes (with the builder's response and warnings)."""
    if scene.kind == "general":
        from ..io.general import build_general
        return build_general(scene)
    if scene.kind not in BUILDERS:
        raise InputError(f"no builder for scene kind {scene.kind!r}")
    return BUILDERS[scene.kind](scene)


def build_model(scene) -> Model:
    """The assembled model of a scene: only the scene's effects are computed."""
    built = build_system(scene)
    built.system.planar = scene["scene"].get("planar", "off")  # system/planar.py
    model = built.system.assemble(effects=scene.effects,
                                  linear_joints=scene["solver"].get("linear_joints", "auto"),
                                  unused_effects="warn" if scene.kind == "general"
                                  else "allow",
                                  bounds=scene["scene"].get("bounds", "check"))
    model.warnings[:0] = built.warnings
    if built.response is not None:
        model.response = built.response
    check_ffr_validity(model, built.system)
    if scene.kind == "general":  # deflection relative to the supports' rigid motion
        from ..system.supports import support_frames
        model.support_frames = support_frames(built.system)
    return model


__all__ = ["build_system", "build_model", "BuiltSystem", "System"]
