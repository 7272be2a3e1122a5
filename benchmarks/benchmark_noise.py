"""Uniform noise end to end: the input simplification exists for. Seeded uniform noise of
n x n samples (default 1000) at a threshold (default 5 %) through the four filters, each in its
own pvpython process so that the peak resident memory (ru_maxrss of that child, from wait4) is
that run's.
Prints, per size: time per stage, peak memory, the memory still resident at the end, the
simplified counts, the topology verdict, failed 2-cells, unreconstructed vertices, the critical
points the verdict found missing and spurious, and the spare saddles topological sampling walked
onto their nodes; errors are printed, not hidden.

Usage: pvpython benchmarks/benchmark_noise.py [n ...] [--threshold P] [--k K]"""
import json
import os
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))

CHILD = r"""
import json, sys, time
import numpy as np
sys.path.insert(0, %(here)r)
import benchmark_common
from paraview import servermanager as sm
from paraview.simple import TrivialProducer
from vtkmodules.util.numpy_support import numpy_to_vtk
from vtkmodules.vtkCommonDataModel import vtkImageData
benchmark_common.start(globals())
ns = globals()
n, percent, k = %(n)d, %(percent)r, %(k)d
image = vtkImageData()
image.SetDimensions(n, n, 1)
values = np.random.default_rng(2026).uniform(0, 1, n * n)
array = numpy_to_vtk(values, deep=1)
array.SetName("f")
image.GetPointData().AddArray(array)
source = TrivialProducer()
source.GetClientSideObject().SetOutput(image)
times = {}
ms = ns["MorseSmaleComplex"](Input=source)
ms.ScalarField = ["POINTS", "f"]
stages = [("complex", ms)]
stages.append(("simplify", ns["SimplifyMorseSmaleComplex"](Input=ms, PersistenceThreshold=percent)))
stages.append(("smooth", ns["Smooth1Cells"](Input=stages[-1][1], CurveSegments=k)))
stages.append(("reconstruct", ns["Reconstruct2Cells"](Input=stages[-1][1])))
for name, proxy in stages:
    start = time.time()
    proxy.UpdatePipeline()
    times[name] = time.time() - start
out = stages[-1][1].GetClientSideObject().GetOutputDataObject(0)
fd = out.GetFieldData()
def number(name, i=0):
    a = fd.GetArray(name)
    return a.GetValue(i) if a is not None and a.GetNumberOfTuples() > i else None
complex_ = stages[1][1].GetClientSideObject().GetOutputDataObject(0)
counts = None
if complex_.GetNumberOfBlocks() > 0 and complex_.GetBlock(0) is not None:
    index = complex_.GetBlock(0).GetPointData().GetArray("CriticalIndex")
    if index is not None:
        values = [int(index.GetValue(i)) for i in range(index.GetNumberOfTuples())]
        counts = [values.count(0), values.count(1), values.count(2)]
# What the process still holds once the pipeline has run (its outputs and what the allocator kept).
resident = next(int(line.split()[1]) / 1e6 for line in open("/proc/self/status") if line.startswith("VmRSS"))
def tuples(name):
    a = fd.GetArray(name)
    return a.GetNumberOfTuples() if a is not None else None
print("RESULT " + json.dumps({"times": times, "resident": resident, "counts": counts, "verdict": number("TopologyVerified"),
                              "failed": number("FailedTwoCells"), "unreconstructed": number("UnreconstructedPoints"),
                              "missing": tuples("MissingCriticalPoints"), "spurious": tuples("SpuriousCriticalPoints"),
                              "walked": number("SamplingWalkedSaddles")}))
"""


def main():
    args = sys.argv[1:]
    percent, k = 5.0, 4
    if "--threshold" in args:
        i = args.index("--threshold")
        percent = float(args[i + 1])
        del args[i:i + 2]
    if "--k" in args:
        i = args.index("--k")
        k = int(args[i + 1])
        del args[i:i + 2]
    sizes = [int(a) for a in args] or [1000]
    print("uniform noise (seed 2026), threshold %g %%, k = %d, 2 STDThread threads" % (percent, k))
    print("| n x n | complex s | simplify s | smooth s | reconstruct s | total s | peak GB | resident after GB | min/saddle/max "
          "| verdict | failed 2-cells | unreconstructed | missing / spurious critical points | saddles walked |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for n in sizes:
        start = time.time()
        with tempfile.TemporaryFile("w+") as out, tempfile.TemporaryFile("w+") as err:
            child = subprocess.Popen(["pvpython", "-c", CHILD % {"here": HERE, "n": n, "percent": percent, "k": k}],
                                     stdout=out, stderr=err, text=True)
            # This child's own peak (RUSAGE_CHILDREN would give the largest child so far).
            _, status, usage = os.wait4(child.pid, 0)
            child.returncode = os.waitstatus_to_exitcode(status)
            out.seek(0)
            err.seek(0)
            stdout, stderr = out.read(), err.read()
        wall = time.time() - start
        peak = usage.ru_maxrss / 1e6  # kB -> GB
        result = next((json.loads(line[7:]) for line in stdout.splitlines() if line.startswith("RESULT ")), None)
        errors = [line.strip()[-200:] for line in (stdout + stderr).splitlines() if "ERR" in line]
        if result is None:
            print("| %d | run failed (exit %d, %.1f s): %s |" % (n, child.returncode, wall,
                                                                (errors or [stderr.strip()[-300:]])[0]))
            continue
        t = result["times"]
        print("| %d | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %s | %s | %s | %s | %s / %s | %s |" % (
            n, t["complex"], t["simplify"], t["smooth"], t["reconstruct"], sum(t.values()), peak, result["resident"],
            "/".join(map(str, result["counts"] or [])), result["verdict"], result["failed"], result["unreconstructed"],
            result.get("missing"), result.get("spurious"), result.get("walked")))
        for e in errors[:3]:
            print("    error: " + e)
        sys.stdout.flush()


main()
