"""Stage 3 through ParaView: the paper's "time I" (1-cell smoothing) for its Shepard example
(25 %, k = 4 and 7) and Mt Rainier (458 x 306 crop, 2 %, k = 7), plus the full DEM, beside the
paper's times (2009 Xeon W3520). Best of 3, STDThread on 2 threads. Prints figures only.

Usage: pvpython benchmarks/benchmark_stage3.py   (after scripts/build.sh)"""
import os
import time

from paraview.simple import *
from paraview import servermanager as sm

import benchmark_common

benchmark_common.start(globals())

cases = [("Shepard 250 x 250", lambda: ShepardField(), 25, 4, 0.13),
         ("Shepard 250 x 250", lambda: ShepardField(), 25, 7, 0.13)]
for name, percent, k, paper in (("rainier_ned1_1970_crop458x306.vti", 2, 7, 0.31), ("rainier_ned1_1970_full.vti", 2, 7, None)):
    path = benchmark_common.data_file(name)
    if path:
        cases.append((name, lambda p=path: XMLImageDataReader(FileName=[p]), percent, k, paper))
    else:
        print("skip %s: absent" % name)

print("Stage 3 'Smooth 1-Cells' (time I), STDThread, 2 threads, best of 3")
print("%-36s %4s %3s %7s %8s %8s %10s %9s" % ("input", "%", "k", "#CP", "pieces", "time s", "paper s", "speed-up"))
for label, make, percent, k, paper in cases:
    source = make()
    simplified = SimplifyMorseSmaleComplex(Input=MorseSmaleComplex(Input=source), PersistenceThreshold=percent)
    simplified.UpdatePipeline()
    cps = sm.Fetch(simplified).GetBlock(0).GetNumberOfPoints()
    best = None
    for repeat in range(3):
        smooth = Smooth1Cells(Input=simplified, CurveSegments=k)
        start = time.perf_counter()
        smooth.UpdatePipeline()
        elapsed = time.perf_counter() - start
        best = elapsed if best is None else min(best, elapsed)
        pieces = sm.Fetch(smooth).GetFieldData().GetArray("NumberOfPieces").GetValue(0)
        Delete(smooth)
    print("%-36s %4d %3d %7d %8d %8.3f %10s %9s" % (label, percent, k, cps, pieces, best,
                                                   "%.2f" % paper if paper else "-",
                                                   "%.1fx" % (paper / best) if paper else "-"))
