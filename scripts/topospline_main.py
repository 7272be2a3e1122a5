"""TopoSpline main job (run by scripts/run-main.sh under pvbatch).

Runs the pipeline on the built-in Shepard field (the paper's parameters) or on a given 2D
field, and writes into the output folder: the input and every stage's result as VTK XML files
(inline binary, readable everywhere), PNG pictures in the style of the paper's figures, and
summary.json (counts, timings per stage, topology verdict, errors)."""
import argparse
import json
import os
import sys
import time

from paraview.simple import *
from paraview import servermanager as sm
from vtkmodules.vtkCommonCore import vtkSMPTools

# The paper's figure style, shared with the states.
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "states"))
import topospline_state_style as style  # noqa: E402

parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
parser.add_argument("--input", help="a 2D .vti/.vtu/.vtp file (default: the built-in Shepard field)")
parser.add_argument("--array", help="point scalar array of the input (default: the active scalars)")
parser.add_argument("--output", default="output", help="output folder (default: ./output)")
parser.add_argument("--threshold", type=float, default=5.0,
                    help="persistence threshold in %% of the maximum persistence (default 5, the default of "
                         "every TopoSpline filter; docs/Simplification.md says why)")
parser.add_argument("--k", type=int, default=4, help="cubic segments per 1-cell piece (default 4)")
parser.add_argument("--seed", type=int, default=1, help="seed of the built-in Shepard field")
args = parser.parse_args([a for a in sys.argv[1:] if a != "--"])
if not 2 <= args.k <= 1000:
    sys.exit("--k must be in [2, 1000]")
if not 0 <= args.threshold <= 100:
    sys.exit("--threshold must be a percentage in [0, 100]")

plugin = os.environ.get("TOPOSPLINE_PLUGIN")
if not plugin or not os.path.exists(plugin):
    sys.exit("TOPOSPLINE_PLUGIN must name the built TopoSpline.so (scripts/run-main.sh sets it)")
LoadPlugin(plugin, remote=False, ns=globals())
vtkSMPTools.SetBackend("STDThread")
os.makedirs(args.output, exist_ok=True)
summary = {"input": args.input or "built-in Shepard field (50 sites, mu = 2, 250 x 250, seed %d)" % args.seed,
           "smp_backend": vtkSMPTools.GetBackend(), "threads": vtkSMPTools.GetEstimatedNumberOfThreads(),
           "timings_s": {}, "stages_available": []}


def timed(name, proxy):
    start = time.perf_counter()
    proxy.UpdatePipeline()
    summary["timings_s"][name] = round(time.perf_counter() - start, 4)
    return proxy


# --- Input ---
if args.input:
    extension = os.path.splitext(args.input)[1].lower()
    readers = {".vti": XMLImageDataReader, ".vtu": XMLUnstructuredGridReader, ".vtp": XMLPolyDataReader}
    if extension not in readers:
        sys.exit("unsupported input %s (use .vti, .vtu or .vtp)" % args.input)
    source = readers[extension](FileName=[os.path.abspath(args.input)])
else:
    source = ShepardField(Seed=args.seed)
timed("input", source)
array = args.array or source.PointData.keys()[0]
summary["scalar_field"] = array

# --- Stage 1: the Morse-Smale complex ---
complex_ = MorseSmaleComplex(Input=source)
complex_.ScalarField = ["POINTS", array]
timed("1 Morse-Smale complex", complex_)
summary["stages_available"].append("Morse-Smale Complex")
data = sm.Fetch(complex_)
if data is None or data.GetNumberOfBlocks() != 4:
    sys.exit("the Morse-Smale complex could not be computed (see the error above)")
from vtkmodules.util.numpy_support import vtk_to_numpy
import numpy as np


def complex_counts(data):
    index = vtk_to_numpy(data.GetBlock(0).GetPointData().GetArray("CriticalIndex"))
    counts = {"minima": int(np.sum(index == 0)), "saddles": int(np.sum(index == 1)), "maxima": int(np.sum(index == 2)),
              "1-cells": data.GetBlock(1).GetNumberOfCells(), "2-cells": data.GetBlock(2).GetNumberOfPoints()}
    counts["critical_points"] = counts["minima"] + counts["saddles"] + counts["maxima"]
    counts["euler_characteristic"] = counts["minima"] - counts["saddles"] + counts["maxima"]
    if data.GetNumberOfBlocks() > 4:
        counts["junction_points"] = data.GetBlock(4).GetNumberOfPoints()
    return counts


