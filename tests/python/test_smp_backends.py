"""The complex is identical with the Sequential and the STDThread SMP backends."""
import numpy as np
from paraview.simple import *
from vtkmodules.vtkCommonCore import vtkSMPTools

import topospline_testing as tt

LoadPlugin(tt.plugin_path(), remote=False, ns=globals())
checks = tt.Checks()

inputs = [("shepard 400", lambda: ShepardField(Resolution=400, Seed=3))]
crop = tt.find_dataset("rainier_ned1_1970_crop458x306.vti")
if crop:
    inputs.append(("rainier crop", lambda: XMLImageDataReader(FileName=[crop])))

results = {}
for backend in ("Sequential", "STDThread"):
    vtkSMPTools.SetBackend(backend)
    vtkSMPTools.Initialize(2)
    checks.equal(vtkSMPTools.GetBackend(), backend, "backend %s selected" % backend)
    for name, make in inputs:
        results[(backend, name)] = tt.fetch_complex(MorseSmaleComplex(Input=make()))

for name, _ in inputs:
    a, b = results[("Sequential", name)], results[("STDThread", name)]
    for key in sorted(k for k in a if k.startswith(("cp_", "arc_S", "arc_D", "cell_", "seg_"))):
        checks.check(np.array_equal(a[key], b[key]), "%s: %s identical across backends" % (name, key))
    checks.check(all(np.array_equal(x, y) for x, y in zip(a["arc_points"], b["arc_points"])),
                 "%s: 1-cell geometry identical across backends" % name)
checks.finish()
