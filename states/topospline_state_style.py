"""The paper's figure style, shared by the Python states: colour map plus isolines of the
field; ascending 1-cells red, descending green; minima blue, saddles green, maxima red."""
import numpy as np
from paraview.simple import *


def solid(display, color):
    display.ColorArrayName = ["POINTS", ""]
    display.AmbientColor = display.DiffuseColor = color


def field_with_isolines(source, array, view, isolines=20):
    display = Show(source, view)
    ColorBy(display, ("POINTS", array))
    GetColorTransferFunction(array).ApplyPreset("Viridis (matplotlib)", True)
    source.UpdatePipeline()
    low, high = source.PointData[array].GetRange()
    contours = Contour(Input=source, ContourBy=["POINTS", array],
                       Isosurfaces=list(np.linspace(low, high, isolines + 2)[1:-1]))
    solid(Show(contours, view), [0.1, 0.1, 0.1])


def complex_lines(complex_proxy, view, block="SampledOneCells", width=3.0):
    arcs = ExtractBlock(Input=complex_proxy, Selectors=["/Root/" + block])
    for kind, color in ((0, [0.0, 0.6, 0.0]), (1, [0.85, 0.0, 0.0])):
        lines = Threshold(Input=arcs, Scalars=["CELLS", "SeparatrixType"], LowerThreshold=kind, UpperThreshold=kind)
        display = Show(lines, view)
        solid(display, color)
        display.LineWidth = width
    points = ExtractBlock(Input=complex_proxy, Selectors=["/Root/CriticalPoints"])
    for kind, color in ((0, [0.0, 0.2, 1.0]), (1, [0.0, 0.7, 0.0]), (2, [1.0, 0.0, 0.0])):
        selected = Threshold(Input=points, Scalars=["POINTS", "CriticalIndex"], LowerThreshold=kind, UpperThreshold=kind)
        display = Show(selected, view)
        solid(display, color)
        display.SetRepresentationType("Points")
        display.RenderPointsAsSpheres = 1
        display.PointSize = 12


def view_from_above(view):
    view.OrientationAxesVisibility = 0
    view.CameraParallelProjection = 1
    ResetCamera(view)


def panel(layout, where, source, array, lines):
    """One view of a figure: `array` of `source` with isolines and the smoothed 1-cells of
    `lines`, seen from above, at position `where` of `layout`."""
    view = CreateView("RenderView")
    AssignViewToLayout(view=view, layout=layout, hint=where)
    field_with_isolines(source, array, view)
    complex_lines(lines, view)
    view_from_above(view)
    return view
