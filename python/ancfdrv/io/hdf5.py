"""HDF5 result files (SPEC section 4), written with h5py.

A file is created (and its root, /model and /counters written) before any solve, so a
failed run still leaves a readable file that says what was attempted.
"""
from __future__ import annotations

import datetime as _dt
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from .. import __version__
from ..system.bodies import Beam
from ..system.model import Model
from .scene import Scene
from ..solvers.static import StaticResult


def _attrs(target: h5py.AttributeManager, values: dict[str, Any]) -> None:
    for key, value in values.items():
        target[key] = value


def create(path: Path, scene: Scene, model: Model) -> None:
    """New result file with the root attributes and /model."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with h5py.File(path, "w") as h5:
        _attrs(h5.attrs, {
            "ancfdrv_version": __version__,
            "created": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
            "scene": scene.text,
            "scene_file": str(scene.path),
            "overrides": "\n".join(scene.overrides),
            "title": scene["scene"]["title"],
            "kind": scene.kind,
            "formulation": scene["scene"]["formulation"],
            "effects": ",".join(scene.effects),
            "warnings": "\n".join(model.warnings),
            "status": "running",
            # what sweeps compare: probe and component (beams: the tip sag)
            "response_probe": (model.response or ("", 0))[0],
            "response_component": (model.response or ("", 0))[1],
            "linear_joints": model.linear_joints,
            "jacobian_policy_model": "constant" if model.constant_policy else "refactor",
        })
        beams = [b for b in model.bodies if isinstance(b, Beam)]
        if beams:  # 'continuum' or 'cubic' (beam.bending) of the first beam
            h5.attrs["bending"] = beams[0].bending
        group = h5.create_group("model")
        _attrs(group.attrs, model.summary())
        geometry = model.plate_geometry()
        if geometry is not None:  # plates: initial node positions and connectivity
            group.create_dataset("nodes", data=geometry[0])
            group.create_dataset("elements", data=geometry[1])
        if len(beams) == 1:
            group.create_dataset("node_s", data=beams[0].stations)
        group.create_dataset("e0", data=model.e0)
        group.attrs["constraint_names"] = "\n".join(model.constraints.names)
        group.attrs["bodies"] = "\n".join(f"{b.name}: {type(b).__name__.lower()}"
                                          for b in model.bodies)
        if model.notes:
            group.attrs["notes"] = "\n".join(model.notes)


def write_static(path: Path, model: Model, result: StaticResult) -> None:
    """The /static group: q, lambda, probes, deflections and solver statistics."""
    with h5py.File(path, "a") as h5:
        if "static" in h5:
            del h5["static"]
        group = h5.create_group("static")
        group.create_dataset("q", data=result.e)
        group.create_dataset("lambda", data=result.lam)
        group.create_dataset("residual_history", data=np.asarray(result.history))
        for name, position in model.probe_positions(result.e).items():
            group.create_dataset(f"probes/{name}", data=position)
        for name, deflection in model.deflections(result.e).items():
            group.create_dataset(f"deflection/{name}", data=deflection)
        _attrs(group.attrs, {"method": result.method, "iterations": result.iterations,
                             "residual_norm": result.residual_norm,
                             "constraint_norm": result.constraint_norm,
                             "wall_time_s": result.wall_time_s, **result.extra})


def finish(path: Path, model: Model, timing: dict[str, float], status: str,
           message: str = "") -> None:
    """Counters, timing and the final status (also after a failure)."""
    with h5py.File(path, "a") as h5:
        for name in ("counters", "timing"):
            if name in h5:
                del h5[name]
        counters = h5.create_group("counters")
        _attrs(counters.attrs, {k: int(v) for k, v in sorted(model.counters.items())})
        counters.attrs["constraint_evaluations"] = model.constraints.evaluations
        group = h5.create_group("timing")
        _attrs(group.attrs, {k: float(v) for k, v in timing.items()})
        # the phases SPEC section 4 names, summed over the analyses (dynamic stepping counts
        # as solve: the kernel's factorization-free steps are substitutions and residuals)
        _attrs(group.attrs, {
            "assembly": float(timing.get("static_assembly", 0.0) + timing.get("model", 0.0)),
            "factorization": float(timing.get("static_factorization", 0.0)
                                   + timing.get("dynamic_setup", 0.0)),
            "solve": float(timing.get("static_solve", 0.0) + timing.get("dynamic_stepping", 0.0)),
            "contact": 0.0,
            "output": float(timing.get("output", 0.0) + timing.get("dynamic_output", 0.0)),
            "total": float(timing.get("total", 0.0))})
        h5.attrs["status"] = status
        h5.attrs["message"] = message
        h5.attrs["warnings"] = "\n".join(model.warnings)
        if "dynamic" in h5 and status != "ok":
            h5["dynamic"].attrs["status"] = status
        has_motion = "dynamic/mesh_nodes" in h5
    if has_motion:
        from .xdmf import write_xdmf
        write_xdmf(path)


def read_summary(path: Path) -> dict[str, Any]:
    """The main figures of a result file as a flat dict (used by info, sweep, plot)."""
    out: dict[str, Any] = {}
    with h5py.File(path, "r") as h5:
        out.update({k: (v.decode() if isinstance(v, bytes) else v) for k, v in h5.attrs.items()})
        out.update({f"model.{k}": v for k, v in h5["model"].attrs.items()})
        if "static" in h5:
            static = h5["static"]
            out.update({f"static.{k}": v for k, v in static.attrs.items()})
            for name in static["deflection"]:
                out[f"static.deflection.{name}"] = static["deflection"][name][()]
                out[f"static.probes.{name}"] = static["probes"][name][()]
        if "dynamic" in h5:
            dynamic = h5["dynamic"]
            out.update({f"dynamic.{k}": v for k, v in dynamic.attrs.items()})
            if "stages" in dynamic:
                out.update({f"stages.{k}": v for k, v in dynamic["stages"].attrs.items()})
            if len(dynamic["time"]):
                out["dynamic.t_reached"] = float(dynamic["time"][-1])
                for name in dynamic["deflection"]:
                    out[f"dynamic.deflection.{name}.final"] = dynamic["deflection"][name][-1]
        if "timing" in h5:
            out.update({f"timing.{k}": v for k, v in h5["timing"].attrs.items()})
        if "counters" in h5:
            out.update({f"counters.{k}": v for k, v in h5["counters"].attrs.items()})
    return out


class DynamicWriter:
    """Appends each chunk of a dynamic run to /dynamic and closes the file after it, so
    every completed chunk is on disk whatever happens next (SPEC section 4)."""

    def __init__(self, path: Path, model: Model, store_q: bool) -> None:
        from ..solvers.dynamic import CONTACT_FIELDS, ENERGY_NAMES
        self.path, self.names, self.store_q = path, list(model.probes), store_q
        self.node_positions = model.node_positions if model.plate_bodies() else None
        self.npoints = model.npoint
        self.contact_fields = CONTACT_FIELDS
        geometry = model.plate_geometry()
        self.nnodes = len(geometry[0]) if geometry is not None and store_q else 0
        self.energy_names = ENERGY_NAMES
        self.rows = 0
        ncon, ndof = len(model.constraints), model.ndof
        with h5py.File(path, "a") as h5:
            if "dynamic" in h5:
                del h5["dynamic"]
            group = h5.create_group("dynamic")
            group.attrs["status"] = "running"

            def series(name: str, width: tuple[int, ...] = ()) -> None:
                # a model without constraints has lambda[nt, 0]: HDF5 chunks must be
                # positive, so that axis gets a free maximum
                chunk = tuple(max(1, w) for w in width)
                limit = tuple(w if w else None for w in width)
                group.create_dataset(name, shape=(0, *width), maxshape=(None, *limit),
                                     dtype="f8", chunks=(1024, *chunk) if width != (ndof,)
                                     else (16, ndof))
            series("time")
            for name in self.names:
                series(f"probes/{name}", (3,))
                series(f"deflection/{name}", (3,))
            series("lambda", (ncon,))
            for name in ENERGY_NAMES:
                series(f"energy/{name}")
            series("energy/balance")
            series("constraint_violation")
            series("newton_iterations")
            series("factorizations")
            series("jacobian_evaluations")
            if self.npoints:  # per contact point: penetration, forces, slip, projection
                for name in CONTACT_FIELDS:
                    series(f"contact/{name}", (self.npoints,))
                group["contact"].attrs["points"] = "\n".join(model.contact_point_names)
            if store_q:
                series("q", (ndof,))
            if self.nnodes:  # plate models: node positions per step, for ParaView (XDMF)
                group.create_dataset("mesh_nodes", shape=(0, self.nnodes, 3),
                                     maxshape=(None, self.nnodes, 3), dtype="f8",
                                     chunks=(16, self.nnodes, 3))

    def __call__(self, chunk) -> None:
        n = len(chunk.time)
        with h5py.File(self.path, "a") as h5:
            group = h5["dynamic"]

            def append(name: str, values: np.ndarray) -> None:
                data = group[name]
                data.resize(self.rows + n, axis=0)
                data[self.rows:] = values
            append("time", chunk.time)
            for p, name in enumerate(self.names):
                append(f"probes/{name}", chunk.probes[:, p, :])
                append(f"deflection/{name}", chunk.deflections[:, p, :])
            append("lambda", chunk.lam)
            for k, name in enumerate(self.energy_names):
                append(f"energy/{name}", chunk.energy[:, k])
            total0 = group["energy/total"][0] if self.rows else chunk.energy[0, 4]
            # total - total(0) - work of drives, moving frames, contact damping, friction and
            # material damping
            append("energy/balance", chunk.energy[:, 4] - total0 - chunk.energy[:, 5]
                   - chunk.energy[:, 6] - chunk.energy[:, 8] - chunk.energy[:, 9]
                   - chunk.energy[:, 10])
            if self.npoints and chunk.contact is not None:
                for k, name in enumerate(self.contact_fields):
                    append(f"contact/{name}", chunk.contact[:, :, k])
            append("constraint_violation", chunk.constraint)
            append("newton_iterations", chunk.stats[:, 0])
            append("factorizations", chunk.stats[:, 1])
            append("jacobian_evaluations", chunk.stats[:, 2])
            if self.store_q and chunk.q is not None:
                append("q", chunk.q)
                if self.nnodes and self.node_positions is not None:
                    append("mesh_nodes", self.node_positions(chunk.q))
                elif self.nnodes:
                    append("mesh_nodes", chunk.q.reshape(n, self.nnodes, -1)[:, :, :3])
            self.rows += n
            group.attrs["rows"] = self.rows


def write_dynamic_attrs(path: Path, attrs: dict[str, Any], stages: dict[str, float]) -> None:
    """Integrator statistics and the per-stage summary (attributes of /dynamic)."""
    with h5py.File(path, "a") as h5:
        group = h5["dynamic"]
        _attrs(group.attrs, attrs)
        if stages:
            stage_group = group.require_group("stages")
            _attrs(stage_group.attrs, stages)
