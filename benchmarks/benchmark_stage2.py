"""Stage 2 through ParaView: time of "Simplify Morse-Smale Complex" on the full Mt Rainier DEM
at 2 % (the first run computes the cancellation hierarchy) and of threshold changes afterwards
(replays only). Prints figures; asserts nothing.

Usage: pvpython benchmarks/benchmark_stage2.py   (after scripts/build.sh)"""
import os
import time

from paraview.simple import *
from paraview import servermanager as sm

import benchmark_common

benchmark_common.start(globals())


def count(proxy):
    data = sm.Fetch(proxy)
    return data.GetBlock(0).GetNumberOfPoints()


inputs = [("Shepard 1000 x 1000", lambda: ShepardField(Resolution=1000))]
for name in ("rainier_ned1_1970_crop458x306.vti", "rainier_ned1_1970_full.vti", "argudo_glaciers_sthelens_10m.vti"):
    path = benchmark_common.data_file(name)
    if path:
        inputs.append((name, lambda p=path: XMLImageDataReader(FileName=[p])))
    else:
        print("skip %s: absent" % name)

print("Stage 2 'Simplify Morse-Smale Complex', STDThread, 2 threads")
print("%-36s %8s %8s %12s %12s %12s" % ("input", "#CP", "#CP 2%", "first 2% s", "2->5% s", "5->1% s"))
for label, make in inputs:
    source = make()
    source.UpdatePipeline()
    complex_ = MorseSmaleComplex(Input=source)
    complex_.UpdatePipeline()
    simplified = SimplifyMorseSmaleComplex(Input=complex_, PersistenceThreshold=2)
    start = time.perf_counter()
    simplified.UpdatePipeline()
    first = time.perf_counter() - start
    after = count(simplified)
    times = []
    for percent in (5, 1):
        simplified.PersistenceThreshold = percent
        start = time.perf_counter()
        simplified.UpdatePipeline()
        times.append(time.perf_counter() - start)
    print("%-36s %8d %8d %12.3f %12.3f %12.3f" % (label, count(complex_), after, first, times[0], times[1]))
    for proxy in (simplified, complex_, source):
        Delete(proxy)
