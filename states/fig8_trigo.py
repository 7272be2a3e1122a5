"""Paper figure 8 (a sin(x/a) sin(y/a), a = 10, 100 x 100 on [-49, 50]^2, no simplification,
k = 7), as far as TopoSpline goes."""
import os
import sys

from paraview.simple import *

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import topospline_state_style as style

if os.environ.get("TOPOSPLINE_PLUGIN"):
    LoadPlugin(os.environ["TOPOSPLINE_PLUGIN"], remote=False, ns=globals())

field = TrigonometricField(registrationName="Trigo", Amplitude=10.0, Resolution=100, Origin=-49.0)
complex_ = MorseSmaleComplex(registrationName="Complex", Input=field)
complex_.ScalarField = ["POINTS", "Trigonometric"]
smooth = Smooth1Cells(registrationName="Smoothed k=7", Input=complex_, CurveSegments=7)
reconstruction = Reconstruct2Cells(registrationName="Reconstruction", Input=smooth, VerifyTopology=0)
layout = CreateLayout("Figure 8")
style.panel(layout, 0, field, "Trigonometric", smooth)
style.panel(layout, 1, reconstruction, "Reconstructed", smooth)
