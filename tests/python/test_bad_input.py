"""Bad input gets a clear error message and an empty output, never a crash: each case runs in
its own pvpython process so that a crash is seen as such."""
import os
import subprocess
import sys

import topospline_testing as tt

checks = tt.Checks()
PRELUDE = """
import numpy as np
from paraview.simple import *
from paraview import servermanager as sm
from vtkmodules.util.numpy_support import numpy_to_vtk
from vtkmodules.vtkCommonDataModel import vtkImageData, vtkPolyData
LoadPlugin(%r, remote=False, ns=globals())
def mesh(points, triangles, values):
    from vtkmodules.vtkCommonCore import vtkPoints
    from vtkmodules.vtkCommonDataModel import vtkCellArray
    pd = vtkPolyData()
    pts = vtkPoints()
    for x, y in points:
        pts.InsertNextPoint(x, y, 0)
    pd.SetPoints(pts)
    cells = vtkCellArray()
    for t in triangles:
        cells.InsertNextCell(3, t)
    pd.SetPolys(cells)
    arr = numpy_to_vtk(np.asarray(values, dtype=float), deep=1)
    arr.SetName("f")
    pd.GetPointData().AddArray(arr)
    return pd
def grid_mesh(nx, ny, dx=0, dy=0):
    pts = [(dx + i, dy + j) for j in range(ny) for i in range(nx)]
    tris = []
    for j in range(ny - 1):
        for i in range(nx - 1):
            a = j * nx + i
            tris += [(a, a + 1, a + nx), (a + 1, a + nx + 1, a + nx)]
    return pts, tris
def producer(data):
    p = TrivialProducer()
    p.GetClientSideObject().SetOutput(data)
    return p
def image(values, dims, name="f", comps=1):
    im = vtkImageData()
    im.SetDimensions(*dims)
    arr = numpy_to_vtk(np.asarray(values, dtype=float).reshape(-1, comps), deep=1)
    arr.SetName(name)
    im.GetPointData().AddArray(arr)
    return im
""" % tt.plugin_path()
EPILOGUE = """
ms.UpdatePipeline()
out = sm.Fetch(ms)
print("BLOCKS", out.GetNumberOfBlocks())
"""

