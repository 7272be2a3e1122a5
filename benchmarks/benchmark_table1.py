"""The paper's Table 1 through ParaView, and a scaling series, run on demand (not in CI).

Table 1: Trigo 100 x 100 (0 %, k = 4), Shepard 250 x 250 (25 %, k = 4 and 7), Mt Rainier
458 x 306 (2 %, k = 7), in the paper's layout (#faces, #V, simplification, #CP, #2-cells, k,
time I = 1-cell smoothing, time II = Delaunay + parameterization, time III = geometry,
# Bezier patches) with the paper's total beside ours (I + II + III, as in the paper) and the
speed-up, plus our whole pipeline (stages 1-4 with evaluation at every vertex, topology check
off) and the peak memory of the process. Scaling: Shepard 250^2, 500^2, 1000^2 (25 %, k = 4)
and the 2000 x 2000 terrain argudo_glaciers_sthelens_10m.vti at 2 % (k = 4), end to end.

Every case runs in its own pvpython process so that its peak memory is its own. STDThread on
2 threads. Prints figures only.

Usage: pvpython benchmarks/benchmark_table1.py   (after scripts/build.sh)"""
import json
import os
import resource
import subprocess
import sys
import time

CASE = os.environ.get("TOPOSPLINE_BENCHMARK_CASE")
PAPER_TOTAL = {"trigo": 2.25, "shepard4": 9.71, "shepard7": 9.32, "rainier": 12.11}

if CASE:
    from paraview.simple import *
    from paraview import servermanager as sm

    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import benchmark_common

    benchmark_common.start(globals())
    spec = json.loads(CASE)
    if spec["input"] == "trigo":
        source = TrigonometricField()
    elif spec["input"].startswith("shepard"):
        source = ShepardField(Resolution=spec.get("resolution", 250))
    else:
        source = XMLImageDataReader(FileName=[benchmark_common.data_file(spec["input"])])
    times = {}

    def run(name, proxy):
        start = time.perf_counter()
        proxy.UpdatePipeline()
        times[name] = time.perf_counter() - start

    run("input", source)
    ms = MorseSmaleComplex(Input=source)
    run("1", ms)
    simplified = SimplifyMorseSmaleComplex(Input=ms, PersistenceThreshold=spec["percent"])
    run("2", simplified)
    smooth = Smooth1Cells(Input=simplified, CurveSegments=spec["k"])
    run("I", smooth)
    reconstruct = Reconstruct2Cells(Input=smooth, VerifyTopology=0, Interior=spec.get("interior", 1))
    run("4", reconstruct)
    complex_data = sm.Fetch(simplified)
    out = sm.Fetch(reconstruct)
    fd = out.GetFieldData()
    number = lambda name: fd.GetArray(name).GetValue(0)
    info = source.GetDataInformation()
    result = {
        "faces": 2 * (info.DataInformation.GetExtent()[1]) * (info.DataInformation.GetExtent()[3])
        if info.GetNumberOfPoints() else 0,
        "vertices": info.GetNumberOfPoints(),
        "cp": complex_data.GetBlock(0).GetNumberOfPoints(),
        "two_cells": int(number("TwoCells")),
        "failed": int(number("FailedTwoCells")),
        "I": times["I"], "II": number("ParameterizationSeconds"), "III": number("SurfaceSeconds"),
        "stage4": times["4"], "pipeline": times["1"] + times["2"] + times["I"] + times["4"],
        "patches": int(number("BezierTriangles")),
        "rms_percent": 100 * number("RMSError") / (fd.GetArray("ValueRange").GetValue(1) -
                                                   fd.GetArray("ValueRange").GetValue(0)),
        "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
    }
    print("RESULT " + json.dumps(result), flush=True)
    sys.exit(0)


