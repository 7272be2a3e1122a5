"""Stage 1 through ParaView: the complex of the synthetic fields and of every terrain, its
invariants, agreement with independent PL counts, and image data == the same triangle mesh."""
import numpy as np
from paraview.simple import *
from paraview import servermanager as sm
from vtkmodules.numpy_interface import dataset_adapter as dsa
from vtkmodules.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray
from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData, vtkUnstructuredGrid, VTK_TRIANGLE
from vtkmodules.vtkCommonCore import vtkPoints

import topospline_testing as tt

LoadPlugin(tt.plugin_path(), remote=False, ns=globals())
checks = tt.Checks()

# The paper's trigonometric field. The paper reports 8 minima, 15 saddles and 8 maxima; with
# a boundary made of 1-cells (every 2-cell closed), every extremum of the field along the
# boundary curve is a critical point too, so the complex has 18 / 27 / 10, of which exactly
# the paper's interior 8 minima, 9 saddles and 8 maxima lie inside the domain.
trig = tt.fetch_complex(MorseSmaleComplex(Input=TrigonometricField()))
tt.check_complex(checks, trig, "trig")
checks.equal(trig["blocks"], ["CriticalPoints", "OneCells", "TwoCells", "Segmentation"], "block names")
checks.equal(tt.counts(trig), [18, 27, 10], "trig: critical points by index")
checks.equal(tt.interior_counts(trig), [8, 9, 8], "trig: interior critical points by index")
checks.equal(trig["cp_VertexId"][trig["cp_CriticalIndex"] == 0].tolist().count(0), 1, "trig: corner minimum")

for seed in (1, 2, 3, 4, 5):
    c = tt.fetch_complex(MorseSmaleComplex(Input=ShepardField(Seed=seed)))
    tt.check_complex(checks, c, "shepard seed %d" % seed)
    checks.check(tt.counts(c)[0] + tt.counts(c)[2] >= 50 - 5,
                 "shepard seed %d: the 50 sites are (nearly all) extrema: %s" % (seed, tt.counts(c)))

# Every data set of the catalog: invariants, and interior critical points equal to the
# catalog's independent PL counts (same triangulation, ties by point id).
for entry in tt.catalog():
    path = tt.find_dataset(entry["file"])
    if path is None:
        checks.skip("%s: file absent (large data sets live in ../shared/data)" % entry["file"])
        continue
    reader = XMLImageDataReader(FileName=[path])
    ms = MorseSmaleComplex(Input=reader)
    ms.ScalarField = ["POINTS", "elevation"]
    c = tt.fetch_complex(ms)
    tt.check_complex(checks, c, entry["name"])
    pl = entry["pl_critical_points"]
    inner = tt.interior_counts(c)
    checks.equal(inner[0], pl["interior_minima"], "%s: interior minima vs catalog" % entry["name"])
    checks.equal(inner[2], pl["interior_maxima"], "%s: interior maxima vs catalog" % entry["name"])
    checks.equal(inner[1], pl["interior_saddles"], "%s: interior saddles vs catalog" % entry["name"])
    print("%s: %s critical points (interior %s)" % (entry["name"], tt.counts(c), inner), flush=True)
    Delete(ms)
    Delete(reader)


def as_mesh(image_proxy, kind):
    """The image's grid as an explicit triangle mesh with the same diagonal split."""
    image_proxy.UpdatePipeline()
    image = sm.Fetch(image_proxy)
    nx, ny, _ = image.GetDimensions()
    points = vtkPoints()
    points.SetData(numpy_to_vtk(np.array([image.GetPoint(i) for i in range(image.GetNumberOfPoints())]), deep=1))
    i, j = np.meshgrid(np.arange(nx - 1), np.arange(ny - 1))
    p00 = (j * nx + i).ravel()
    # Same order as the filter's own split of the image: both triangles of a quad in turn.
    tris = np.stack([p00, p00 + 1, p00 + nx, p00 + 1, p00 + nx + 1, p00 + nx], 1).reshape(-1, 3)
    cells = vtkCellArray()
    cells.SetData(numpy_to_vtkIdTypeArray(np.arange(0, 3 * len(tris) + 1, 3, dtype=np.int64), deep=1),
                  numpy_to_vtkIdTypeArray(tris.astype(np.int64).ravel(), deep=1))
    if kind == "poly":
        mesh = vtkPolyData()
        mesh.SetPoints(points)
        mesh.SetPolys(cells)
    else:
        mesh = vtkUnstructuredGrid()
        mesh.SetPoints(points)
        mesh.SetCells(VTK_TRIANGLE, cells)
    mesh.GetPointData().AddArray(image.GetPointData().GetArray(0))
    producer = TrivialProducer()
    producer.GetClientSideObject().SetOutput(mesh)
    return producer


for name, source in (("trig", TrigonometricField()), ("shepard", ShepardField(Resolution=120, Seed=9))):
    source.UpdatePipeline()  # so that ParaView picks the source's array as the default
    reference = tt.fetch_complex(MorseSmaleComplex(Input=source))
    for kind in ("poly", "unstructured"):
        other = tt.fetch_complex(MorseSmaleComplex(Input=as_mesh(source, kind)))
        if not checks.check(other is not None, "%s as %s mesh: complex computed" % (name, kind)):
            continue
        for key in ("cp_VertexId", "cp_CriticalIndex", "arc_SourceId", "arc_DestinationId", "seg_TwoCellId",
                    "seg_AscendingManifoldId", "cell_SaddleIds"):
            checks.check(np.array_equal(reference[key], other[key]), "%s: image == %s mesh (%s)" % (name, kind, key))
        checks.check(all(np.array_equal(a, b) for a, b in zip(reference["arc_points"], other["arc_points"])),
                     "%s: image == %s mesh (1-cell geometry)" % (name, kind))

checks.finish()
