"""Stage 4 through ParaView on the synthetic fields and every catalog data set at 2, 5 and
25 % with k = 4 and 7 (files above 300k vertices only with TOPOSPLINE_LARGE_TESTS=1).
Asserted: every 2-cell is reconstructed; no Sibson cell violates the monotonicity conditions;
critical values are interpolated; the Bezier patches (VTK_BEZIER_TRIANGLE) and the finer
resampling (4x; 2x if the machine lacks the memory) are output; the outputs' samplings (after topological
sampling) have exactly the simplified complex's number of minima, saddles and maxima, at the
input resolution and finer; and the topology verdict, which also requires every critical point
within one grid spacing of its node, holds on every run but the listed known misses (which
must still miss). On a 48 x 48 noise field whose boundary saddle's only way into the domain
runs through a wanted minimum, the sampling must want that saddle one step along the boundary,
report it, and verify at the input's vertices and at 4x. Printed for the
record: the counts before topological sampling, how far it moved values, and the L-infinity and
RMS errors. Issue 15's RMS target (1.5 % of the range) is asserted on every catalog DEM at 2 and
5 %, on a seeded random crop of each DEM shipped here and on a Maunga Whau crop that missed it."""
import os

import numpy as np
from paraview.simple import *
from paraview import servermanager as sm
from vtkmodules.util.numpy_support import vtk_to_numpy

import topospline_testing as tt

LoadPlugin(tt.plugin_path(), remote=False, ns=globals())
checks = tt.Checks()

inputs = [("shepard", ShepardField()), ("trig", TrigonometricField())]
LARGE = os.environ.get("TOPOSPLINE_LARGE_TESTS") == "1"
for entry in tt.catalog():
    path = tt.find_dataset(entry["file"])
    if path and entry["vertices"] > 300000 and not LARGE:
        checks.skip("%s: %d vertices, run with TOPOSPLINE_LARGE_TESTS=1 (CI time budget)" % (entry["file"],
                                                                                          entry["vertices"]))
    elif path:
        inputs.append((entry["file"], XMLImageDataReader(FileName=[path])))
    else:
        checks.skip("%s absent (large data sets live in ../shared/data)" % entry["file"])


def field_range_of(fd):
    return tt.field_value(fd, "ValueRange", 1) - tt.field_value(fd, "ValueRange", 0)


# Runs that miss (docs/Reconstruction.md, "Known misses"); each must still miss, so that the
# list stays true. Every other check still applies to them.
# Runs whose F o Phi (before topological sampling) misses a node's critical value; the
# sampling gives every node's vertex its value, and the verdict holds on them.
# (None now: the Saint Helens crop at 25 %, k = 4 hits its values since stage 3 finds the
# crossings between its samples.)
INTERPOLATION_MISSES = {}
KNOWN_MISSES = {
    # TOPOSPLINE_LARGE_TESTS=1 only (measured again in Session 36: every 2-cell is reconstructed,
    # the verdict misses one saddle next to the boundary, at (1444, 1), whose saddle the sampling
    # puts two vertices away at (1446, 0), on all six runs; the full Rainier DEM at 25 %, once
    # listed, verifies at k = 4 and 7, with the version before too).
    "argudo_glaciers_sthelens_10m.vti 2% k=4": "topology verdict off (a saddle by the boundary two vertices off)",
    "argudo_glaciers_sthelens_10m.vti 2% k=7": "topology verdict off (a saddle by the boundary two vertices off)",
    "argudo_glaciers_sthelens_10m.vti 5% k=4": "topology verdict off (a saddle by the boundary two vertices off)",
    "argudo_glaciers_sthelens_10m.vti 5% k=7": "topology verdict off (a saddle by the boundary two vertices off)",
    "argudo_glaciers_sthelens_10m.vti 25% k=4": "topology verdict off (a saddle by the boundary two vertices off)",
    "argudo_glaciers_sthelens_10m.vti 25% k=7": "topology verdict off (a saddle by the boundary two vertices off)",
}


