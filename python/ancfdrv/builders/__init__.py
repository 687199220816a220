"""Template scenes as thin builders over the System API (one module per template): each
turns a validated template scene into a :class:`~ancfdrv.system.System`, and
:func:`build_model` assembles it with the scene's effects. General scenes (SPEC section 8)
are built by :mod:`ancfdrv.builders.general` into the same API."""
from __future__ import annotations

from ..errors import InputError
from ..system import Model, System
from . import boom, cantilever, leaf, plate, spinup, spring
from .common import BuiltSystem
from .general import build_general

BUILDERS = {"boom": boom.build, "cantilever": cantilever.build, "spinup": spinup.build,
            "plate": plate.build, "leaf": leaf.build, "spring": spring.build}
#: what a template adds to a run and to a sweep's report (the runner and the sweep know no
#: template): hook name -> function of the scene, by scene kind; a kind without the hook
#: takes the default below
RUN_HOOKS = {"boom": {"stage_bounds": boom.stage_bounds,
                      "closed_form_error": boom.closed_form_error},
             "plate": {"closed_form_error": plate.closed_form_error},
             "spring": {"settle_mode": spring.settle_mode}}


def build_system(scene) -> BuiltSystem:
    """The System a template scene describes (with the builder's response and warnings)."""
    if scene.kind == "general":  # the System load_scene built (once), else a new one
        built, scene.built = scene.built, None
        return built if built is not None else build_general(scene)
    if scene.kind not in BUILDERS:
        raise InputError(f"no builder for scene kind {scene.kind!r}")
    return BUILDERS[scene.kind](scene)


def fixed_loads(scene, system: System) -> tuple[str, ...]:
    """The loads (names or effects) a buckling scene keeps at their value
    (buckling.fixed_loads; none for other analyses): an unknown name is an InputError
    naming buckling.fixed_loads."""
    if scene["scene"]["analysis"] != "buckling":
        return ()
    fixed = tuple((scene.values.get("buckling") or {}).get("fixed_loads", ()))
    known = set(system.loads) | {load.effect for load in system.loads.values()}
    unknown = [name for name in fixed if name not in known]
    if unknown:
        raise InputError(f"unknown load or effect {', '.join(map(repr, unknown))} (loads: "
                         f"{', '.join(system.loads) or 'none'})", file=str(scene.path),
                         group="buckling", key="fixed_loads")
    return fixed


def build_model(scene) -> Model:
    """The assembled model of a scene: only the scene's effects are computed; a buckling
    scene's fixed loads are flagged (:func:`fixed_loads`)."""
    built = build_system(scene)
    built.system.planar = scene["scene"].get("planar", "off")  # system/planar.py
    return built.system.assemble(effects=scene.effects,
                                 linear_joints=scene["solver"].get("linear_joints", "auto"),
                                 unused_effects="warn" if scene.kind == "general"
                                 else "allow",
                                 bounds=scene["scene"].get("bounds", "check"),
                                 warnings=built.warnings, response=built.response,
                                 # deflection relative to the supports' rigid motion
                                 supports=scene.kind == "general",
                                 fixed_loads=fixed_loads(scene, built.system))


def stage_bounds(scene) -> dict[str, tuple[float, float]] | None:
    """The stages over which a dynamic run summarizes the response (the luffing boom's:
    :func:`ancfdrv.builders.boom.stage_bounds`), None for other scenes."""
    hook = RUN_HOOKS.get(scene.kind, {}).get("stage_bounds")
    return hook(scene) if hook else None


def settle_mode(scene) -> str:
    """How a dynamic run starts: 'none' (from the assembled configuration), 'unloaded'
    (at rest in the equilibrium of the internal forces alone: prestress carried by
    contact, the external loads off) or 'loaded' (at rest in the static equilibrium under
    every load): ``solver.settle``, or the template's own key (the spring's
    ``spring.settle``)."""
    hook = RUN_HOOKS.get(scene.kind, {}).get("settle_mode")
    return hook(scene) if hook else scene["solver"]["settle"]


def closed_form_error(scene, row: dict) -> float | None:
    """The relative error of a successful static case's response (a sweep's row) against
    the template's closed form, which the hook records in the row (the boom's tip sag:
    :func:`ancfdrv.builders.boom.closed_form_error`; the simply supported plate's centre
    deflection: :func:`ancfdrv.builders.plate.closed_form_error`); None for a scene without
    one."""
    hook = RUN_HOOKS.get(scene.kind, {}).get("closed_form_error")
    return hook(scene, row) if hook else None


__all__ = ["build_system", "build_model", "stage_bounds", "settle_mode", "closed_form_error",
           "BuiltSystem", "System"]
