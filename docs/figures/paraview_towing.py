"""docs/paraview-towing.png: the paper's towing case as ParaView shows floedem's XDMF export.
Made with ParaView's pvbatch (Debian: python3-paraview; without a display, under xvfb-run):

    floedem run scenarios/towing_paper.toml -o towing.h5
    floedem export towing.h5 --xdmf
    xvfb-run -a -s "-screen 0 1600x1000x24" pvbatch docs/figures/paraview_towing.py towing.xdmf docs/paraview-towing.png

then reduced to 1200 x 600 pixels and 64 colours (PIL's quantize) to keep the repository small.
"""
import sys

from paraview.simple import (ColorBy, ExtractBlock, GetActiveViewOrCreate, GetColorTransferFunction, GetScalarBar,
                             Render, SaveScreenshot, Show, Threshold, XDMFReader)

xdmf, out = sys.argv[1], sys.argv[2]
reader = XDMFReader(FileNames=[xdmf])
reader.UpdatePipelineInformation()
last = reader.TimestepValues[-1]
view = GetActiveViewOrCreate("RenderView")
view.ViewTime = last
view.ViewSize = [1600, 800]
view.UseColorPaletteForBackground = 0
view.Background = [1.0, 1.0, 1.0]
view.OrientationAxesVisibility = 0

bodies = ExtractBlock(Input=reader, Selectors=["/Root/bodies"])
shown = Show(bodies, view)
ColorBy(shown, ("CELLS", "velocity", "Magnitude"))
speed = GetColorTransferFunction("velocity")
speed.ApplyPreset("Blues", True)
speed.InvertTransferFunction()   # still floes pale, fast ones dark
speed.RescaleTransferFunction(0.0, 0.8)
shown.SetScalarBarVisibility(view, True)
bar = GetScalarBar(speed, view)
bar.Title, bar.ComponentTitle = "floe speed (m/s)", ""
bar.TitleColor = bar.LabelColor = [0.0, 0.0, 0.0]
shown.EdgeColor = [0.35, 0.35, 0.35]
shown.SetRepresentationType("Surface With Edges")

# The collisions of the last minute, as red points.
collisions = ExtractBlock(Input=reader, Selectors=["/Root/collisions"])
recent = Threshold(Input=collisions, Scalars=["POINTS", "time"], LowerThreshold=last - 60.0, UpperThreshold=last)
points = Show(recent, view)
points.SetRepresentationType("Points")
points.PointSize = 4.0
points.AmbientColor = points.DiffuseColor = [0.85, 0.2, 0.1]
ColorBy(points, None)

view.CameraParallelProjection = 1
view.ResetCamera()
Render(view)
view.CameraParallelScale = 0.58 * view.CameraParallelScale
Render(view)
SaveScreenshot(out, view, ImageResolution=[1600, 800])
print(out)
