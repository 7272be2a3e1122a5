"""Stage 4 on triangle meshes (vtkPolyData), where the finer image is not aligned with the input
vertices: both synthetic fields as a triangulated grid and as a triangulated irregular network
(the grid's interior points jittered by up to 0.3 spacing, Delaunay2D), at 2, 5 and 25 % with
k = 4 and 7, Output Resolution 4. Asserted on every run: every 2-cell reconstructed, the
sampled counts of minima, saddles and maxima exact at the input vertices and on the finer
image, and the topology verdict (every critical point within one spacing of its node), except
on listed misses (none now), which must still miss so that the list stays true."""
from paraview.simple import *

import topospline_testing as tt

LoadPlugin(tt.plugin_path(), remote=False, ns=globals())
checks = tt.Checks()

JITTER = """
import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy, numpy_to_vtk
from vtkmodules.vtkCommonCore import vtkPoints
source = self.GetInput()
out = self.GetOutput()
out.ShallowCopy(source)
p = vtk_to_numpy(source.GetPoints().GetData()).copy()
low, high = p[:, :2].min(0), p[:, :2].max(0)
inner = np.all((p[:, :2] > low + 1e-9) & (p[:, :2] < high - 1e-9), axis=1)
p[inner, :2] += np.random.default_rng(5).uniform(-0.3, 0.3, (int(inner.sum()), 2))
points = vtkPoints()
points.SetData(numpy_to_vtk(p, deep=1))
out.SetPoints(points)
"""

# Runs that still miss, each with its reason (docs/Reconstruction.md, "Triangle meshes"); each
# listed run must still miss, so that the list stays true. Empty since the floods spread the
# regions they re-value on meshes that are not images (Session 35): Shepard at 25 %, k = 7 on
# the irregular network kept spurious minimum-saddle pairs there, fills and cuts alternating
# between vertices of a flat spot whose tie-breaking ids are not ordered in space.
KNOWN_MISSES = {}


for field in ("trig", "shepard"):
    for mesh in ("grid", "irregular"):
        source = TrigonometricField() if field == "trig" else ShepardField()
        triangles = Triangulate(Input=ExtractSurface(Input=source))
        if mesh == "irregular":
            # (In builtin mode its script runs in this module's namespace and star-imports numpy:
            # module-level names such as "number" would be shadowed.)
            jittered = ProgrammableFilter(Input=triangles)
            jittered.Script = JITTER
            triangles = Delaunay2D(Input=jittered)
        ms = MorseSmaleComplex(Input=triangles, ScalarField=["POINTS", "Trigonometric" if field == "trig" else "Shepard"])
        for percent in (2, 5, 25):
            simplified = SimplifyMorseSmaleComplex(Input=ms, PersistenceThreshold=percent)
            for k in (4, 7):
                label = "%s %s %d%% k=%d" % (field, mesh, percent, k)
                smooth = Smooth1Cells(Input=simplified, CurveSegments=k)
                reconstruct = Reconstruct2Cells(Input=smooth, OutputResolution=4)
                reconstruct.UpdatePipeline()
                algorithm = reconstruct.GetClientSideObject()
                out = algorithm.GetOutputDataObject(0)
                fd = out.GetFieldData()
                checks.check(out.IsA("vtkPolyData"), "%s: the output keeps the input's type" % label)
                checks.check(algorithm.GetOutputDataObject(2).GetNumberOfPoints() > 4 * out.GetNumberOfPoints(),
                             "%s: the resampled image is finer" % label)
                checks.equal(tt.field_value(fd, "FailedTwoCells"), 0, "%s: every 2-cell reconstructed" % label)
                expected = [int(tt.field_value(fd, "ExpectedCriticalPoints", i)) for i in range(3)]
                found = [int(tt.field_value(fd, "InputCriticalPoints", i)) for i in range(3)]
                fine = [int(tt.field_value(fd, "ResampledCriticalPoints", i)) for i in range(3)]
                verdict = bool(tt.field_value(fd, "TopologyVerified"))
                print("%s: expected %s, at the input vertices %s, 4x %s, verdict %d"
                      % (label, expected, found, fine, verdict), flush=True)
                checks.equal(fine, expected, "%s: critical points of the 4x image" % label)
                if label in KNOWN_MISSES:
                    checks.check(not verdict, "%s: still a known miss (%s); if it now holds, take it off the list"
                                 % (label, KNOWN_MISSES[label]))
                else:
                    checks.equal(found, expected, "%s: critical points at the input vertices" % label)
                    checks.check(verdict, "%s: topology verified (counts and positions within one spacing)" % label)
                Delete(reconstruct)
                Delete(smooth)
            Delete(simplified)
checks.finish()