summary["complex"] = complex_counts(data)

# --- Stage 2: persistence simplification ---
simplified = SimplifyMorseSmaleComplex(Input=complex_, PersistenceThreshold=args.threshold)
timed("2 simplification", simplified)
summary["stages_available"].append("Simplify Morse-Smale Complex")
simplified_data = sm.Fetch(simplified)
if simplified_data is None or simplified_data.GetNumberOfBlocks() < 4:
    sys.exit("the simplification failed (see the error above)")
summary["simplified_complex"] = complex_counts(simplified_data)
summary["simplified_complex"]["persistence_threshold_percent"] = args.threshold
sdf = simplified_data.GetFieldData()
summary["simplified_complex"]["maximum_persistence"] = sdf.GetArray("MaximumPersistence").GetValue(0)
summary["simplified_complex"]["blocked_cancellations"] = sdf.GetArray("BlockedCancellations").GetValue(0)
curve_percent = [sdf.GetArray("PersistenceCurvePercent").GetValue(i)
                 for i in range(sdf.GetArray("PersistenceCurvePercent").GetNumberOfTuples())]
curve_points = [sdf.GetArray("PersistenceCurveCriticalPoints").GetValue(i) for i in range(len(curve_percent))]

# --- Stage 3: smooth, strictly monotone 1-cells ---
smoothed = Smooth1Cells(Input=simplified, CurveSegments=args.k)
timed("3 1-cell smoothing (time I)", smoothed)
summary["stages_available"].append("Smooth 1-Cells")
smoothed_data = sm.Fetch(smoothed)
if smoothed_data is None or smoothed_data.GetNumberOfBlocks() < 7:
    sys.exit("the 1-cell smoothing failed (see the error above)")
sfd = smoothed_data.GetFieldData()
summary["smoothed_1_cells"] = {name: sfd.GetArray(name).GetValue(0) for name in (
    "CurveSegments", "NumberOfPieces", "AdaptedPieces", "RiseKnotPieces", "RefinedPieces", "RemainingCrossings",
    "PiecesOutsideDomain", "L1Error", "UnconstrainedL1Error")}
summary["smoothed_1_cells"]["bezier_segments"] = smoothed_data.GetBlock(5).GetNumberOfCells()

# --- Stage 4: the reconstruction, with its built-in topology check ---
reconstruction = Reconstruct2Cells(Input=smoothed, VerifyTopology=1)
timed("4 2-cell reconstruction (times II + III)", reconstruction)
summary["stages_available"].append("Reconstruct 2-Cells")
reconstruction_data = sm.Fetch(reconstruction)
rfd = reconstruction_data.GetFieldData() if reconstruction_data is not None else None
if rfd is None or rfd.GetArray("TopologyVerified") is None:
    sys.exit("the reconstruction failed (see the error above)")


def field_numbers(name):
    a = rfd.GetArray(name)
    values = [a.GetValue(i) for i in range(a.GetNumberOfTuples() * a.GetNumberOfComponents())]
    return values[0] if len(values) == 1 else values


value_range = field_numbers("ValueRange")
summary["reconstruction"] = {
    "topology_verified": bool(field_numbers("TopologyVerified")),
    "expected_critical_points_min_saddle_max": field_numbers("ExpectedCriticalPoints"),
    "found_critical_points_min_saddle_max": field_numbers("InputCriticalPoints"),
    "spurious_critical_points": rfd.GetArray("SpuriousCriticalPoints").GetNumberOfTuples(),
    "missing_critical_points": rfd.GetArray("MissingCriticalPoints").GetNumberOfTuples(),
    "max_error": field_numbers("MaximumError"),
    "rms_error": field_numbers("RMSError"),
    "max_error_percent_of_range": 100 * field_numbers("MaximumError") / (value_range[1] - value_range[0]),
    "rms_error_percent_of_range": 100 * field_numbers("RMSError") / (value_range[1] - value_range[0]),
    "interior": "fitted to the data" if reconstruction.Interior in (1, "Fitted") else "the paper's (boundary only)",
    "fitted_two_cells": field_numbers("FittedCells"), "refined_two_cells": field_numbers("RefinedCells"),
    "topological_sampling_changed_percent_of_vertices": 100 * field_numbers("SamplingChangedFraction"),
    "topological_sampling_largest_change_percent_of_range":
        100 * field_numbers("SamplingMaximumChange") / (value_range[1] - value_range[0]),
    "spurious_critical_points_of_F_o_Phi_near_1_cells": field_numbers("RawSpuriousNearOneCells"),
    "spurious_critical_points_of_F_o_Phi_far_from_1_cells": field_numbers("RawSpuriousFarFromOneCells"),
    "two_cells": field_numbers("TwoCells"), "failed_two_cells": field_numbers("FailedTwoCells"),
    "violating_patches": field_numbers("ViolatingPatches"), "bezier_triangles": field_numbers("BezierTriangles"),
    "time_II_delaunay_parameterization_s": round(field_numbers("ParameterizationSeconds"), 4),
    "time_III_geometry_s": round(field_numbers("SurfaceSeconds"), 4),
    "evaluation_s": round(field_numbers("EvaluationSeconds"), 4),
    "verification_s": round(field_numbers("VerificationSeconds"), 4),
}
summary["timings_s"]["total_stages_1_to_4"] = round(sum(v for k, v in summary["timings_s"].items() if k != "input"), 4)

