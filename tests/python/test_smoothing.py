"""Stage 3 through ParaView: strictly increasing heights checked on their Bezier ordinates,
exact end values and zero end slopes, one value per junction point shared by all 1-cells
through it, L1 errors, no crossings, on the synthetic fields and every catalog data set at
2, 5 and 25 % with k = 4 and 7; the display block's point budget (coarser samples, or an empty
block, with stage 4 unaffected); a better k named where a prime k oversegments noise."""
import numpy as np
from paraview.simple import *
from paraview import servermanager as sm
from vtkmodules.util.numpy_support import vtk_to_numpy

import topospline_testing as tt

LoadPlugin(tt.plugin_path(), remote=False, ns=globals())
checks = tt.Checks()

inputs = [("shepard", ShepardField()), ("trig", TrigonometricField())]
for entry in tt.catalog():
    path = tt.find_dataset(entry["file"])
    if path:
        inputs.append((entry["file"], XMLImageDataReader(FileName=[path])))
    else:
        checks.skip("%s absent (large data sets live in ../shared/data)" % entry["file"])


def check_smoothing(c, data, name, k):
    fd = data.GetFieldData()
    value_of = dict(zip(c["cp_CriticalPointId"].tolist(), c["cp_CriticalValue"].tolist()))
    value_range = max(value_of.values()) - min(value_of.values())
    bezier = data.GetBlock(5)
    checks.equal(bezier.GetCellType(0) if bezier.GetNumberOfCells() else 75, 75, "%s: cells are VTK_BEZIER_CURVE" % name)
    # Bezier ordinates of the heights, back in curve order (VTK stores the ends first).
    h = vtk_to_numpy(bezier.GetPointData().GetArray("Height")).reshape(-1, 4)[:, [0, 2, 3, 1]]
    piece = vtk_to_numpy(bezier.GetCellData().GetArray("PieceId"))
    first = np.r_[True, piece[1:] != piece[:-1]]
    last = np.r_[piece[1:] != piece[:-1], True]
    steps = np.diff(h, axis=1)
    # Strictly increasing: every ordinate step positive, except the zero end slopes.
    inner_ok = (steps[:, 1] > 0) & ((steps[:, 0] > 0) | first) & ((steps[:, 2] > 0) | last)
    checks.check(bool(np.all(inner_ok)), "%s: heights strictly increasing on their Bezier ordinates" % name)
    checks.check(bool(np.all(steps[first, 0] == 0) and np.all(steps[last, 2] == 0)),
                 "%s: zero derivative at both ends of every piece (exactly)" % name)
    checks.check(bool(np.all(h[:-1, 3][~last[:-1]] == h[1:, 0][~last[:-1]])), "%s: C0 between segments" % name)
    # Along every sampled 1-cell: strictly increasing, from the source's to the destination's
    # critical value (ties of critical values are separated by at most 1e-9 of the range).
    sampled = data.GetBlock(6)
    heights = vtk_to_numpy(sampled.GetPointData().GetArray("Height"))
    points = vtk_to_numpy(sampled.GetPoints().GetData())
    lines = sampled.GetLines()
    offsets = vtk_to_numpy(lines.GetOffsetsArray())
    conn = vtk_to_numpy(lines.GetConnectivityArray())
    src = vtk_to_numpy(sampled.GetCellData().GetArray("SourceId"))
    dst = vtk_to_numpy(sampled.GetCellData().GetArray("DestinationId"))
    bad_monotone = bad_ends = 0
    at_point = {}
    shared_bad = 0
    for i in range(len(offsets) - 1):
        ids = conn[offsets[i]:offsets[i + 1]]
        hv = heights[ids]
        if len(ids) < 2:  # a 1-cell of one point: a saddle on its minimum's vertex
            continue
        # Strictness is proven on the ordinates above; dense samples next to a zero end slope
        # differ by less than a double's resolution (and evaluation rounds): never decreasing,
        # up to rounding.
        bad_monotone += not bool(np.all(np.diff(hv) >= -1e-12 * np.abs(hv[1:])))
        tolerance = 1e-9 * value_range + 1e-12 * abs(hv[0])
        bad_ends += abs(hv[0] - value_of[int(src[i])]) > tolerance or abs(hv[-1] - value_of[int(dst[i])]) > tolerance
        for p, value in zip(map(tuple, np.round(points[ids], 9)), hv):
            if p in at_point and at_point[p][1] != i and abs(at_point[p][0] - value) > 1e-9 * value_range:
                shared_bad += 1
            at_point.setdefault(p, (value, i))
    checks.equal(bad_monotone, 0, "%s: sampled heights never decrease along any 1-cell" % name)
    checks.equal(bad_ends, 0, "%s: 1-cells start and end at the critical values" % name)
    checks.equal(shared_bad, 0, "%s: 1-cells through one point (junctions) agree on its value" % name)
    l1, free = fd.GetArray("L1Error").GetValue(0), fd.GetArray("UnconstrainedL1Error").GetValue(0)
    checks.check(l1 >= free * (1 - 1e-9), "%s: monotone L1 error >= unconstrained (%g vs %g)" % (name, l1, free))
    checks.equal(fd.GetArray("PiecesOutsideDomain").GetValue(0), 0, "%s: curves stay in the domain" % name)
    return fd.GetArray("RemainingCrossings").GetValue(0), fd.GetArray("AdaptedPieces").GetValue(0), l1, free


