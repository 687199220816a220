"""XDMF descriptions of result files, for ParaView (and meshio).

The XDMF 3 file beside ``OUT.h5`` is a temporal collection with one uniform grid per
output step. Every DataItem is a plain ``Format="HDF"`` item naming one dataset, which is
what both ParaView's XDMF 3 reader and meshio's ``meshio.xdmf.TimeSeriesReader``
understand (meshio reads neither HyperSlab nor Function items). The per-step items are
HDF5 virtual datasets, ``/dynamic/xdmf/position/<k>`` and ``/dynamic/xdmf/displacement/<k>``,
that map row k of ``/dynamic/mesh_nodes`` and ``/dynamic/mesh_displacement``: no data is
copied. The XML is built with ElementTree, so any file name (``&``, ``<``, quotes)
gives valid XML; a ``:`` in the HDF5 file name cannot be expressed in XDMF's
``file:/path`` notation and is refused.
"""
from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from pathlib import Path

import h5py

from ..errors import InputError

_STEPS_GROUP = "dynamic/xdmf"


def _item(parent: ET.Element, dims: tuple[int, ...], h5_name: str, dataset: str,
          number_type: str = "Float", precision: int = 8) -> ET.Element:
    item = ET.SubElement(parent, "DataItem", Dimensions=" ".join(map(str, dims)),
                         NumberType=number_type, Precision=str(precision), Format="HDF")
    item.text = f"{h5_name}:{dataset}"
    return item


def _step_views(h5: h5py.File, source: str, name: str, nsteps: int) -> bool:
    """Virtual datasets /dynamic/xdmf/<name>/<k> = source[k]; False if source is missing."""
    if source not in h5:
        return False
    data = h5[source]
    shape = data.shape
    group = h5.require_group(f"{_STEPS_GROUP}/{name}")
    whole = h5py.VirtualSource(".", "/" + source, shape=shape, dtype=data.dtype)
    for k in range(nsteps):
        layout = h5py.VirtualLayout(shape=shape[1:], dtype=data.dtype)
        layout[...] = whole[k]
        view = group.create_virtual_dataset(str(k), layout)
        view.attrs["units"] = data.attrs.get("units", "m")
    return True


def write_xdmf(path: Path) -> Path:
    """An XDMF file beside the HDF5 result of a plate model: one quadrilateral grid per
    output step (the elements' corner nodes) at the node positions of the step, with the
    nodal displacement from /model/nodes; opens in ParaView as a time series."""
    path = Path(path)
    name = path.name
    if ":" in name:
        raise InputError("XDMF cannot name an HDF5 file with ':' in its name", file=str(path))
    with h5py.File(path, "a") as h5:
        times = h5["dynamic/time"][()]
        nsteps = min(len(times), h5["dynamic/mesh_nodes"].shape[0])
        nnodes = h5["dynamic/mesh_nodes"].shape[1]
        nel, corners = h5["model/elements"].shape
        if _STEPS_GROUP in h5:
            del h5[_STEPS_GROUP]
        _step_views(h5, "dynamic/mesh_nodes", "position", nsteps)
        displacement = _step_views(h5, "dynamic/mesh_displacement", "displacement", nsteps)
    root = ET.Element("Xdmf", Version="3.0")
    domain = ET.SubElement(root, "Domain")
    series = ET.SubElement(domain, "Grid", Name="motion", GridType="Collection",
                           CollectionType="Temporal")
    for k in range(nsteps):
        grid = ET.SubElement(series, "Grid", Name=f"step {k}", GridType="Uniform")
        ET.SubElement(grid, "Time", Value=f"{times[k]:.17g}")
        topology = ET.SubElement(grid, "Topology", TopologyType="Quadrilateral",
                                 NumberOfElements=str(nel))
        _item(topology, (nel, corners), name, "/model/elements", "Int")
        geometry = ET.SubElement(grid, "Geometry", GeometryType="XYZ")
        _item(geometry, (nnodes, 3), name, f"/{_STEPS_GROUP}/position/{k}")
        if displacement:
            attribute = ET.SubElement(grid, "Attribute", Name="displacement",
                                      AttributeType="Vector", Center="Node")
            _item(attribute, (nnodes, 3), name, f"/{_STEPS_GROUP}/displacement/{k}")
    out = path.with_suffix(".xdmf")
    partial = out.with_name(out.name + ".partial")
    ET.ElementTree(root).write(partial, encoding="utf-8", xml_declaration=True)
    os.replace(partial, out)
    return out