CASES = {
    "no point scalars": ("im = vtkImageData(); im.SetDimensions(10, 10, 1)\n"
                         "ms = MorseSmaleComplex(Input=producer(im))", "no point scalar array"),
    "multi-component array": ("ms = MorseSmaleComplex(Input=producer(image(np.random.rand(300), (10, 10, 1), 'v', 3)))\n"
                              "ms.ScalarField = ['POINTS', 'v']", "3 components"),
    "3D image": ("ms = MorseSmaleComplex(Input=Wavelet())", "the image is 3D"),
    "NaN values": ("v = np.random.rand(100); v[42] = np.nan\n"
                   "ms = MorseSmaleComplex(Input=producer(image(v, (10, 10, 1))))", "non-finite"),
    "Inf values": ("v = np.random.rand(100); v[7] = np.inf\n"
                   "ms = MorseSmaleComplex(Input=producer(image(v, (10, 10, 1))))", "non-finite"),
    "empty data set": ("ms = MorseSmaleComplex(Input=producer(vtkPolyData()))", "empty"),
    "non-triangle cells": ("plane = Plane(XResolution=5, YResolution=5)\n"
                           "calc = Calculator(Input=plane, ResultArrayName='f', Function='coordsX*coordsY')\n"
                           "ms = MorseSmaleComplex(Input=calc)\nms.ScalarField = ['POINTS', 'f']",
                           "is not a triangle"),
    "1D image": ("ms = MorseSmaleComplex(Input=producer(image(np.random.rand(10), (10, 1, 1))))",
                 "fewer than two dimensions"),
    "non-planar mesh": ("s = Sphere()\ncalc = Calculator(Input=s, ResultArrayName='f', Function='coordsZ')\n"
                        "ms = MorseSmaleComplex(Input=calc)\nms.ScalarField = ['POINTS', 'f']", "coordinate plane"),
    "threshold below 0": ("ms = MorseSmaleComplex(Input=TrigonometricField())\n"
                          "s = SimplifyMorseSmaleComplex(Input=ms)\n"
                          "s.PersistenceThreshold = -5\nms = s", "must be a percentage in [0, 100]"),
    "threshold above 100": ("ms = MorseSmaleComplex(Input=TrigonometricField())\n"
                            "s = SimplifyMorseSmaleComplex(Input=ms)\n"
                            "s.PersistenceThreshold = 250\nms = s",
                            "must be a percentage in [0, 100]"),
    "zero spacing": ("im = image(np.random.rand(100), (10, 10, 1)); im.SetSpacing(1, 0, 1)\n"
                     "ms = MorseSmaleComplex(Input=producer(im))", "not a finite positive spacing"),
    "NaN spacing": ("im = image(np.random.rand(100), (10, 10, 1)); im.SetSpacing(float('nan'), 1, 1)\n"
                    "ms = MorseSmaleComplex(Input=producer(im))", "not a finite positive spacing"),
    "tilted image": ("im = image(np.random.rand(100), (10, 10, 1)); im.SetDirectionMatrix(1, 0, 0, 0, 0.6, -0.8, 0, 0.8, 0.6)\n"
                     "ms = MorseSmaleComplex(Input=producer(im))", "direction matrix is not the identity"),
    "origin far from the data": ("im = image(np.random.rand(100), (10, 10, 1)); im.SetOrigin(1e15, 0, 0)\n"
                                 "ms = MorseSmaleComplex(Input=producer(im))", "more than 1e12 spacings"),
    "extreme anisotropy": ("im = image(np.random.rand(100), (10, 10, 1)); im.SetSpacing(1, 1e5, 1)\n"
                           "ms = MorseSmaleComplex(Input=producer(im))", "differ by a factor above 1e4"),
    "bow-tie vertex": ("ms = MorseSmaleComplex(Input=producer(mesh([(0, 0), (1, 0), (0, 1), (-1, 0), (0, -1)], "
                       "[(0, 1, 2), (0, 3, 4)], np.random.rand(5))))", "bow-tie"),
    "two grids sharing a corner": ("p1, t1 = grid_mesh(4, 4)\np2, t2 = grid_mesh(4, 4, 3, 3)\n"
                                   "ms = MorseSmaleComplex(Input=producer(mesh(p1 + p2[1:], t1 + [tuple(15 + v for v in t) for t in t2], "
                                   "np.random.rand(31))))", "bow-tie"),
    "zero-area triangle": ("ms = MorseSmaleComplex(Input=producer(mesh([(0, 0), (1, 0), (2, 0), (1, 1)], "
                           "[(0, 1, 3), (1, 2, 3), (0, 2, 1)], np.random.rand(4))))", "zero area"),
    "folded triangles": ("ms = MorseSmaleComplex(Input=producer(mesh([(0, 0), (2, 0), (1, 1), (1, 2)], "
                         "[(0, 1, 2), (0, 1, 3)], np.random.rand(4))))", "folds over"),
    "two separate grids": ("p1, t1 = grid_mesh(3, 3)\np2, t2 = grid_mesh(3, 3, 10, 0)\n"
                           "ms = MorseSmaleComplex(Input=producer(mesh(p1 + p2, t1 + [tuple(v + 9 for v in t) for t in t2], "
                           "np.random.rand(18))))", "2 separate pieces"),
    "multiblock input": ("ms = MorseSmaleComplex(Input=GroupDatasets(Input=[TrigonometricField()]))",
                         "the input is a composite data set"),
    "simplify input is not a complex": ("s = SimplifyMorseSmaleComplex(Input=GroupDatasets(Input=[TrigonometricField()]))\n"
                                        "ms = s", "not a Morse-Smale complex"),
    "curve segments below 2": ("ms = Smooth1Cells(Input=MorseSmaleComplex(Input=TrigonometricField()), CurveSegments=1)",
                               "Curve Segments must be in [2, 30]"),
    "curve segments absurd": ("ms = Smooth1Cells(Input=MorseSmaleComplex(Input=TrigonometricField()), CurveSegments=100000)",
                              "Curve Segments must be in [2, 30]"),
    "smoothing input is not a complex": ("ms = Smooth1Cells(Input=GroupDatasets(Input=[TrigonometricField()]))",
                                         "not a Morse-Smale complex"),
}
# Stage 4 and the one-step filter: their first output is a data set; bad input leaves it empty.
RECONSTRUCTION_EPILOGUE = """
ms.UpdatePipeline()
out = sm.Fetch(ms)
print("POINTS", out.GetNumberOfPoints())
"""
SMOOTHED = "sm1 = Smooth1Cells(Input=SimplifyMorseSmaleComplex(Input=MorseSmaleComplex(Input=TrigonometricField())))\n"
RECONSTRUCTION_CASES = {
    "reconstruction input not smoothed": ("ms = Reconstruct2Cells(Input=SimplifyMorseSmaleComplex("
                                          "Input=MorseSmaleComplex(Input=TrigonometricField())))",
                                          "no smoothed 1-cells", 0),
    "reconstruction input is not a complex": ("ms = Reconstruct2Cells(Input=GroupDatasets(Input=[TrigonometricField()]))",
                                              "not a Morse-Smale complex", 0),
    "boundary samples 0": (SMOOTHED + "ms = Reconstruct2Cells(Input=sm1, BoundarySamples=0)",
                           "Boundary Samples must be in [1, 1000]", 0),
    "output resolution absurd": (SMOOTHED + "ms = Reconstruct2Cells(Input=sm1, OutputResolution=1000)",
                                 "Output Resolution must be in [1, 16]", 0),
    # Memory-hungry settings are refused with the estimate (the limit set for this run only:
    # the machine's own memory would need a huge input): by the count of 2-cells and finer
    # points up front, and by the surfaces' grid sizes once those are known.
    "over the memory limit up front": ("import os; os.environ['TOPOSPLINE_MEMORY_LIMIT'] = '1e6'\n" + SMOOTHED +
                                       "ms = Reconstruct2Cells(Input=sm1, OutputResolution=16)",
                                       "GB available", 0),
    "one step on a 3D image": ("ms = TopoSplineReconstruction(Input=Wavelet())", "the image is 3D", 0),
    "one step with NaN values": ("v = np.random.rand(100); v[3] = np.nan\n"
                                 "ms = TopoSplineReconstruction(Input=producer(image(v, (10, 10, 1))))", "non-finite", 0),
    # Not errors, but must neither crash nor hang: a plateau and a tiny noisy field.
    "plateau through all stages": ("ms = TopoSplineReconstruction(Input=producer(image(np.r_[np.zeros(60), "
                                   "np.random.rand(40)], (10, 10, 1))), PersistenceThreshold=0)", "", None),
    "tiny noise field through all stages": ("ms = TopoSplineReconstruction(Input=producer(image(np.random.rand(16), "
                                            "(4, 4, 1))), PersistenceThreshold=0)", "", None),
}
# Not an error: a stale or mistyped array name falls back to the active scalars, with a warning.
FALLBACKS = {
    "missing array name": ("ms = MorseSmaleComplex(Input=TrigonometricField())\n"
                           "ms.ScalarField = ['POINTS', 'doesnotexist']",
                           'point array "doesnotexist" not found; using "Trigonometric"'),
}

