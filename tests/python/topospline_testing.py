"""Shared helpers of the pvpython tests: plugin and data locations, a check recorder that ends
with the plain "N passed, N failed" line, and readers of the complex's blocks as numpy arrays."""
import json
import os
import random
import subprocess
import sys
import time

import numpy as np
from paraview import servermanager as sm
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: F401 (re-exported for tests)

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def plugin_path():
    path = os.environ.get("TOPOSPLINE_PLUGIN",
                          os.path.join(REPO, "build", "lib", "paraview-plugins", "TopoSpline", "TopoSpline.so"))
    if not os.path.exists(path):
        sys.exit("TopoSpline plugin not found at %s (build first, or set TOPOSPLINE_PLUGIN)" % path)
    return path


def test_data_dir():
    return os.environ.get("TOPOSPLINE_TEST_DATA", os.path.join(REPO, "tests", "data"))


def catalog():
    with open(os.path.join(test_data_dir(), "catalog.json")) as f:
        return json.load(f)["datasets"]


def physical_memory():
    """Bytes of physical memory of this machine."""
    return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")


def find_dataset(filename):
    """A data set shipped in tests/data, else in ../shared/data; None when absent."""
    for folder in (test_data_dir(), os.environ.get("TOPOSPLINE_SHARED_DATA", os.path.join(REPO, "..", "shared", "data"))):
        path = os.path.join(folder, filename)
        if os.path.exists(path):
            return path
    return None


# Signs that a virtual X server failed to come up (seen once under heavy load): the test
# machine's problem, not the plugin's.
X_STARTUP_FAILURES = ("bad X server connection", "SupportsOpenGL", "Could not open display", "Xvfb failed")


def run_with_virtual_display(args, cwd, env, timeout=600, screen="1280x1024x24"):
    """Runs args under xvfb-run (display search from a random number, since two "xvfb-run -a"
    starting together can pick the same display); up to four more tries, 5 to 40 s apart, if
    the X server failed to start (seen on a loaded machine: twice in a row once, and three times
    in a row while two stress runs shared the machine). Returns (returncode, output)."""
    for attempt in range(5):
        if attempt:
            time.sleep(5 * 2 ** (attempt - 1))
        result = subprocess.run(["xvfb-run", "-a", "-n", str(random.randint(200, 30000)), "-s", "-screen 0 " + screen]
                                + args, cwd=cwd, env=env, capture_output=True, text=True, timeout=timeout)
        output = result.stdout + result.stderr
        if result.returncode == 0 or not any(sign in output for sign in X_STARTUP_FAILURES):
            break
        print("X server start-up failure, trying again", flush=True)
    return result.returncode, output


class Checks:
    """Records named checks; finish() prints the summary and exits non-zero on failure."""

    def __init__(self):
        self.passed = 0
        self.failed = 0
        self.skipped = 0

    def check(self, condition, what):
        if condition:
            self.passed += 1
        else:
            self.failed += 1
            print("FAIL: %s" % what, flush=True)
        return condition

    def equal(self, a, b, what):
        return self.check(a == b, "%s: %r != %r" % (what, a, b))

    def skip(self, what):
        self.skipped += 1
        print("SKIP: %s" % what, flush=True)

    def finish(self):
        print("%d passed, %d failed, %d skipped" % (self.passed, self.failed, self.skipped), flush=True)
        sys.exit(1 if self.failed else 0)


def image_data(values2d, name="f", origin=(0, 0, 0), spacing=(1, 1, 1), extent_start=(0, 0, 0)):
    """A one-layer vtkImageData with values2d (ny x nx) as the point array `name`."""
    from vtkmodules.util.numpy_support import numpy_to_vtk
    from vtkmodules.vtkCommonDataModel import vtkImageData
    ny, nx = values2d.shape
    image = vtkImageData()
    x0, y0, z0 = extent_start
    image.SetExtent(x0, x0 + nx - 1, y0, y0 + ny - 1, z0, z0)
    image.SetOrigin(*origin)
    image.SetSpacing(*spacing)
    array = numpy_to_vtk(np.ascontiguousarray(values2d.ravel(), dtype=np.float64), deep=1)
    array.SetName(name)
    image.GetPointData().AddArray(array)
    return image


def field_value(fd, name, index=0):
    """Component `index` of field-data array `name`, or None if it is absent."""
    array = fd.GetArray(name)
    return array.GetValue(index) if array is not None else None


def _arrays(data, names, where="point"):
    fd = data.GetPointData() if where == "point" else data.GetCellData()
    out = {}
    for name in names:
        arr = fd.GetArray(name)
        out[name] = vtk_to_numpy(arr).copy() if arr is not None else None
    return out