def run_case(spec):
    env = dict(os.environ, TOPOSPLINE_BENCHMARK_CASE=json.dumps(spec))
    env = {k: v for k, v in env.items() if not k.startswith(("OMPI_", "PMIX_"))}
    out = subprocess.run([sys.executable if "pvpython" in sys.executable else "pvpython", os.path.abspath(__file__)],
                         env=env, capture_output=True, text=True)
    for line in out.stdout.splitlines():
        if line.startswith("RESULT "):
            return json.loads(line[7:])
    print("case %s failed:\n%s" % (spec, out.stderr[-2000:]))
    return None


print("Table 1 (paper layout). Times in seconds; paper: Xeon W3520 (2009); ours: STDThread, 2 threads.")
print("%-22s %7s %7s %5s %5s %7s %2s %7s %7s %7s %8s %8s %8s %8s %9s %8s" % (
    "input", "#faces", "#V", "simp", "#CP", "#2cells", "k", "time I", "time II", "time III", "#patches",
    "I+II+III", "paper", "speed-up", "pipeline", "peak MB"))
table = [("Trigo 100x100", {"input": "trigo", "percent": 0, "k": 4}, "trigo"),
         ("Shepard 250x250", {"input": "shepard", "percent": 25, "k": 4}, "shepard4"),
         ("Shepard 250x250", {"input": "shepard", "percent": 25, "k": 7}, "shepard7"),
         ("MtRainier 458x306", {"input": "rainier_ned1_1970_crop458x306.vti", "percent": 2, "k": 7}, "rainier")]
rows = []
for interior, title in ((0, "the paper's (boundary only): Table 1 as the paper defines it"),
                        (1, "fitted to the data (the default)")):
    rows.append((None, title, None))
    rows += [(label, dict(spec, interior=interior), key) for label, spec, key in table]
for label, spec, key in rows:
    if label is None:
        print("-- 2-cell interiors: " + spec)
        continue
    r = run_case(spec)
    if not r:
        continue
    ours = r["I"] + r["II"] + r["III"]
    print("%-22s %7d %7d %4g%% %5d %7d %2d %7.3f %7.3f %8.3f %8d %8.3f %8.2f %7.0fx %9.3f %8.0f" % (
        label, r["faces"], r["vertices"], spec["percent"], r["cp"], r["two_cells"], spec["k"], r["I"], r["II"],
        r["III"], r["patches"], ours, PAPER_TOTAL[key], PAPER_TOTAL[key] / ours, r["pipeline"], r["peak_mb"]) +
        "  RMS %.2f %% of the range" % r["rms_percent"])
    if r["failed"]:
        print("   (%d 2-cells not reconstructed)" % r["failed"])

print()
print("Scaling, end to end (stages 1-4, topology check off, fitted interiors), STDThread, 2 threads")
print("%-40s %9s %6s %8s %8s %8s %8s %9s %8s" % ("input", "#V", "#CP", "time I", "time II", "time III",
                                                 "stage 4", "pipeline", "peak MB"))
series = [("Shepard 250^2, 25%, k=4", {"input": "shepard", "resolution": 250, "percent": 25, "k": 4}),
          ("Shepard 500^2, 25%, k=4", {"input": "shepard", "resolution": 500, "percent": 25, "k": 4}),
          ("Shepard 1000^2, 25%, k=4", {"input": "shepard", "resolution": 1000, "percent": 25, "k": 4})]
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from benchmark_common import data_file  # noqa: E402

if data_file("argudo_glaciers_sthelens_10m.vti"):
    series.append(("argudo 2000^2, 2%, k=4", {"input": "argudo_glaciers_sthelens_10m.vti", "percent": 2, "k": 4}))
else:
    print("skip argudo_glaciers_sthelens_10m.vti: absent")
for label, spec in series:
    r = run_case(spec)
    if r:
        print("%-40s %9d %6d %8.3f %8.3f %8.3f %8.3f %9.3f %8.0f%s" % (
            label, r["vertices"], r["cp"], r["I"], r["II"], r["III"], r["stage4"], r["pipeline"], r["peak_mb"],
            "  (%d 2-cells failed)" % r["failed"] if r["failed"] else ""))
