"""Fingerprint of every output of every stage, for refactorings that must not change results.

    pvpython scripts/output_fingerprint.py > before.txt   # (TOPOSPLINE_PLUGIN selects the plugin)
    ... change, rebuild ...
    pvpython scripts/output_fingerprint.py > after.txt && diff before.txt after.txt

Each line is one array of one block of one output port: the case, the stage, the block, the
array name and a SHA-1 of its bytes (points and cell connectivity included), so any change of
any value, however small, shows. The cases cover both synthetic fields, a catalog crop, a
triangle mesh and a noise field, through the four filters and the one-step filter."""
import hashlib
import os
import sys

import numpy as np
from paraview import servermanager as sm
from paraview.simple import *  # noqa: F401,F403
import paraview.simple as ps
from vtkmodules.util.numpy_support import vtk_to_numpy

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "tests", "python"))
import topospline_testing as tt  # noqa: E402

ps.LoadPlugin(tt.plugin_path(), remote=False, ns=globals())


def digest(array):
    return hashlib.sha1(np.ascontiguousarray(array).tobytes()).hexdigest()[:16]


def dataset_lines(prefix, data):
    lines = []
    if data is None:
        return [prefix + " None"]
    if data.IsA("vtkMultiBlockDataSet"):
        for b in range(data.GetNumberOfBlocks()):
            lines += dataset_lines("%s/block%d" % (prefix, b), data.GetBlock(b))
        return lines
    lines.append("%s class=%s" % (prefix, data.GetClassName()))
    if data.IsA("vtkPointSet") and data.GetPoints() is not None:
        lines.append("%s points %s" % (prefix, digest(vtk_to_numpy(data.GetPoints().GetData()))))
    if data.IsA("vtkPolyData"):
        for kind in ("GetVerts", "GetLines", "GetPolys"):
            cells = getattr(data, kind)()
            lines.append("%s %s %s %s" % (prefix, kind, digest(vtk_to_numpy(cells.GetOffsetsArray())),
                                          digest(vtk_to_numpy(cells.GetConnectivityArray()))))
    if data.IsA("vtkUnstructuredGrid") and data.GetCells() is not None:
        lines.append("%s cells %s" % (prefix, digest(vtk_to_numpy(data.GetCells().GetConnectivityArray()))))
    if data.IsA("vtkImageData"):
        lines.append("%s image %s %s %s" % (prefix, data.GetExtent(), data.GetOrigin(), data.GetSpacing()))
    for where, fd in (("point", data.GetPointData()), ("cell", data.GetCellData()), ("field", data.GetFieldData())):
        for i in range(fd.GetNumberOfArrays()):
            array = fd.GetAbstractArray(i)
            if array.GetName().endswith("Seconds"):  # timings differ from run to run
                lines.append("%s %s %s (timing)" % (prefix, where, array.GetName()))
                continue
            if array.IsA("vtkDataArray"):
                values = vtk_to_numpy(array)
            else:
                values = np.array([array.GetValue(j) for j in range(array.GetNumberOfValues())], dtype=str)
            lines.append("%s %s %s %s" % (prefix, where, array.GetName(), digest(values)))
    return lines


def outputs(label, proxy):
    proxy.UpdatePipeline()
    algorithm = proxy.GetClientSideObject()
    lines = []
    for port in range(algorithm.GetNumberOfOutputPorts()):
        lines += dataset_lines("%s port%d" % (label, port), algorithm.GetOutputDataObject(port))
    return lines


def mesh_of(source):
    return Triangulate(Input=ExtractSurface(Input=source))


def cases():
    yield "shepard", ShepardField(), "Shepard", (5, 25), (4,)
    yield "trig", TrigonometricField(), "Trigonometric", (0, 25), (4, 7)
    yield "trig-mesh", mesh_of(TrigonometricField()), "Trigonometric", (5,), (4,)
    rainier = tt.find_dataset("rainier_ned1_1970_crop458x306.vti")
    if rainier:
        reader = XMLImageDataReader(FileName=[rainier])
        yield "rainier", reader, reader.PointData.keys()[0], (2,), (7,)
    noise = PVTrivialProducer()
    noise.GetClientSideObject().SetOutput(tt.image_data(np.random.default_rng(7).uniform(0, 1, (30, 30))))
    yield "noise30", noise, "f", (5,), (4,)


for name, source, array, thresholds, ks in cases():
    ms = MorseSmaleComplex(Input=source, ScalarField=["POINTS", array])
    for line in outputs(name + " stage1", ms):
        print(line)
    for t in thresholds:
        simplified = SimplifyMorseSmaleComplex(Input=ms, PersistenceThreshold=t)
        for line in outputs("%s %g%% stage2" % (name, t), simplified):
            print(line)
        for k in ks:
            smooth = Smooth1Cells(Input=simplified, CurveSegments=k)
            for line in outputs("%s %g%% k%d stage3" % (name, t, k), smooth):
                print(line)
            rec = Reconstruct2Cells(Input=smooth, OutputResolution=2)
            for line in outputs("%s %g%% k%d stage4" % (name, t, k), rec):
                print(line)
    one = TopoSplineReconstruction(Input=source, ScalarField=["POINTS", array],
                                   PersistenceThreshold=thresholds[-1], CurveSegments=ks[0])
    for line in outputs("%s one-step" % name, one):
        print(line)
