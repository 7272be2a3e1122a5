"""How close the reconstruction stays to the data, run on demand (not in CI).

Per data set and threshold, for the fitted 2-cell interiors (the default) and the paper's
boundary-only ones: the errors of "Reconstructed" against the input (L_inf in units of
eps = threshold x range, and in % of the range; RMS in % of the range), the L_inf of
"ReconstructedExact" (F o Phi itself), the spurious critical points of F o Phi at the input
vertices within two grid spacings of a smoothed 1-cell and farther, the share of vertices that
topological sampling changed and its largest change, the topology verdict, and the time of
stage 4 and of the whole pipeline.

A yardstick written here, sharing no code with the plugin: the input flooded to the simplified
complex's extrema (priority-flood: every pit but a kept minimum filled to the level where it
spills, every peak but a kept maximum cut, alternately until nothing changes; the grid's own
triangulation, boundary vertices treated like the others). That is what TTK's
TopologicalSimplificationByPersistence does with the same extrema: a field with the simplified
extrema that changes the data only inside the cancelled features, by at most their persistence.
Its RMS ("flood RMS") tells how much of a reconstruction's error any such field has to make.

Inputs: the Trigonometric Field at 0 %; Shepard fields (250^2, 50 sites) of seeds 0-9 at 5 and
25 %; every DEM shipped in tests/data at 2 and 5 %. k = 4, except the Rainier crop (k = 7, the
paper's). STDThread on 2 threads.

Usage: pvpython benchmarks/benchmark_fidelity.py [--quick] [--seeds FIRST-LAST] [--crops N] [--fitted-only]
                                                 [--large] [--alternative-map-strength S] [--json FILE]
  --quick: Shepard seeds 0-3 only.
  --crops N: N seeded random crops (64-300 vertices a side) of every DEM found, at 2 and 5 %,
      k = 4, instead of the inputs above: the same measurements on terrain windows nothing was
      tuned on.
  --large: the catalog's two large DEMs too (the full Rainier DEM, 884 x 824, and the 2000 x 2000
      terrain), from ../shared/data, skipped with a message when absent; about 10 and 30 s per
      run, and the flood yardstick about a minute per threshold on the 2000 x 2000 terrain.
  --seeds FIRST-LAST: the Shepard fields of these seeds only (no Trigonometric Field, no DEMs):
      the same measurements on fields the tests and the tables above never saw.
  --fitted-only: the fitted interiors only (half the time).
  --alternative-map-strength S: stage 4's Alternative Map Strength (default: the filter's own;
      0: the mean value map everywhere)."""
import heapq
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
SEEDS = None
if "--seeds" in sys.argv:
    first, _, last = sys.argv[sys.argv.index("--seeds") + 1].partition("-")
    SEEDS = range(int(first), int(last or first) + 1)
FITTED_ONLY = "--fitted-only" in sys.argv
LARGE = "--large" in sys.argv
CROPS = int(sys.argv[sys.argv.index("--crops") + 1]) if "--crops" in sys.argv else 0
STRENGTH = (float(sys.argv[sys.argv.index("--alternative-map-strength") + 1])
            if "--alternative-map-strength" in sys.argv else None)

DEMS = ["r_volcano_maunga_whau.vti", "rainier_ned1_1970_crop458x306.vti", "sainthelens_usgs_dem_crop.vti",
        "msh_crater_2007_10m.vti", "ttk_happi_tas_anomaly.vti"]
LARGE_DEMS = ["rainier_ned1_1970_full.vti", "argudo_glaciers_sthelens_10m.vti"]


def crop_cases(count):
    """Seeded random crops of every DEM found (the large ones too), each at 2 and 5 %."""
    import random
    import numpy as np
    from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
    from vtkmodules.vtkCommonDataModel import vtkImageData
    from vtkmodules.vtkIOXML import vtkXMLImageDataReader
    grids = {}
    for name in DEMS + LARGE_DEMS:
        path = benchmark_common.data_file(name)
        if path is None:
            print("skip %s: not found" % name)
            continue
        reader = vtkXMLImageDataReader()
        reader.SetFileName(path)
        reader.Update()
        image = reader.GetOutput()
        nx, ny, _ = image.GetDimensions()
        array = image.GetPointData().GetScalars() or image.GetPointData().GetArray(0)
        grids[name] = (np.array(vtk_to_numpy(array), dtype=np.float64).reshape(ny, nx), image.GetSpacing())
    random_ = random.Random(2026)
    names = sorted(grids)
    for _ in range(count if names else 0):
        name = random_.choice(names)
        values, spacing = grids[name]
        ny, nx = values.shape
        w, h = random_.randint(min(64, nx), min(300, nx)), random_.randint(min(64, ny), min(300, ny))
        i0, j0 = random_.randint(0, nx - w), random_.randint(0, ny - h)

        def make(window=values[j0:j0 + h, i0:i0 + w].copy(), spacing=spacing):
            image = vtkImageData()
            image.SetDimensions(window.shape[1], window.shape[0], 1)
            image.SetSpacing(spacing)
            array = numpy_to_vtk(window.ravel(), deep=1)
            array.SetName("elevation")
            image.GetPointData().SetScalars(array)
            producer = TrivialProducer()
            producer.GetClientSideObject().SetOutput(image)
            return producer
        for percent in (2, 5):
            yield "%s i0 %d j0 %d %dx%d" % (name.replace(".vti", ""), i0, j0, w, h), make, percent, 4


