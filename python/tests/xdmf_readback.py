"""Run by ParaView's pvbatch (python3-paraview): reads an XDMF file with one of ParaView's XDMF
readers, and writes what it read at the given frames to an .npz for the test to compare:
  pvbatch xdmf_readback.py READER RUN.xdmf OUT.npz FRAME [FRAME ...]
READER: XDMFReader (the older "XDMF Reader"), Xdmf3ReaderS or Xdmf3ReaderT. The Xdmf3 readers
give the first grid (the bodies) alone, the older one a block per grid."""
import sys

import numpy as np
from paraview import servermanager
from paraview import simple
from vtkmodules.numpy_interface import dataset_adapter as dsa

reader_name, xdmf, out, frames = sys.argv[1], sys.argv[2], sys.argv[3], [int(x) for x in sys.argv[4:]]
make = getattr(simple, reader_name)
reader = make(FileNames=[xdmf]) if reader_name == "XDMFReader" else make(FileName=[xdmf])
reader.UpdatePipelineInformation()
times = list(reader.TimestepValues)
result = {"times": np.array(times)}


def keep(name, k, grid):
    block = dsa.WrapDataObject(grid)
    result[f"{name}_{k}_points"] = np.array(block.Points)
    if name == "bodies":
        result[f"bodies_{k}_cell_sizes"] = np.array([grid.GetCell(i).GetNumberOfPoints()
                                                    for i in range(grid.GetNumberOfCells())])
        result[f"bodies_{k}_cell_types"] = np.array([grid.GetCellType(i) for i in range(grid.GetNumberOfCells())])
    for key in block.CellData.keys():
        result[f"{name}_{k}_cell_{key}"] = np.array(block.CellData[key])
    for key in block.PointData.keys():
        result[f"{name}_{k}_point_{key}"] = np.array(block.PointData[key])


for k in frames:
    reader.UpdatePipeline(times[k])
    data = servermanager.Fetch(reader)
    if data.IsA("vtkMultiBlockDataSet"):
        for b in range(data.GetNumberOfBlocks()):
            keep(data.GetMetaData(b).Get(data.NAME()), k, data.GetBlock(b))
    else:
        keep("bodies", k, data)
np.savez(out, **result)
