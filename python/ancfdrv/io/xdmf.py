"""XDMF descriptions of result files, for ParaView (and meshio).

The XDMF 3 file beside ``OUT.h5`` is a temporal collection with one uniform grid per
output step. Every DataItem is a plain ``Format="HDF"`` item naming one dataset, which is
what both ParaView's XDMF 3 reader and meshio's ``meshio.xdmf.TimeSeriesReader``
understand (meshio reads neither HyperSlab nor Function items). The per-step items are
HDF5 virtual datasets, ``/dynamic/xdmf/position/<k>`` and ``/dynamic/xdmf/displacement/<k>``,
that map row k of ``/dynamic/mesh_nodes`` and ``/dynamic/mesh_displacement``: no data is
copied (the dynamic writer adds them as rows are written, :func:`add_step_views`). The XML is built with ElementTree, so any file name (``&``, ``<``, quotes)
gives valid XML; a ``:`` in the HDF5 file name cannot be expressed in XDMF's
``file:/path`` notation and is refused.
"""
from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from pathlib import Path

import h5py
import numpy as np
from h5py import h5a, h5d, h5p, h5s, h5t

from ..errors import InputError

_STEPS_GROUP = "dynamic/xdmf"


def _item(parent: ET.Element, dims: tuple[int, ...], h5_name: str, dataset: str,
          number_type: str = "Float", precision: int = 8) -> ET.Element:
    item = ET.SubElement(parent, "DataItem", Dimensions=" ".join(map(str, dims)),
                         NumberType=number_type, Precision=str(precision), Format="HDF")
    item.text = f"{h5_name}:{dataset}"
    return item


def add_step_views(h5: h5py.File, first: int, stop: int) -> None:
    """Virtual datasets /dynamic/xdmf/position/<k> = /dynamic/mesh_nodes[k] and
    /dynamic/xdmf/displacement/<k> = /dynamic/mesh_displacement[k] for first <= k < stop,
    each with its source's ``units``. The dynamic writer calls this at each flush, so the
    cost (~0.3 ms per view) is spread over the run and a stopped run does not wait for
    it. (h5py's low-level API: its high-level VirtualLayout took ~1 ms per view.)"""
    for source, name in (("dynamic/mesh_nodes", "position"),
                         ("dynamic/mesh_displacement", "displacement")):
        if source not in h5:
            continue
        data = h5[source]
        shape = data.shape
        group = h5.require_group(f"{_STEPS_GROUP}/{name}")
        selection = h5s.create_simple(shape)
        view_space = h5s.create_simple(shape[1:])
        dtype = data.id.get_type()
        text = h5py.string_dtype()
        text_type = h5t.py_create(text, logical=True)
        scalar = h5s.create(h5s.SCALAR)
        units = np.array(data.attrs.get("units", "m"), dtype=text)
        count = (1, *shape[1:])
        for k in range(first, min(stop, shape[0])):
            if str(k) in group:
                continue
            selection.select_hyperslab((k,) + (0,) * (len(shape) - 1), count)
            plist = h5p.create(h5p.DATASET_CREATE)
            plist.set_virtual(view_space, b".", ("/" + source).encode(), selection)
            view = h5d.create(group.id, str(k).encode(), dtype, view_space, dcpl=plist)
            h5a.create(view, b"units", text_type, scalar).write(units)


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
        add_step_views(h5, 0, nsteps)  # those the writer has not made (older files)
        displacement = "dynamic/mesh_displacement" in h5
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