def fetch_complex(proxy):
    """The complex produced by a TopoSpline filter, as numpy arrays."""
    proxy.UpdatePipeline()
    mb = sm.Fetch(proxy)
    if mb is None or mb.GetNumberOfBlocks() < 4:
        return None
    cps, arcs, cells, seg = (mb.GetBlock(i) for i in range(4))
    c = {"blocks": [mb.GetMetaData(i).Get(mb.NAME()) for i in range(mb.GetNumberOfBlocks())]}
    c.update({"cp_" + k: v for k, v in _arrays(cps, ["CriticalPointId", "CriticalIndex", "CriticalValue", "VertexId",
                                                      "IsOnBoundary"]).items()})
    c.update({"arc_" + k: v for k, v in _arrays(arcs, ["SourceId", "DestinationId", "SeparatrixType"], "cell").items()})
    values = vtk_to_numpy(arcs.GetPointData().GetArray("ScalarValue"))
    lines = arcs.GetLines()
    offsets = vtk_to_numpy(lines.GetOffsetsArray())
    conn = vtk_to_numpy(lines.GetConnectivityArray())
    c["arc_values"] = [values[conn[offsets[i]:offsets[i + 1]]] for i in range(len(offsets) - 1)]
    c["arc_points"] = [vtk_to_numpy(arcs.GetPoints().GetData())[conn[offsets[i]:offsets[i + 1]]]
                       for i in range(len(offsets) - 1)]
    c.update({"cell_" + k: v for k, v in _arrays(cells, ["MinimumId", "MaximumId", "SaddleIds",
                                                          "BoundarySeparatrixIds", "IsPouch",
                                                          "NumberOfVertices"]).items()})
    c.update({"seg_" + k: v for k, v in _arrays(seg, ["AscendingManifoldId", "DescendingManifoldId",
                                                       "TwoCellId"]).items()})
    c["n_points"] = seg.GetNumberOfPoints()
    return c


def counts(c):
    return [int(np.sum(c["cp_CriticalIndex"] == k)) for k in range(3)]


def interior_counts(c):
    """Interior critical points by index; saddles counted once per vertex (a degenerate PL
    saddle of multiplicity m is m critical edges on one vertex), as the data catalog does."""
    inner = c["cp_IsOnBoundary"] == 0
    return [len(np.unique(c["cp_VertexId"][(c["cp_CriticalIndex"] == k) & inner])) for k in range(3)]


def check_complex(checks, c, name, disk=True, simplified=False):
    """The invariants of a Morse-Smale complex on a planar domain. A simplified complex's
    1-cells are unions of 1-cells (the paper's trivial embedding): values along them need not
    be monotone (stage 3 makes them so), but their ends are still the critical values."""
    if not checks.check(c is not None, "%s: output is a 4-block complex" % name):
        return
    n = counts(c)
    if disk:
        checks.equal(n[0] - n[1] + n[2], 1, "%s: #min - #saddles + #max (counts %s)" % (name, n))
    index_of = dict(zip(c["cp_CriticalPointId"].tolist(), c["cp_CriticalIndex"].tolist()))
    value_of = dict(zip(c["cp_CriticalPointId"].tolist(), c["cp_CriticalValue"].tolist()))
    # 1-cells join consecutive indices, from the lower to the higher critical value.
    bad_ends = bad_monotone = 0
    for a, (s, d, t) in enumerate(zip(c["arc_SourceId"], c["arc_DestinationId"], c["arc_SeparatrixType"])):
        vals = c["arc_values"][a]
        ok = index_of.get(int(s)) == t and index_of.get(int(d)) == t + 1
        bad_ends += not (ok and vals[0] == value_of[int(s)] and vals[-1] == value_of[int(d)])
        if t == 0 and not simplified:  # descending 1-cells are vertex paths: values never decrease
            bad_monotone += not bool(np.all(np.diff(vals) >= 0))
    checks.equal(bad_ends, 0, "%s: 1-cells with wrong end points" % name)
    checks.equal(bad_monotone, 0, "%s: descending 1-cells with decreasing values" % name)
    # 2-cells are quads minimum-saddle-maximum-saddle with consistent sides.
    src, dst = c["arc_SourceId"], c["arc_DestinationId"]
    bad_cells = 0
    for k in range(len(c["cell_MinimumId"])):
        mn, mx = int(c["cell_MinimumId"][k]), int(c["cell_MaximumId"][k])
        s0, s1 = (int(x) for x in c["cell_SaddleIds"][k])
        a = [int(x) for x in c["cell_BoundarySeparatrixIds"][k]]
        ok = index_of.get(mn) == 0 and index_of.get(mx) == 2 and index_of.get(s0) == 1 and index_of.get(s1) == 1
        ok = ok and min(a) >= 0
        if ok:
            ok = (src[a[0]] == mn and dst[a[0]] == s0 and src[a[1]] == s0 and dst[a[1]] == mx and
                  src[a[2]] == mn and dst[a[2]] == s1 and src[a[3]] == s1 and dst[a[3]] == mx)
            ok = ok and bool(c["cell_IsPouch"][k]) == (s0 == s1)
        bad_cells += not ok
    checks.equal(bad_cells, 0, "%s: 2-cells that are not min-saddle-max-saddle cycles" % name)
    n_asc = int(np.sum(c["arc_SeparatrixType"] == 1))
    checks.equal(len(c["cell_MinimumId"]), n_asc, "%s: one 2-cell per side of each ascending 1-cell / 2" % name)
    tc = c["seg_TwoCellId"]
    checks.check(bool(np.all((tc >= 0) & (tc < len(c["cell_MinimumId"])))), "%s: every vertex has a 2-cell id" % name)
    checks.equal(int(np.sum(c["cell_NumberOfVertices"])), c["n_points"], "%s: 2-cells partition the vertices" % name)
    # A vertex's manifolds are its cell's extrema.
    checks.check(bool(np.all(c["seg_DescendingManifoldId"] == c["cell_MaximumId"][tc])),
                 "%s: descending manifold id is the 2-cell's maximum" % name)
