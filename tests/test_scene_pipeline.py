"""The path from a scene to a model (issue 25): a general scene's System is built once (when
the scene is read and checked), the model is complete when assembly returns it (the
builder's response, the supports' frames, the warnings), and templates own what they add to
a run (the boom's luffing stages, the spring's settled start)."""
from __future__ import annotations

import math

import pytest

from conftest import INPUTS
from ancfdrv import builders
from ancfdrv.builders import build_model, settle_mode, stage_bounds
from ancfdrv.io import scene as scene_module
from ancfdrv.io.scene import load_scene


@pytest.fixture
def build_count(monkeypatch):
    """Counts the builds of general scenes (the builder io.scene calls and build_system's
    fallback are the same function)."""
    calls = []
    real = scene_module.GENERAL_BUILDER["build"]

    def counting(scene):
        calls.append(scene.path)
        return real(scene)
    monkeypatch.setitem(scene_module.GENERAL_BUILDER, "build", counting)
    monkeypatch.setattr(builders, "build_general", counting)
    return calls


def test_a_general_scene_is_built_once(build_count):
    """Reading the scene builds its System (every name and value checked); the run's model
    takes that System instead of building a second one (before: two builds)."""
    scene = load_scene(INPUTS / "general" / "cantilever.nml")
    assert len(build_count) == 1
    model = build_model(scene)
    try:
        assert len(build_count) == 1
    finally:
        model.close()
    model = build_model(scene)  # taken once: a second model is built afresh, never shared
    try:
        assert len(build_count) == 2
    finally:
        model.close()


def test_the_model_is_complete_at_assembly():
    """General scenes: deflections relative to the supports' rigid motion (support_frames
    set by assembly); templates: none, and the builder's response probe."""
    general = build_model(load_scene(INPUTS / "general" / "cantilever.nml"))
    template = build_model(load_scene(INPUTS / "boom_static.nml"))
    try:
        assert general.support_frames is not None and general.support_frames
        assert template.support_frames is None
        assert template.response is not None and template.response[0] in template.probes
        assert not hasattr(template, "kind")  # the write-only Model.kind is gone
    finally:
        general.close()
        template.close()


def test_the_boom_owns_its_luffing_stages():
    """inputs/boom_luffing.nml: phi from 0 to 60 deg at omega = 0.2 rad/s, 1 s smooth start
    and 1 s braking: the constant-speed stage ends at sweep/omega + (t_s - t_b)/2 =
    (pi/3)/0.2 = 5.23599 s, braking ends 1 s later (closed form of the drive's profile)."""
    scene = load_scene(INPUTS / "boom_luffing.nml")
    bounds = stage_bounds(scene)
    t1 = (math.pi / 3) / 0.2
    assert bounds["start"] == (0.0, 1.0)
    assert bounds["luffing"] == pytest.approx((1.0, t1), rel=1e-12)
    assert bounds["braking"] == pytest.approx((t1, t1 + 1.0), rel=1e-12)
    assert bounds["vibration"][1] == scene["solver"]["t_end"]
    assert stage_bounds(load_scene(INPUTS / "boom_static.nml",
                                   ["boom.omega=0"])) is None
    assert stage_bounds(load_scene(INPUTS / "cantilever.nml")) is None


def test_the_spring_owns_its_settled_start():
    """spring.settle names the start after what it settles; other scenes take
    solver.settle."""
    spring = INPUTS / "leaf_spring.nml"
    assert settle_mode(load_scene(spring, ["spring.settle='none'"])) == "none"
    assert settle_mode(load_scene(spring, ["spring.settle='prestress'"])) == "unloaded"
    assert settle_mode(load_scene(spring, ["spring.settle='gravity'"])) == "loaded"
    general = load_scene(INPUTS / "general" / "leaf_spring.nml")
    assert settle_mode(general) == general["solver"]["settle"]