def check_reconstruction(label, reconstruct, c, resolution):
    reconstruct.UpdatePipeline()
    out = sm.Fetch(reconstruct)
    fd = out.GetFieldData()
    checks.equal(tt.field_value(fd, "ViolatingPatches"), 0, "%s: no Sibson cell violates the monotonicity conditions" % label)
    expected = [int(tt.field_value(fd, "ExpectedCriticalPoints", i)) for i in range(3)]
    # Every node, and at each boundary junction the minimum and saddle that stage 1's boundary
    # rule puts on a boundary vertex where the field falls into the domain.
    junctions = fd.GetArray("BoundaryJunctionVertexId")
    checks.equal(sum(expected), len(c["cp_VertexId"]) + 2 * (junctions.GetNumberOfTuples() if junctions else 0),
                 "%s: the topology check counted every node and boundary junction" % label)
    found = [int(tt.field_value(fd, "InputCriticalPoints", i)) for i in range(3)]
    fine = [int(tt.field_value(fd, "ResampledCriticalPoints", i)) for i in range(3)] if resolution > 1 else None
    known_miss = label in KNOWN_MISSES
    checks.check(tt.field_value(fd, "FailedTwoCells") == 0 or (known_miss and "2-cell" in KNOWN_MISSES[label]),
                 "%s: every 2-cell reconstructed (%d failed)" % (label, tt.field_value(fd, "FailedTwoCells")))
    if known_miss:
        checks.check(not tt.field_value(fd, "TopologyVerified"),
                     "%s: still a known miss (%s); if it now holds, take it off the list" % (label, KNOWN_MISSES[label]))
    else:
        checks.equal(found, expected, "%s: critical points of the sampling at the input resolution" % label)
        if fine is not None:
            checks.equal(fine, expected, "%s: critical points of the %dx finer sampling" % (label, resolution))
        # The full verdict: also every critical point within one grid spacing of its node, at
        # both resolutions.
        checks.check(bool(tt.field_value(fd, "TopologyVerified")),
                     "%s: topology verified (counts and positions within one spacing)" % label)
    raw = [int(tt.field_value(fd, "RawInputCriticalPoints", i)) for i in range(3)]
    print("%s: failed 2-cells %d; critical points expected %s, before topological sampling %s (it moved %d "
          "vertices, at most %.3g = %.2f%% of the range); verdict %d (%d spurious, %d missing within one grid spacing)"
          % (label, tt.field_value(fd, "FailedTwoCells"), expected, raw, tt.field_value(fd, "SamplingChangedVertices"),
             tt.field_value(fd, "SamplingMaximumChange"), 100 * tt.field_value(fd, "SamplingMaximumChange") / field_range_of(fd),
             tt.field_value(fd, "TopologyVerified"), fd.GetArray("SpuriousCriticalPoints").GetNumberOfTuples(),
             fd.GetArray("MissingCriticalPoints").GetNumberOfTuples()), flush=True)
    values = vtk_to_numpy(out.GetPointData().GetArray("Reconstructed"))
    checks.check(bool(np.all(np.isfinite(values))), "%s: finite values" % label)
    # F o Phi itself (before topological sampling) interpolates the critical values.
    exact = vtk_to_numpy(out.GetPointData().GetArray("ReconstructedExact"))
    field_range = field_range_of(fd)
    # At the nodes whose vertex lies in a reconstructed cell (a failed cell keeps input values).
    cell_of = vtk_to_numpy(out.GetPointData().GetArray("ReconstructionCellId"))
    vertices = c["cp_VertexId"].astype(int)
    located = cell_of[vertices] >= 0
    at_nodes = exact[vertices][located]
    moved = float(np.max(np.abs(values[vertices] - exact[vertices]))) if len(vertices) else 0.0
    worst = float(np.max(np.abs(at_nodes - c["cp_CriticalValue"][located]))) if len(at_nodes) else 0.0
    if label in INTERPOLATION_MISSES:
        checks.check(worst > 1e-9 * field_range,
                     "%s: F o Phi still misses a critical value (%s); if it now holds, take it off the list"
                     % (label, INTERPOLATION_MISSES[label]))
    else:
        checks.check(worst <= 1e-9 * field_range or known_miss,
                     "%s: critical values interpolated (worst %.3g)" % (label, worst))
    print("%s: topological sampling moved node values by up to %.3g (%.2f%% of the range)"
          % (label, moved, 100 * moved / field_range))
    return tt.field_value(fd, "MaximumError"), tt.field_value(fd, "RMSError"), field_range, tt.field_value(fd, "BezierTriangles")


def fetch_port(proxy, port):
    return sm.Fetch(proxy, None, None, port)