def cases():
    if CROPS:
        yield from crop_cases(CROPS)
        return
    if SEEDS is not None:
        for seed in SEEDS:
            for percent in (5, 25):
                yield "Shepard seed %d" % seed, (lambda s=seed: ShepardField(Seed=s)), percent, 4
        return
    yield "Trigonometric", lambda: TrigonometricField(), 0, 4
    for seed in range(4 if QUICK else 10):
        for percent in (5, 25):
            yield "Shepard seed %d" % seed, (lambda s=seed: ShepardField(Seed=s)), percent, 4
    for name in DEMS + (LARGE_DEMS if LARGE else []):
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


def flooded(values, nx, ny, minima, maxima):
    """The values flooded to the given extrema (vertex ids), as the module docstring says."""
    neighbours = ((1, 0), (-1, 0), (0, 1), (0, -1), (1, -1), (-1, 1))  # GridTriangles' diagonal

    def sweep(g, seeds, sign):
        # Ascending (sign 1): each vertex ends at the lowest level from which a monotone path
        # leads down to a seed; descending (sign -1), the same for peaks.
        done = bytearray(len(g))
        heap = [(sign * g[s], s) for s in seeds]
        heapq.heapify(heap)
        while heap:
            key, v = heapq.heappop(heap)
            if done[v]:
                continue
            done[v] = 1
            g[v] = sign * key
            i, j = v % nx, v // nx
            for di, dj in neighbours:
                a, b = i + di, j + dj
                if 0 <= a < nx and 0 <= b < ny and not done[b * nx + a]:
                    w = b * nx + a
                    heapq.heappush(heap, (max(sign * g[w], key), w))

    g = list(values)
    for _ in range(20):
        before = list(g)
        sweep(g, minima, 1)
        sweep(g, maxima, -1)
        if g == before:
            break
    return g


def flood_reference(simplified, source_values, span):
    """RMS and L_inf (% of the range) of the flooded input against the input."""
    mb = sm.Fetch(simplified)
    points = mb.GetBlock(0).GetPointData()
    vertex, index = points.GetArray("VertexId"), points.GetArray("CriticalIndex")
    minima = [int(vertex.GetValue(i)) for i in range(vertex.GetNumberOfTuples()) if index.GetValue(i) == 0]
    maxima = [int(vertex.GetValue(i)) for i in range(vertex.GetNumberOfTuples()) if index.GetValue(i) == 2]
    segmentation = mb.GetBlock(3)
    nx, ny, _ = segmentation.GetDimensions()
    g = flooded(source_values, nx, ny, minima, maxima)
    squares = sum((a - b) ** 2 for a, b in zip(g, source_values))
    largest = max(abs(a - b) for a, b in zip(g, source_values))
    return 100 * (squares / len(g)) ** 0.5 / span, 100 * largest / span


REFERENCES = {}


def run(make_source, percent, k, interior, name):
    source = make_source()
    source.UpdatePipeline()
    start = time.perf_counter()
    ms = MorseSmaleComplex(Input=source)
    simplified = SimplifyMorseSmaleComplex(Input=ms, PersistenceThreshold=percent)
    smooth = Smooth1Cells(Input=simplified, CurveSegments=k)
    smooth.UpdatePipeline()
    stage4_start = time.perf_counter()
    reconstruct = Reconstruct2Cells(Input=smooth, Interior=interior)
    if STRENGTH is not None:
        reconstruct.AlternativeMapStrength = STRENGTH
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
    points = out.GetNumberOfPoints()
    # The input: Reconstructed - Difference.
    data = [values.GetValue(i) - difference.GetValue(i) for i in range(points)]
    # L_inf of F o Phi.
    exact_error = 0.0
    if exact is not None:
        exact_error = max(abs(exact.GetValue(i) - data[i]) for i in range(points))
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
    if (name, percent) not in REFERENCES:
        REFERENCES[(name, percent)] = flood_reference(simplified, data, span)
    result["flood_rms_range"], result["flood_linf_range"] = REFERENCES[(name, percent)]
    for proxy in (reconstruct, smooth, simplified, ms, source):
        Delete(proxy)
    return result


header = ("%-34s %5s %-6s %8s %7s %7s %7s %5s %5s %7s %7s %3s %6s %6s %8s" %
          ("input", "thr", "inter.", "Linf/eps", "Linf%R", "RMS%R", "FoPhi%R", "near", "far", "repair%",
           "rep.%R", "ok", "st4 s", "tot s", "floodRMS"))
print(header)
records = []
for name, make, percent, k in cases():
    for interior, label in ((1, "fitted"),) if FITTED_ONLY else ((1, "fitted"), (0, "paper")):
        r = run(make, percent, k, interior, name)
        r.update({"input": name, "percent": percent, "k": k, "interior": label})
        records.append(r)
        print("%-34s %4g%% %-6s %8.2f %7.2f %7.2f %7.2f %5d %5d %7.2f %7.2f %3d %6.2f %6.2f %8.2f" %
              ("%s (k=%d)" % (name, k), percent, label, r["linf_eps"], r["linf_range"], r["rms_range"],
               r["exact_linf_range"], r["near"], r["far"], r["repaired"], r["repair_max_range"], r["verified"],
               r["stage4_s"], r["total_s"], r["flood_rms_range"]), flush=True)
if JSON:
    with open(JSON, "w") as f:
        json.dump(records, f, indent=1)
