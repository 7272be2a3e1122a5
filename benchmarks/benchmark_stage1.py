"""Stage 1 through ParaView (pvbatch/pvpython): time and peak memory of the "Morse-Smale
Complex" filter on a 1000 x 1000 Shepard field and on the large terrains, with the STDThread
backend on 2 threads. Prints figures; asserts nothing. Each input runs in a fresh process so
that its peak memory is its own.

Usage: pvpython benchmarks/benchmark_stage1.py   (after scripts/build.sh)"""
import json
import os
import resource
import subprocess
import sys
import time

from benchmark_common import PLUGIN, data_file

CHILD = r"""
import json, resource, sys, time
from paraview.simple import *
from vtkmodules.vtkCommonCore import vtkSMPTools
LoadPlugin(%(plugin)r, remote=False, ns=globals())
vtkSMPTools.SetBackend("STDThread"); vtkSMPTools.Initialize(2)
kind, arg = %(kind)r, %(arg)r
if kind == "shepard":
    src = ShepardField(Resolution=int(arg))
else:
    src = XMLImageDataReader(FileName=[arg])
src.UpdatePipeline()
base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
times = []
for r in range(3):
    ms = MorseSmaleComplex(Input=src)
    t = time.perf_counter(); ms.UpdatePipeline(); times.append(time.perf_counter() - t)
    info = ms.GetDataInformation()
    Delete(ms)
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
print("RESULT", json.dumps({"times": times, "base_rss_mb": base / 1024, "peak_rss_mb": peak / 1024,
                            "backend": vtkSMPTools.GetBackend(), "threads": vtkSMPTools.GetEstimatedNumberOfThreads()}))
"""

inputs = [("Shepard 1000 x 1000", "shepard", "1000")]
for name in ("rainier_ned1_1970_full.vti", "argudo_glaciers_sthelens_10m.vti"):
    path = data_file(name)
    if path:
        inputs.append((name, "file", path))
    else:
        print("skip %s: absent" % name)

print("Stage 1 'Morse-Smale Complex' filter, STDThread backend, 2 threads, best of 3 (process peak RSS)")
print("%-36s %10s %10s %14s %14s" % ("input", "best s", "median s", "peak RSS MB", "filter +MB"))
for label, kind, arg in inputs:
    out = subprocess.run(["pvpython", "--force-offscreen-rendering", "-c",
                          CHILD % {"plugin": PLUGIN, "kind": kind, "arg": arg}], capture_output=True, text=True)
    line = [l for l in out.stdout.splitlines() if l.startswith("RESULT")]
    if not line:
        print("%-36s failed: %s" % (label, out.stderr[-300:]))
        continue
    r = json.loads(line[0][7:])
    t = sorted(r["times"])
    print("%-36s %10.3f %10.3f %14.0f %14.0f" % (label, t[0], t[1], r["peak_rss_mb"], r["peak_rss_mb"] - r["base_rss_mb"]))