for name, source in inputs:
    source.UpdatePipeline()
    points = source.GetDataInformation().GetNumberOfPoints()
    # 4x finer: the topology must hold on a finer sampling too. The 2000 x 2000 terrain at 4x
    # is 64M vertices: measured 16.3 GB at peak (about 200 bytes per fine vertex on top of the
    # 4M-vertex pipeline), so on a machine with less memory the check falls back to 2x, and
    # says so.
    resolution = 4
    needed = 3e9 + 260 * 16 * points
    if needed > tt.physical_memory():
        resolution = 2
        print("%s: checked at 2x, not 4x: 4x needs about %.0f GB, this machine has %.0f GB"
              % (name, needed / 1e9, tt.physical_memory() / 1e9), flush=True)
    ms = MorseSmaleComplex(Input=source)
    for percent in (2, 5, 25):
        simplified = SimplifyMorseSmaleComplex(Input=ms, PersistenceThreshold=percent)
        c = tt.fetch_complex(simplified)
        for k in (4, 7):
            smooth = Smooth1Cells(Input=simplified, CurveSegments=k)
            reconstruct = Reconstruct2Cells(Input=smooth, OutputResolution=resolution)
            label = "%s %d%% k=%d" % (name, percent, k)
            linf, rms, field_range, triangles = check_reconstruction(label, reconstruct, c, resolution)
            bezier = fetch_port(reconstruct, 1)
            checks.equal(bezier.GetNumberOfCells(), int(triangles), "%s: Bezier triangles on port 1" % label)
            checks.check(bezier.GetNumberOfCells() == 0 or bezier.GetCellType(0) == 76,
                         "%s: cells are VTK_BEZIER_TRIANGLE" % label)
            if resolution > 1:
                image = fetch_port(reconstruct, 2)
                checks.check(image.GetNumberOfPoints() > points, "%s: resampled image is finer" % label)
            print("%s: %d critical points, L-inf error %.4g (%.2f%% of range), RMS %.4g (%.3f%%), %d Bezier triangles"
                  % (label, len(c["cp_VertexId"]), linf, 100 * linf / field_range, rms, 100 * rms / field_range,
                     triangles), flush=True)
            if name.endswith(".vti") and percent in (2, 5):
                # Issue 15's target for every catalog DEM at 2 and 5 %: RMS within 1.5 % of the range.
                checks.check(rms <= 0.015 * field_range, "%s: RMS %.3f %% of the range <= 1.5 %%" % (label, 100 * rms / field_range))
            Delete(reconstruct)
            Delete(smooth)
        Delete(simplified)

