"""Paper figure 6 (the Shepard field, 25 %, k = 4 and k = 7): the reconstruction with its
smoothed 1-cells for both k, side by side.
Run with pvpython/pvbatch; TOPOSPLINE_PLUGIN names the plugin (else it must be loaded)."""
import os
import sys

from paraview.simple import *

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import topospline_state_style as style

if os.environ.get("TOPOSPLINE_PLUGIN"):
    LoadPlugin(os.environ["TOPOSPLINE_PLUGIN"], remote=False, ns=globals())

field = ShepardField(registrationName="Shepard", NumberOfSites=50, Power=2.0, Resolution=250, Seed=1)
complex_ = MorseSmaleComplex(registrationName="Complex", Input=field)
complex_.ScalarField = ["POINTS", "Shepard"]
simplified = SimplifyMorseSmaleComplex(registrationName="Simplified 25%", Input=complex_, PersistenceThreshold=25.0)
layout = CreateLayout("Figure 6")
for k, where in ((4, 0), (7, 1)):
    smooth = Smooth1Cells(registrationName="Smoothed k=%d" % k, Input=simplified, CurveSegments=k)
    reconstruction = Reconstruct2Cells(registrationName="Reconstruction k=%d" % k, Input=smooth, VerifyTopology=0)
    style.panel(layout, where, reconstruction, "Reconstructed", smooth)
