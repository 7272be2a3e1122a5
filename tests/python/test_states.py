"""Every state in states/ loads in pvbatch from a directory other than states/ (with
LoadState(..., data_directory=tests/data)) and its pipeline updates without errors; every
Python twin runs in its own process. Rendering needs an X server: each run is under xvfb-run."""
import glob
import os
import tempfile

import topospline_testing as tt

checks = tt.Checks()
states = os.path.join(tt.REPO, "states")
LOAD = """
from paraview.simple import *
LoadPlugin(%(plugin)r, remote=False, ns=globals())
LoadState(%(state)r, data_directory=%(data)r, restrict_to_data_directory=True)
smoothed = 0
for (name, _), proxy in GetSources().items():
    proxy.UpdatePipeline()
    if proxy.GetXMLLabel() == "Smooth 1-Cells":
        data = servermanager.Fetch(proxy)
        smoothed += data is not None and data.GetNumberOfBlocks() == 7
Render(GetActiveViewOrCreate("RenderView"))
print("SMOOTHED", smoothed)
"""


def run(args, what):
    environment = dict(os.environ, TOPOSPLINE_PLUGIN=tt.plugin_path(), TOPOSPLINE_DATA=tt.test_data_dir())
    with tempfile.TemporaryDirectory() as elsewhere:
        returncode, output = tt.run_with_virtual_display(args, elsewhere, environment)
    errors = "\n".join(line for line in output.splitlines() if "ERR|" in line or "rror" in line)[:1500]
    checks.equal(returncode, 0, "%s: exits cleanly (%s)" % (what, errors))
    checks.check("ERR|" not in output, "%s: no VTK error (%s)" % (what, errors))
    return output


pvsm = sorted(glob.glob(os.path.join(states, "*.pvsm")))
checks.check(len(pvsm) >= 3, "states/ has the paper's figures 6, 7 and 8")
for state in pvsm:
    output = run(["pvbatch", "-c", LOAD % {"plugin": tt.plugin_path(), "state": state, "data": tt.test_data_dir()}],
                 os.path.basename(state))
    checks.check("SMOOTHED 0" not in output and "SMOOTHED" in output,
                 "%s: its smoothed 1-cells are computed" % os.path.basename(state))
for script in sorted(glob.glob(os.path.join(states, "fig*.py"))):
    run(["pvbatch", script], os.path.basename(script))
checks.finish()
