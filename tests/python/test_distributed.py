"""Under mpiexec -n 2 pvbatch the pipeline (stages 1 to 4, on the built-in Shepard field and a
terrain read by a reader that splits its image across processes) gives the same result as in
one process: the complex is computed on the process of piece 0, from the whole input."""
import os
import shutil
import subprocess

import topospline_testing as tt

checks = tt.Checks()
SCRIPT = """
from paraview.simple import *
LoadPlugin(%(plugin)r, remote=False, ns=globals())
for name, source in (("shepard", ShepardField()), ("rainier", XMLImageDataReader(FileName=[%(terrain)r]))):
    complex_ = MorseSmaleComplex(Input=source)
    simplified = SimplifyMorseSmaleComplex(Input=complex_, PersistenceThreshold=2)
    smoothed = Smooth1Cells(Input=simplified, CurveSegments=4)
    reconstruction = Reconstruct2Cells(Input=smoothed)
    for stage, proxy in (("complex", complex_), ("simplified", simplified), ("smoothed", smoothed),
                         ("reconstruction", reconstruction)):
        proxy.UpdatePipeline()
        info = proxy.GetDataInformation()
        extra = ""
        if stage == "reconstruction":
            values = info.GetPointDataInformation().GetArrayInformation("Reconstructed")
            extra = " %%.12g %%.12g" %% values.GetComponentRange(0)
        print("DIGEST", name, stage, info.GetNumberOfPoints(), info.GetNumberOfCells(), extra)
"""
terrain = tt.find_dataset("rainier_ned1_1970_crop458x306.vti")
script = SCRIPT % {"plugin": tt.plugin_path(), "terrain": terrain}
mpiexec = shutil.which("mpiexec")
if not mpiexec:
    checks.skip("mpiexec absent")
else:
    # This test runs in pvpython, an MPI singleton: its children must not inherit its MPI
    # environment, or mpiexec and pvbatch fail to start.
    clean = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMIX_", "OPAL_", "PRTE_"))}
    runs = {}
    for label, command in (("serial", ["pvbatch", "-c", script]),
                           ("2 processes", [mpiexec, "--allow-run-as-root", "--oversubscribe", "-n", "2",
                                            "pvbatch", "-c", script])):
        result = subprocess.run(command, capture_output=True, text=True, timeout=600, env=clean)
        output = result.stdout + result.stderr
        checks.equal(result.returncode, 0, "%s run exits cleanly (%s)" % (label, output[-500:]))
        checks.check("ERR|" not in output, "%s run logs no error (%s)" % (label, output[-500:]))
        runs[label] = sorted(set(line for line in result.stdout.splitlines() if line.startswith("DIGEST")))
    checks.equal(len(runs["serial"]), 8, "serial run reports every stage")
    checks.equal(runs["2 processes"], runs["serial"], "2 processes give the serial result")
    print("\n".join(runs["serial"]))
checks.finish()