# A boundary saddle whose only way into the domain runs through a wanted minimum
# (docs/Reconstruction.md, "Saddles with no way up"; stress case #38): on this 48 x 48 noise at
# 25 %, the complex's boundary saddle at (0, 1) stands above its whole link, and its only interior
# neighbour, (1, 1), is a wanted minimum (its link on the grid's triangulation: right, up,
# up-left, left, down, down-right). No values at these vertices give (0, 1) a way up and keep the
# minimum: the sampling wants the saddle one step along the boundary, at (0, 2), instead. Checked
# here from the output's values: (1, 1) is still a pit, (0, 1) is no peak, (0, 2) is a boundary
# saddle (both boundary neighbours lower, a neighbour higher), and the verdict holds; the
# resampled output at 4x has the complex's counts.
noise = np.random.default_rng(1525008249).uniform(0, 1, (48, 48))
producer = TrivialProducer()
producer.GetClientSideObject().SetOutput(tt.image_data(noise))
ms = MorseSmaleComplex(Input=producer, ScalarField=["POINTS", "f"])
simplified = SimplifyMorseSmaleComplex(Input=ms, PersistenceThreshold=25)
smooth = Smooth1Cells(Input=simplified, CurveSegments=18)
reconstruct = Reconstruct2Cells(Input=smooth, OutputResolution=4)
out = sm.Fetch(reconstruct)
fd = out.GetFieldData()
sampled = vtk_to_numpy(out.GetPointData().GetArray("Reconstructed")).reshape(48, 48)
c = tt.fetch_complex(simplified)
nodes = {(int(v) % 48, int(v) // 48): int(i) for v, i in zip(c["cp_VertexId"], c["cp_CriticalIndex"])}
checks.check(nodes.get((1, 1)) == 0 and nodes.get((0, 1)) == 1, "corner case: the complex has a minimum at (1, 1), a saddle at (0, 1)")
def at(x, y):
    return (sampled[y, x], y * 48 + x)  # the stage-1 order: value, then vertex id
saddle_peak = all(at(0, 1) > at(x, y) for x, y in ((1, 1), (0, 2), (0, 0), (1, 0)))
pit = all(at(1, 1) < at(x, y) for x, y in ((2, 1), (1, 2), (0, 2), (0, 1), (1, 0), (2, 0)))
moved_saddle = (at(0, 2) > at(0, 1) and at(0, 2) > at(0, 3) and
                any(at(x, y) > at(0, 2) for x, y in ((1, 2), (1, 1))))
checks.check(pit and not saddle_peak, "corner case: (1, 1) is still a pit, (0, 1) no peak")
checks.check(moved_saddle, "corner case: (0, 2) is a boundary saddle")
checks.check(tt.field_value(fd, "SamplingMovedBoundarySaddles") >= 1, "corner case: the moved saddle is reported")
checks.equal(tt.field_value(fd, "TopologyVerified"), 1, "corner case: the verdict at the input's vertices")
expected = [tt.field_value(fd, "ExpectedCriticalPoints", i) for i in range(3)]
checks.equal([tt.field_value(fd, "ResampledCriticalPoints", i) for i in range(3)], expected,
             "corner case: the resampled output at 4x has the complex's counts")
print("corner case: (0, 1) a peak %d, (1, 1) a pit %d, (0, 2) a boundary saddle %d, moved %d, blocked %d, expected %s" % (
    saddle_peak, pit, moved_saddle, tt.field_value(fd, "SamplingMovedBoundarySaddles"),
    tt.field_value(fd, "SamplingBlockedWaysUp"), expected), flush=True)

# The alternative maps for the largest misses (docs/Reconstruction.md, "Alternative maps for the
# largest misses"): with the default strength the largest miss of ReconstructedExact, measured
# here against the input, is never larger than with the mean value map everywhere (strength 0),
# the cells that kept another map are reported, and the paper's interior never uses them.
lowered = 0
for seed in (7, 8):
    field = ShepardField(Seed=seed)
    data = vtk_to_numpy(sm.Fetch(field).GetPointData().GetArray(0))
    smooth = Smooth1Cells(Input=SimplifyMorseSmaleComplex(Input=MorseSmaleComplex(Input=field), PersistenceThreshold=5))
    misses = {}
    for strength in (0, 30):
        out = sm.Fetch(Reconstruct2Cells(Input=smooth, AlternativeMapStrength=strength))
        fd = out.GetFieldData()
        exact = vtk_to_numpy(out.GetPointData().GetArray("ReconstructedExact"))
        misses[strength] = np.max(np.abs(exact - data)) / (data.max() - data.min())
        checks.equal(tt.field_value(fd, "TopologyVerified"), 1, "alternative maps, seed %d, strength %g: verdict" % (seed, strength))
        remapped = tt.field_value(fd, "RemappedCells")
        checks.check(remapped == 0 if strength == 0 else remapped >= 0, "alternative maps: RemappedCells %d at strength %g" % (remapped, strength))
    checks.check(misses[30] <= misses[0] + 1e-12, "alternative maps, seed %d: largest miss %.4f <= %.4f" % (seed, misses[30], misses[0]))
    lowered += misses[30] < misses[0]
    paper = sm.Fetch(Reconstruct2Cells(Input=smooth, Interior=0))
    checks.equal(tt.field_value(paper.GetFieldData(), "RemappedCells"), 0, "alternative maps: none with the paper's interior")
    print("alternative maps, Shepard seed %d at 5 %%: largest miss of ReconstructedExact %.2f -> %.2f %% of the range" % (
        seed, 100 * misses[0], 100 * misses[30]), flush=True)
checks.check(lowered >= 1, "alternative maps lower the largest miss on Shepard seed 7 or 8 (%d)" % lowered)

# Terrain windows (issue 15's RMS target, 1.5 % of the range at 2 and 5 %, on crops nothing was
# tuned on): seeded random crops of the DEMs shipped here, and the Maunga Whau crop whose integer
# plateaus put a ridge at the foot of a slope, below the valley across a narrow cell, where the
# fit held the cell a fifth of the range above the data (RMS 3.7 %) until the fit's aim at F
# rising along u and v was released there (docs/Reconstruction.md, "The axis aim released"); the
# cause was the solver's pull back towards the paper's surface, and the first fit now stays on
# the data at 2 % without the release ("Fits no longer pulled back to the paper's surface").
# The RMS is recomputed here from Reconstructed and the crop's own values.
def crop_errors(values, percent):
    """RMS and largest error of Reconstructed in units of the crop's range, and the field data."""
    producer = TrivialProducer()
    producer.GetClientSideObject().SetOutput(tt.image_data(values))
    smooth = Smooth1Cells(Input=SimplifyMorseSmaleComplex(Input=MorseSmaleComplex(Input=producer, ScalarField=["POINTS", "f"]),
                                                          PersistenceThreshold=percent))
    out = sm.Fetch(Reconstruct2Cells(Input=smooth))
    difference = vtk_to_numpy(out.GetPointData().GetArray("Reconstructed")) - values.ravel()
    span = values.max() - values.min()
    return np.sqrt(np.mean(difference ** 2)) / span, np.abs(difference).max() / span, out.GetFieldData()


def crop_rms(values, percent):
    rms, _, fd = crop_errors(values, percent)
    return rms, fd


def dem(name):
    reader = XMLImageDataReader(FileName=[tt.find_dataset(name)])
    image = sm.Fetch(reader)
    nx, ny, _ = image.GetDimensions()
    array = image.GetPointData().GetScalars() or image.GetPointData().GetArray(0)
    return np.array(vtk_to_numpy(array), dtype=np.float64).reshape(ny, nx)


# At 5 % the same cell's free fit misses by a sixth as much (RMS 0.7 % of the range against 8.7 %)
# but has 3 critical points more deep inside, which the release refused until a release that
# halves the RMS is kept regardless ("The axis aim released").
if tt.find_dataset("r_volcano_maunga_whau.vti"):
    for percent in (2, 5):
        rms, fd = crop_rms(dem("r_volcano_maunga_whau.vti")[0:61, 11:86].copy(), percent)
        label = "Maunga Whau crop i0 11 j0 0 75 x 61 at %d %%" % percent
        checks.check(rms <= 0.015, "%s: RMS %.3f %% of the range <= 1.5 %%" % (label, 100 * rms))
        checks.equal(tt.field_value(fd, "TopologyVerified"), 1, "%s: verdict" % label)
        print("%s: RMS %.3f %% of the range, %d cells without the axis aim" % (
            label, 100 * rms, tt.field_value(fd, "AxisFreeCells")), flush=True)


def check_window(title, name, i0, j0, w, h, largest_eps):
    """Largest error <= largest_eps eps, RMS <= 1.5 % of the range and verdict 1 at 2 and 5 %
    on a window of a shipped DEM (from Reconstructed and the window's own values)."""
    if not tt.find_dataset(name):
        return
    window = dem(name)[j0:j0 + h, i0:i0 + w].copy()
    for percent in (2, 5):
        rms, largest, fd = crop_errors(window, percent)
        largest /= percent / 100.0
        label = "%s window i0 %d j0 %d %d x %d at %d %%" % (title, i0, j0, w, h, percent)
        checks.check(rms <= 0.015, "%s: RMS %.3f %% of the range <= 1.5 %%" % (label, 100 * rms))
        checks.check(largest <= largest_eps, "%s: largest error %.2f eps <= %g" % (label, largest, largest_eps))
        checks.equal(tt.field_value(fd, "TopologyVerified"), 1, "%s: verdict" % label)
        print("%s: RMS %.3f %% of the range, largest error %.2f eps" % (label, 100 * rms, largest), flush=True)


# A Saint Helens window (a benchmark crop, docs/Reconstruction.md, "Fits no longer pulled back to
# the paper's surface") whose fits the solver's pull back towards the paper's surface undid:
# its rows mix heights of a thousand metres with millimetre margins, and the largest error was
# 14.3 eps at 2 % and 4.5 eps at 5 % (RMS 2.70 and 2.26 % of the range).
check_window("Saint Helens", "sainthelens_usgs_dem_crop.vti", 102, 110, 186, 270, 3)

# A msh_crater window (a benchmark crop, docs/Reconstruction.md, "Crossing repairs that stay
# where the pieces meet") with two long 1-cells running side by side a spacing or two apart:
# the crossing repair raised k on the whole of one to 256 segments, the 2-cell beside it got a
# grid beyond the fitted ones and kept the paper's interior, 22.4 eps off (RMS 3.97 %).
check_window("msh_crater", "msh_crater_2007_10m.vti", 68, 2, 139, 276, 3.5)

# A ttk_happi window (a benchmark crop, docs/Reconstruction.md, "Short boundary pieces that
# follow a cliff") whose short pieces along the domain's sides fall by most of their rise in the
# edge next to their node: with evenly spaced knots their heights, flat at the node, missed the
# data there by 8.1 eps at 2 % and 3.2 eps at 5 %.
check_window("ttk_happi", "ttk_happi_tas_anomaly.vti", 91, 19, 76, 70, 4)

# A Maunga Whau window and the whole ttk_happi field (a benchmark crop and a catalog run,
# docs/Reconstruction.md, "Rise knots kept through the crossing repair and on sparse pieces"):
# where pieces whose knots follow their rise crossed, the crossing repair put them back on even
# knots, whose heights missed the data by 5.4 eps (Maunga Whau at 2 %) and 5.7 eps (ttk_happi
# at 2 %: a valley piece that climbs 43 % of its rise in the edge off a junction, where its
# height starts flat). Before that, ttk_happi's largest error was 7.1 eps in a narrow cell of
# 33 vertices that kept the paper's interior (too few samples for its grid); now 4.1 eps.
check_window("Maunga Whau", "r_volcano_maunga_whau.vti", 11, 0, 75, 61, 2.5)
check_window("ttk_happi", "ttk_happi_tas_anomaly.vti", 0, 0, 192, 96, 4.5)

random_ = np.random.default_rng(20261206)
shipped = [n for n in ("r_volcano_maunga_whau.vti", "rainier_ned1_1970_crop458x306.vti", "sainthelens_usgs_dem_crop.vti",
                       "msh_crater_2007_10m.vti") if tt.find_dataset(n)]
for name in shipped:
    values = dem(name)
    ny, nx = values.shape
    w, h = int(random_.integers(min(48, nx), min(160, nx) + 1)), int(random_.integers(min(48, ny), min(160, ny) + 1))
    i0, j0 = int(random_.integers(0, nx - w + 1)), int(random_.integers(0, ny - h + 1))
    for percent in (2, 5):
        rms, fd = crop_rms(values[j0:j0 + h, i0:i0 + w].copy(), percent)
        label = "%s crop i0 %d j0 %d %d x %d at %d %%" % (name, i0, j0, w, h, percent)
        checks.check(rms <= 0.015, "%s: RMS %.3f %% of the range <= 1.5 %%" % (label, 100 * rms))
        print("%s: RMS %.3f %% of the range, verdict %d" % (label, 100 * rms, tt.field_value(fd, "TopologyVerified")), flush=True)

# The ordering rounds after the stiffening (docs/Reconstruction.md, "Critical points the
# stiffening leaves, ordered away") are reported in field data: cells whose kept fit orders
# samples; none with the paper's interior. (TestFieldReconstruction checks what they do.)
smooth = Smooth1Cells(Input=SimplifyMorseSmaleComplex(Input=MorseSmaleComplex(Input=ShepardField(Seed=1)),
                                                      PersistenceThreshold=25))
fitted = sm.Fetch(Reconstruct2Cells(Input=smooth)).GetFieldData()
paper = sm.Fetch(Reconstruct2Cells(Input=smooth, Interior=0)).GetFieldData()
ordered = tt.field_value(fitted, "OrderedCells")
checks.check(ordered is not None and ordered <= tt.field_value(fitted, "FittedCells"),
             "ordering rounds: OrderedCells %s of %s fitted cells" % (ordered, tt.field_value(fitted, "FittedCells")))
checks.equal(tt.field_value(paper, "OrderedCells"), 0, "ordering rounds: none with the paper's interior")
checks.equal(tt.field_value(fitted, "TopologyVerified"), 1, "ordering rounds, Shepard seed 1 at 25 %: verdict")
print("ordering rounds, Shepard seed 1 at 25 %%: %s cells ordered" % ordered, flush=True)
checks.finish()