# --- Files (inline binary XML: appended XML files are unreadable with Debian 12's expat) ---
files = {}
writers = [("input", source, ".vti" if not args.input or args.input.endswith(".vti") else
            os.path.splitext(args.input)[1]), ("complex", complex_, ".vtm"),
           ("simplified_complex", simplified, ".vtm"), ("smoothed_1_cells", smoothed, ".vtm"),
           ("reconstruction", reconstruction, ".vti" if not args.input or args.input.endswith(".vti") else
            os.path.splitext(args.input)[1])]
for name, proxy, ext in writers:
    path = os.path.join(args.output, name + ext)
    SaveData(path, proxy=proxy, DataMode="Binary", CompressorType="ZLib")
    files[name] = path
summary["files"] = files

# --- Pictures in the style of the paper: colour map + isolines; ascending 1-cells red,
# descending green; minima blue, saddles green, maxima red ---
view = CreateRenderView()
view.ViewSize = [1000, 1000]
view.OrientationAxesVisibility = 0
view.Background = [1, 1, 1]
try:
    view.UseColorPaletteForBackground = 0
except AttributeError:
    pass


def show_field(proxy):
    style.field_with_isolines(proxy, array, view)


def show_complex(ms_proxy, smooth=False):
    style.complex_lines(ms_proxy, view, block="SampledOneCells" if smooth else "OneCells")
    if ms_proxy is not complex_:
        junctions = ExtractBlock(Input=ms_proxy, Selectors=["/Root/JunctionPoints"])
        display = Show(junctions, view)
        style.solid(display, [0.0, 0.0, 0.0])
        display.SetRepresentationType("Points")
        display.RenderPointsAsSpheres = 1
        display.PointSize = 7


def save(name):
    ResetCamera(view)
    view.CameraParallelProjection = 1
    Render(view)
    path = os.path.join(args.output, name)
    SaveScreenshot(path, view, ImageResolution=[1000, 1000])
    pictures.append(path)
    for proxy in list(GetSources().values()):
        Hide(proxy, view)


