"""Run by ParaView's pvbatch (python3-paraview): reads an XDMF file with ParaView's own XDMF
reader, and writes what it read at the given times to an .npz for the test to compare:
  pvbatch xdmf_readback.py RUN.xdmf OUT.npz FRAME [FRAME ...]"""
import sys

import numpy as np
from paraview import servermanager
from paraview.simple import XDMFReader
from vtkmodules.numpy_interface import dataset_adapter as dsa

xdmf, out, frames = sys.argv[1], sys.argv[2], [int(x) for x in sys.argv[3:]]
reader = XDMFReader(FileNames=[xdmf])
reader.UpdatePipelineInformation()
times = list(reader.TimestepValues)
result = {"times": np.array(times)}
for k in frames:
    reader.UpdatePipeline(times[k])
    data = servermanager.Fetch(reader)
    for b in range(data.GetNumberOfBlocks()):
        name = data.GetMetaData(b).Get(data.NAME())
        block = dsa.WrapDataObject(data.GetBlock(b))
        result[f"{name}_{k}_points"] = np.array(block.Points)
        if name == "bodies":
            grid = data.GetBlock(b)
            result[f"bodies_{k}_cell_sizes"] = np.array([grid.GetCell(i).GetNumberOfPoints()
                                                        for i in range(grid.GetNumberOfCells())])
            result[f"bodies_{k}_cell_types"] = np.array([grid.GetCellType(i) for i in range(grid.GetNumberOfCells())])
        for key in block.CellData.keys():
            result[f"{name}_{k}_cell_{key}"] = np.array(block.CellData[key])
        for key in block.PointData.keys():
            result[f"{name}_{k}_point_{key}"] = np.array(block.PointData[key])
np.savez(out, **result)
