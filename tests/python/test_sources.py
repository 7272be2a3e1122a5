"""The two synthetic sources: the paper's parameters by default, deterministic, correct values."""
import numpy as np
from paraview.simple import *
from paraview import servermanager as sm
from vtkmodules.util.numpy_support import vtk_to_numpy

import topospline_testing as tt

LoadPlugin(tt.plugin_path(), remote=False, ns=globals())
checks = tt.Checks()


def values(proxy, name):
    proxy.UpdatePipeline()
    image = sm.Fetch(proxy)
    return image, vtk_to_numpy(image.GetPointData().GetArray(name))


trig = TrigonometricField()
image, v = values(trig, "Trigonometric")
checks.equal(image.GetDimensions(), (100, 100, 1), "trig: paper's 100 x 100 samples")
checks.equal(image.GetOrigin()[:2], (-49.0, -49.0), "trig: paper's domain starts at -49")
x = -49 + np.arange(100)
expected = 10 * np.outer(np.sin(x / 10), np.sin(x / 10))  # [j, i]
checks.check(np.allclose(v.reshape(100, 100), expected, atol=1e-12), "trig: a sin(x/a) sin(y/a)")

shepard = ShepardField()
image, v = values(shepard, "Shepard")
checks.equal(image.GetDimensions(), (250, 250, 1), "shepard: paper's 250 x 250 grid")
checks.check(v.min() >= 0 and v.max() <= 1, "shepard: values inside the site values' range [0, 1]")
_, again = values(ShepardField(), "Shepard")
checks.check(np.array_equal(v, again), "shepard: same seed, same field")
_, other = values(ShepardField(Seed=2), "Shepard")
checks.check(not np.array_equal(v, other), "shepard: another seed, another field")
small = ShepardField(Resolution=64, NumberOfSites=5, Power=3.0)
image, v = values(small, "Shepard")
checks.equal(image.GetDimensions(), (64, 64, 1), "shepard: resolution property")
checks.finish()