def run(name, body, expected, blocks):
    result = subprocess.run(["pvpython", "--force-offscreen-rendering", "-c", PRELUDE + body + EPILOGUE],
                            capture_output=True, text=True, timeout=300)
    output = result.stdout + result.stderr
    checks.equal(result.returncode, 0, "%s: exits cleanly (output: %s)" % (name, output[-500:]))
    checks.check(expected in output, "%s: message contains %r (output: %s)" % (name, expected, output[-500:]))
    checks.check("BLOCKS %d" % blocks in output, "%s: %d output blocks" % (name, blocks))


for name, (body, expected) in CASES.items():
    run(name, body, expected, 0)
for name, (body, expected) in FALLBACKS.items():
    run(name, body, expected, 4)
for name, (body, expected, points) in RECONSTRUCTION_CASES.items():
    result = subprocess.run(["pvpython", "--force-offscreen-rendering", "-c", PRELUDE + body + RECONSTRUCTION_EPILOGUE],
                            capture_output=True, text=True, timeout=300)
    output = result.stdout + result.stderr
    checks.equal(result.returncode, 0, "%s: exits cleanly (output: %s)" % (name, output[-500:]))
    checks.check(expected in output, "%s: message contains %r (output: %s)" % (name, expected, output[-500:]))
    if points is not None:
        checks.check("POINTS %d" % points in output, "%s: empty output (%s)" % (name, output[-300:]))
    else:
        checks.check("POINTS 100" in output or "POINTS 16" in output, "%s: output on the input geometry" % name)

# The other side of the up-front refusal: a run the estimate says fits is not refused. 100 x 100
# uniform noise at 5 % has about 5000 2-cells, and stage 4 holds about 7 kB per such cell (35 MB,
# docs/Reconstruction.md); with 100 MB counted as available the estimate (800 bytes per vertex,
# 6.5 kB per cell: 40 MB) stays below the 80 MB it may use. The estimate of 30 kB per cell that
# it replaced (150 MB) refused this run.
FITTING = ("import os; os.environ['TOPOSPLINE_MEMORY_LIMIT'] = '1e8'\n"
           "ms = Reconstruct2Cells(Input=Smooth1Cells(Input=SimplifyMorseSmaleComplex(Input=MorseSmaleComplex("
           "Input=producer(image(np.random.default_rng(5).uniform(0, 1, 10000), (100, 100, 1)))), "
           "PersistenceThreshold=5)))")
result = subprocess.run(["pvpython", "--force-offscreen-rendering", "-c", PRELUDE + FITTING + RECONSTRUCTION_EPILOGUE],
                        capture_output=True, text=True, timeout=300)
output = result.stdout + result.stderr
checks.equal(result.returncode, 0, "within the memory limit: exits cleanly (output: %s)" % output[-500:])
checks.check("GB available" not in output, "within the memory limit: not refused (output: %s)" % output[-500:])
checks.check("POINTS 10000" in output, "within the memory limit: output on the input geometry (%s)" % output[-300:])
checks.finish()