def save_persistence_curve(name):
    """Critical points left against the threshold (a step function: each step is performed
    for every threshold above it), with the chosen threshold marked."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    figure, axes = plt.subplots(figsize=(7, 4.5), dpi=140)
    axes.step(curve_percent + [100], curve_points + [curve_points[-1]], where="post", color="black")
    axes.axvline(args.threshold, color="tab:red", linestyle="--",
                 label="threshold %g %%: %d critical points" % (args.threshold, sum(
                     summary["simplified_complex"][k] for k in ("minima", "saddles", "maxima"))))
    axes.set_xscale("symlog", linthresh=0.1)
    axes.set_yscale("log")
    axes.set_xlim(0, 100)
    axes.set_xlabel("persistence threshold (% of the field's range)")
    axes.set_ylabel("critical points left")
    axes.set_title("Persistence curve of %s" % (os.path.basename(args.input) if args.input else "the Shepard field (seed %d)" % args.seed))
    axes.grid(True, which="both", alpha=0.3)
    axes.legend()
    figure.tight_layout()
    path = os.path.join(args.output, name)
    figure.savefig(path)
    plt.close(figure)
    pictures.append(path)


def planar_field(data, names):
    """x, y, triangles (None for a grid: then the arrays are 2D) and the named point arrays."""
    import numpy as np
    from vtkmodules.util.numpy_support import vtk_to_numpy
    arrays = [vtk_to_numpy(data.GetPointData().GetArray(n)).astype(float) for n in names]
    if data.IsA("vtkImageData"):
        dims = [d for d in data.GetDimensions() if d > 1]
        origin, spacing, extent = data.GetOrigin(), data.GetSpacing(), data.GetExtent()
        x = origin[0] + spacing[0] * np.arange(extent[0], extent[1] + 1)
        y = origin[1] + spacing[1] * np.arange(extent[2], extent[3] + 1)
        return x, y, None, [a.reshape(dims[1], dims[0]) for a in arrays]
    points = vtk_to_numpy(data.GetPoints().GetData())
    triangles = [[data.GetCell(c).GetPointId(i) for i in range(3)] for c in range(data.GetNumberOfCells())
                 if data.GetCell(c).GetNumberOfPoints() == 3]
    return points[:, 0], points[:, 1], np.array(triangles), arrays


def save_side_by_side(input_name, output_name):
    """The input and the reconstruction with one colour map and the same isolines, and the error
    map (Reconstructed - input, symmetric diverging colours), drawn from the output arrays."""
    import numpy as np
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    data = sm.Fetch(reconstruction)
    x, y, triangles, (original, rebuilt, difference) = planar_field(data, [array, "Reconstructed", "Difference"])
    low, high = float(original.min()), float(original.max())
    levels = np.linspace(low, high, 22)[1:-1]
    span = high - low if high > low else 1.0

    def draw(axes, values, title, cmap="viridis", vmin=low, vmax=high, lines=True):
        if triangles is None:
            image = axes.imshow(values, origin="lower", extent=(x[0], x[-1], y[0], y[-1]), cmap=cmap, vmin=vmin,
                                vmax=vmax, interpolation="nearest")
            if lines:
                axes.contour(x, y, values, levels=levels, colors="k", linewidths=0.6)
        else:
            image = axes.tripcolor(x, y, triangles, values, cmap=cmap, vmin=vmin, vmax=vmax, shading="gouraud")
            if lines:
                axes.tricontour(x, y, triangles, values, levels=levels, colors="k", linewidths=0.6)
        axes.set_aspect("equal")
        axes.set_title(title)
        axes.set_xticks([])
        axes.set_yticks([])
        return image

    figure, axes = plt.subplots(1, 2, figsize=(14, 7), dpi=110)
    draw(axes[0], original, "input")
    image = draw(axes[1], rebuilt, "reconstruction (%g %%, k = %d)" % (args.threshold, args.k))
    figure.colorbar(image, ax=axes, shrink=0.7, label=array)
    path = os.path.join(args.output, input_name)
    figure.savefig(path, bbox_inches="tight")
    plt.close(figure)
    pictures.append(path)

    bound = max(float(np.abs(difference).max()), 1e-300)
    figure, axes = plt.subplots(figsize=(8, 7), dpi=110)
    image = draw(axes, difference, "reconstruction - input: max %.2f %%, RMS %.2f %% of the range" % (
        100 * bound / span, 100 * float(np.sqrt(np.mean(difference ** 2))) / span), cmap="RdBu_r", vmin=-bound,
        vmax=bound, lines=False)
    figure.colorbar(image, ax=axes, shrink=0.8, label="error")
    path = os.path.join(args.output, output_name)
    figure.savefig(path, bbox_inches="tight")
    plt.close(figure)
    pictures.append(path)


pictures = []
show_field(source)
save("1_input.png")
show_field(source)
show_complex(complex_)
save("2_morse_smale_complex.png")
show_field(source)
show_complex(simplified)
save("3_simplified_complex_%g_percent.png" % args.threshold)
show_field(source)
show_complex(smoothed, smooth=True)
save("4_smoothed_1_cells_k%d.png" % args.k)
style.field_with_isolines(reconstruction, "Reconstructed", view)
show_complex(smoothed, smooth=True)
save("5_reconstruction_k%d.png" % args.k)
style.field_with_isolines(reconstruction, "Reconstructed", view)
save("6_reconstruction_isolines_k%d.png" % args.k)
save_persistence_curve("3b_persistence_curve.png")
save_side_by_side("7_input_and_reconstruction_k%d.png" % args.k, "8_error_map_k%d.png" % args.k)
summary["pictures"] = pictures

with open(os.path.join(args.output, "summary.json"), "w") as f:
    json.dump(summary, f, indent=2)
print(json.dumps(summary, indent=2))
print("main: results in %s" % os.path.abspath(args.output))
