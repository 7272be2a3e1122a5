"""Paper figure 7 (Mt Rainier, 458 x 306, 2 %, k = 7), as far as TopoSpline goes. The data set
is tests/data/rainier_ned1_1970_crop458x306.vti (TOPOSPLINE_DATA overrides the folder)."""
import os
import sys

from paraview.simple import *

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, here)
import topospline_state_style as style

if os.environ.get("TOPOSPLINE_PLUGIN"):
    LoadPlugin(os.environ["TOPOSPLINE_PLUGIN"], remote=False, ns=globals())

data = os.environ.get("TOPOSPLINE_DATA", os.path.join(here, "..", "tests", "data"))
terrain = XMLImageDataReader(registrationName="Mt Rainier",
                             FileName=[os.path.abspath(os.path.join(data, "rainier_ned1_1970_crop458x306.vti"))])
complex_ = MorseSmaleComplex(registrationName="Complex", Input=terrain)
complex_.ScalarField = ["POINTS", "elevation"]
simplified = SimplifyMorseSmaleComplex(registrationName="Simplified 2%", Input=complex_, PersistenceThreshold=2.0)
smooth = Smooth1Cells(registrationName="Smoothed k=7", Input=simplified, CurveSegments=7)
reconstruction = Reconstruct2Cells(registrationName="Reconstruction", Input=smooth, VerifyTopology=0)
layout = CreateLayout("Figure 7")
style.panel(layout, 0, terrain, "elevation", smooth)
style.panel(layout, 1, reconstruction, "Reconstructed", smooth)