for name, source in inputs:
    source.UpdatePipeline()
    ms = MorseSmaleComplex(Input=source)
    for percent in (2, 5, 25):
        simplified = SimplifyMorseSmaleComplex(Input=ms, PersistenceThreshold=percent)
        for k in (4, 7):
            smooth = Smooth1Cells(Input=simplified, CurveSegments=k)
            smooth.UpdatePipeline()
            data = sm.Fetch(smooth)
            label = "%s %d%% k=%d" % (name, percent, k)
            if not checks.check(data is not None and data.GetNumberOfBlocks() == 7, "%s: 7 output blocks" % label):
                continue
            c = tt.fetch_complex(smooth)
            crossings, adapted, l1, free = check_smoothing(c, data, label, k)
            checks.equal(crossings, 0, "%s: smoothed 1-cells do not cross" % label)
            print("%s: adapted %d pieces, L1 %.6g (unconstrained %.6g)" % (label, adapted, l1, free), flush=True)
            Delete(smooth)

# The display block's point budget: sampled more coarsely above it, left empty when even one
# point per segment is too many; stage 4 reads the Bezier block and does not notice.
shepard = ShepardField()
simplified = SimplifyMorseSmaleComplex(Input=MorseSmaleComplex(Input=shepard), PersistenceThreshold=5)
full = Smooth1Cells(Input=simplified, CurveSegments=4)
full_data = sm.Fetch(full)
full_points = full_data.GetBlock(6).GetNumberOfPoints()
lines = full_data.GetBlock(6).GetNumberOfCells()
checks.equal(int(full_data.GetFieldData().GetArray("SampledSamplesPerSegment").GetValue(0)), 16,
             "budget: 16 samples per segment within the default budget")
for budget, expect_empty in ((full_points // 3, False), (10, True)):
    small = Smooth1Cells(Input=simplified, CurveSegments=4, MaximumSampledPoints=budget)
    data = sm.Fetch(small)
    used = int(data.GetFieldData().GetArray("SampledSamplesPerSegment").GetValue(0))
    block = data.GetBlock(6)
    if expect_empty:
        checks.check(used == 0 and block.GetNumberOfPoints() == 0, "budget %d: block left empty" % budget)
    else:
        checks.check(0 < used < 16 and block.GetNumberOfPoints() <= budget and block.GetNumberOfCells() == lines,
                     "budget %d: %d samples per segment, %d points, a line per 1-cell" % (budget, used, block.GetNumberOfPoints()))
        c = tt.fetch_complex(small)
        check_smoothing(c, data, "budget %d" % budget, 4)
    recon = Reconstruct2Cells(Input=small)
    recon.UpdatePipeline()
    verdict = sm.Fetch(recon).GetFieldData().GetArray("TopologyVerified").GetValue(0)
    checks.equal(int(verdict), 1, "budget %d: stage 4 verifies on the coarser display block" % budget)
    Delete(recon)
    Delete(small)

# A prime k on noise: short pieces keep k segments (no divisor to give them fewer), the filter
# names a better k in field data (and a warning), and that k does take far fewer segments.
from vtkmodules.util.numpy_support import numpy_to_vtk
from vtkmodules.vtkCommonDataModel import vtkImageData
image = vtkImageData()
image.SetDimensions(60, 60, 1)
noise_values = numpy_to_vtk(np.random.default_rng(49).uniform(0, 1, 3600), deep=1)
noise_values.SetName("f")
image.GetPointData().AddArray(noise_values)
noise = TrivialProducer()
noise.GetClientSideObject().SetOutput(image)
noise_complex = MorseSmaleComplex(Input=noise)
noise_complex.ScalarField = ["POINTS", "f"]
noise_simplified = SimplifyMorseSmaleComplex(Input=noise_complex, PersistenceThreshold=2)
segments_at = {}
for k in (11, 12):
    smooth = Smooth1Cells(Input=noise_simplified, CurveSegments=k)
    data = sm.Fetch(smooth)
    fd = data.GetFieldData()
    segments_at[k] = (data.GetBlock(5).GetNumberOfCells(), int(fd.GetArray("SuggestedCurveSegments").GetValue(0)),
                      int(fd.GetArray("OversegmentedPieces").GetValue(0)), int(fd.GetArray("NumberOfPieces").GetValue(0)))
    Delete(smooth)
checks.check(segments_at[11][1] not in (0, 11) and segments_at[11][2] > segments_at[11][3] // 2,
             "60^2 noise at 2 %%, k = 11: most pieces oversegmented (%d of %d), k = %d suggested"
             % (segments_at[11][2], segments_at[11][3], segments_at[11][1]))
print("60^2 noise at 2 %%: k = 11: %d Bezier segments, %d of %d pieces oversegmented, k = %d suggested; k = 12: %d segments"
      % (segments_at[11][0], segments_at[11][2], segments_at[11][3], segments_at[11][1], segments_at[12][0]), flush=True)
checks.equal(segments_at[12][1], 0, "60^2 noise at 2 %, k = 12: nothing to suggest")
checks.check(segments_at[12][0] * 3 < segments_at[11][0],
             "60^2 noise at 2 %%: %d Bezier segments at k = 12, %d at k = 11" % (segments_at[12][0], segments_at[11][0]))
checks.finish()
