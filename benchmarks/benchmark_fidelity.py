"""How close the reconstruction stays to the data, run on demand (not in CI).

Per data set and threshold, for the fitted 2-cell interiors (the default) and the paper's
boundary-only ones: the errors of "Reconstructed" against the input (L_inf in units of
eps = threshold x range, and in % of the range; RMS in % of the range), the L_inf of
"ReconstructedExact" (F o Phi itself), the spurious critical points of F o Phi at the input
vertices within two grid spacings of a smoothed 1-cell and farther, the share of vertices that
topological sampling changed and its largest change, the topology verdict, and the time of
stage 4 and of the whole pipeline.

Inputs: the Trigonometric Field at 0 %; Shepard fields (250^2, 50 sites) of seeds 0-9 at 5 and
25 %; every DEM shipped in tests/data at 2 and 5 %. k = 4, except the Rainier crop (k = 7, the
paper's). STDThread on 2 threads.

Usage: pvpython benchmarks/benchmark_fidelity.py [--quick] [--json FILE]
  --quick: Shepard seeds 0-3 only."""
import json
import os
import sys
import time

from paraview.simple import *
from paraview import servermanager as sm

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchmark_common

benchmark_common.start(globals())
QUICK = "--quick" in sys.argv
JSON = sys.argv[sys.argv.index("--json") + 1] if "--json" in sys.argv else None

DEMS = ["r_volcano_maunga_whau.vti", "rainier_ned1_1970_crop458x306.vti", "sainthelens_usgs_dem_crop.vti",
        "msh_crater_2007_10m.vti", "ttk_happi_tas_anomaly.vti"]


def cases():
    yield "Trigonometric", lambda: TrigonometricField(), 0, 4
    for seed in range(4 if QUICK else 10):
        for percent in (5, 25):
            yield "Shepard seed %d" % seed, (lambda s=seed: ShepardField(Seed=s)), percent, 4
    for name in DEMS:
        path = benchmark_common.data_file(name)
        if path is None:
            print("skip %s: not found" % name)
            continue
        for percent in (2, 5):
            yield name.replace(".vti", ""), (lambda p=path: XMLImageDataReader(FileName=[p])), percent, \
                7 if name.startswith("rainier") else 4


def number(fd, name, default=float("nan")):
    array = fd.GetArray(name)
    return array.GetValue(0) if array is not None else default


def run(make_source, percent, k, interior):
    source = make_source()
    source.UpdatePipeline()
    start = time.perf_counter()
    ms = MorseSmaleComplex(Input=source)
    simplified = SimplifyMorseSmaleComplex(Input=ms, PersistenceThreshold=percent)
    smooth = Smooth1Cells(Input=simplified, CurveSegments=k)
    smooth.UpdatePipeline()
    stage4_start = time.perf_counter()
    reconstruct = Reconstruct2Cells(Input=smooth, Interior=interior)
    reconstruct.UpdatePipeline()
    end = time.perf_counter()
    out = sm.Fetch(reconstruct)
    fd = out.GetFieldData()
    pd = out.GetPointData()
    low, high = number(fd, "ValueRange"), fd.GetArray("ValueRange").GetValue(1)
    span = high - low
    exact = pd.GetArray("ReconstructedExact")
    difference = pd.GetArray("Difference")
    values = pd.GetArray("Reconstructed")
    # L_inf of F o Phi: Reconstructed - Difference is the input.
    exact_error = 0.0
    if exact is not None:
        for i in range(out.GetNumberOfPoints()):
            data = values.GetValue(i) - difference.GetValue(i)
            exact_error = max(exact_error, abs(exact.GetValue(i) - data))
    points = out.GetNumberOfPoints()
    result = {
        "linf_range": 100 * number(fd, "MaximumError") / span,
        "rms_range": 100 * number(fd, "RMSError") / span,
        "exact_linf_range": 100 * exact_error / span,
        "near": number(fd, "RawSpuriousNearOneCells"),
        "far": number(fd, "RawSpuriousFarFromOneCells"),
        "repaired": 100 * number(fd, "SamplingChangedVertices", 0) / points,
        "repair_max_range": 100 * number(fd, "SamplingMaximumChange", 0) / span,
        "verified": number(fd, "TopologyVerified"),
        "fitted": number(fd, "FittedCells", 0),
        "cells": number(fd, "TwoCells", float("nan")),
        "stage4_s": end - stage4_start,
        "total_s": end - start,
    }
    result["linf_eps"] = result["linf_range"] / percent if percent > 0 else float("nan")
    for proxy in (reconstruct, smooth, simplified, ms, source):
        Delete(proxy)
    return result


header = ("%-34s %5s %-6s %8s %7s %7s %7s %5s %5s %7s %7s %3s %6s %6s" %
          ("input", "thr", "inter.", "Linf/eps", "Linf%R", "RMS%R", "FoPhi%R", "near", "far", "repair%",
           "rep.%R", "ok", "st4 s", "tot s"))
print(header)
records = []
for name, make, percent, k in cases():
    for interior, label in ((1, "fitted"), (0, "paper")):
        r = run(make, percent, k, interior)
        r.update({"input": name, "percent": percent, "k": k, "interior": label})
        records.append(r)
        print("%-34s %4g%% %-6s %8.2f %7.2f %7.2f %7.2f %5d %5d %7.2f %7.2f %3d %6.2f %6.2f" %
              ("%s (k=%d)" % (name, k), percent, label, r["linf_eps"], r["linf_range"], r["rms_range"],
               r["exact_linf_range"], r["near"], r["far"], r["repaired"], r["repair_max_range"], r["verified"],
               r["stage4_s"], r["total_s"]), flush=True)
if JSON:
    with open(JSON, "w") as f:
        json.dump(records, f, indent=1)
