"""XDMF descriptions of result files, for ParaView."""
from __future__ import annotations

from pathlib import Path

import h5py


def write_xdmf(path: Path) -> Path:
    """An XDMF file beside the HDF5 result of a plate model: one quadrilateral grid per
    output step (the elements' corner nodes) with the node positions of
    /dynamic/mesh_nodes, and the nodal displacement; opens in ParaView as a time series."""
    with h5py.File(path, "r") as h5:
        times = h5["dynamic/time"][()]
        nnodes = h5["dynamic/mesh_nodes"].shape[1]
        nel = h5["model/elements"].shape[0]
    name = path.name
    grids = []
    for k, t in enumerate(times):
        slab = (f'<DataItem ItemType="HyperSlab" Dimensions="{nnodes} 3" Type="HyperSlab">'
                f'<DataItem Dimensions="3 3" Format="XML">{k} 0 0 1 1 1 1 {nnodes} 3</DataItem>'
                f'<DataItem Dimensions="{len(times)} {nnodes} 3" NumberType="Float" '
                f'Precision="8" Format="HDF">{name}:/dynamic/mesh_nodes</DataItem></DataItem>')
        grids.append(
            f'<Grid Name="step {k}" GridType="Uniform"><Time Value="{t:.9g}"/>'
            f'<Topology TopologyType="Quadrilateral" NumberOfElements="{nel}">'
            f'<DataItem Dimensions="{nel} 4" NumberType="Int" Precision="8" Format="HDF">'
            f'{name}:/model/elements</DataItem></Topology>'
            f'<Geometry GeometryType="XYZ">{slab}</Geometry>'
            f'<Attribute Name="displacement" AttributeType="Vector" Center="Node">'
            f'<DataItem ItemType="Function" Function="$0 - $1" Dimensions="{nnodes} 3">'
            f'{slab}<DataItem Dimensions="{nnodes} 3" NumberType="Float" Precision="8" '
            f'Format="HDF">{name}:/model/nodes</DataItem></DataItem></Attribute></Grid>')
    text = ('<?xml version="1.0" ?>\n<Xdmf Version="3.0"><Domain>'
            '<Grid Name="motion" GridType="Collection" CollectionType="Temporal">\n'
            + "\n".join(grids) + "\n</Grid></Domain></Xdmf>\n")
    out = path.with_suffix(".xdmf")
    out.write_text(text)
    return out
