"""The ParaView GUI starts with the plugin, runs the four stages on the built-in Shepard field in
its own render view (the reconstruction with the smoothed 1-cells, in the style of the paper's
figure 6) and saves a screenshot;
under xvfb-run. (A GUI start-up script that creates layouts and views hangs the 5.11 GUI
here, so this uses the GUI's own view.)"""
import os
import tempfile

import numpy as np
from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOImage import vtkPNGReader

import topospline_testing as tt

checks = tt.Checks()
GUI_SCRIPT = """
import os, sys
from paraview.simple import *
sys.path.insert(0, %(states)r)
import topospline_state_style as style
LoadPlugin(os.environ["TOPOSPLINE_PLUGIN"], remote=False, ns=globals())
field = ShepardField()
field.UpdatePipeline()
smooth = Smooth1Cells(Input=SimplifyMorseSmaleComplex(Input=MorseSmaleComplex(Input=field), PersistenceThreshold=25))
reconstruction = Reconstruct2Cells(Input=smooth)
view = GetActiveViewOrCreate("RenderView")
style.field_with_isolines(reconstruction, "Reconstructed", view)
style.complex_lines(smooth, view)
style.view_from_above(view)
SaveScreenshot(%(shot)r, view, ImageResolution=[1000, 800])
print("GUI-SCRIPT-DONE", flush=True)
"""
with tempfile.TemporaryDirectory() as work:
    shot = os.environ.get("TOPOSPLINE_GUI_SCREENSHOT", os.path.join(work, "gui_fig6.png"))
    script = os.path.join(work, "gui.py")
    with open(script, "w") as f:
        f.write(GUI_SCRIPT % {"states": os.path.join(tt.REPO, "states"), "shot": shot})
    returncode, output = tt.run_with_virtual_display(["paraview", "--script=" + script, "--exit"], work,
                                                     dict(os.environ, TOPOSPLINE_PLUGIN=tt.plugin_path()),
                                                     timeout=300, screen="1920x1080x24")
    checks.equal(returncode, 0, "paraview GUI exits cleanly (%s)" % output[-600:])
    checks.check("GUI-SCRIPT-DONE" in output, "the GUI ran the pipeline script")
    checks.check("ERR|" not in output, "no VTK error in the GUI run (%s)" % output[-600:])
    if checks.check(os.path.exists(shot), "screenshot written"):
        reader = vtkPNGReader()
        reader.SetFileName(shot)
        reader.Update()
        pixels = vtk_to_numpy(reader.GetOutput().GetPointData().GetScalars())
        checks.equal(reader.GetOutput().GetDimensions()[:2], (1000, 800), "screenshot size")
        # A rendered field with isolines and 1-cells, not an empty view: many distinct colours.
        checks.check(len(np.unique(pixels[:, :3], axis=0)) > 500, "screenshot shows the rendered pipeline")
checks.finish()
