"""Stress test: seeded inputs a new user would try, each run through the four filters and
checked by an independent PL critical-point counter written here (no code shared with the core).

Cases (seeded, reproducible): uniform noise 16^2-1000^2 (and, last, images of 2-3 by 2-12
vertices), random crops of every catalog data set,
triangle-mesh versions (the same grids as vtkPolyData with jittered points, and Delaunay meshes
of random points), constant and near-constant fields, images with extents that do not start at
0, shifted origins and anisotropic spacing; thresholds 0.5-50 %, k 2-30.

For every case it records:
- VTK errors, crashes (each batch runs in its own pvpython process; a crash is recorded against
  the case that was running) and time-outs;
- the topology verdict;
- whether the counter below, run on `Reconstructed` at the input vertices, finds exactly the
  simplified complex's critical points (plus the minimum and saddle of each boundary junction),
  by index, with saddle multiplicity, boundary included. The boundary junctions are derived
  here from the complex's descending 1-cells (`route_junctions`: a boundary vertex the 1-cells
  come down to along the boundary from both sides and leave into the domain), and the complex's
  own list (field data BoundaryJunctionVertexId) must be the same;
- whether every critical point it finds lies within two edges of a node of its index (boundary
  junction pairs: within three).
It also checks that the 1-cells lie within the input's bounds (images whose extent does not
start at 0, or at z != 0). It fails on a crash or time-out, on 1-cells outside the input, on
boundary junction lists that differ, and on a dishonest verdict (1 while the counter disagrees
or 2-cells failed); the CI subset also fails when the counter's counts differ from the
complex's. Both sets end with the REQUIRED cases (inputs that once failed a 2-cell, or left a
saddle off its node): the run fails unless each of them reconstructs every 2-cell and (all but
one) verifies. The count of cases where topological sampling kept F o Phi (field data
SamplingKeptExact) is printed too.
Errors and verdicts of 0 on valid input are printed with their totals: they are still open
(docs/StressTest.md); TOPOSPLINE_STRESS_STRICT=1 fails on those too. A run the filters refuse
because it would not fit in memory (their error gives the estimate) is counted apart from the
other errors, as "refused for memory".

The counter: vertices ordered by (value, id); an interior vertex is a minimum (empty lower link),
a maximum (whole link lower) or a saddle of multiplicity c - 1 (c lower-link components, c >= 2).
A boundary vertex follows the complex's closed-boundary rule, derived in docs/MorseSmaleComplex.md:
along the boundary curve it is a minimum when both boundary neighbours are higher, a saddle when
both are lower; inside, every lower-link component touching neither boundary neighbour is a
saddle, and a lower link covering the whole link path adds a maximum.

TOPOSPLINE_STRESS=full runs the full set (>= 300 cases, a few hours); the default is the CI
subset (about 5 minutes). TOPOSPLINE_STRESS_SEED changes the seed of both.
TOPOSPLINE_STRESS_ONLY=3,27 runs only those case ids (of the chosen set). With
TOPOSPLINE_STRESS_DIAGNOSE=1, every case that is not ok also prints the filters' warnings and
the vertex ids of the complex's nodes with no critical point of their index within one edge
(missing) and of critical points with no node of their index within one edge (extra); with
TOPOSPLINE_STRESS_DUMP=<folder> every case writes its smoothed complex and reconstruction there
(`<id>_smoothed.vtm`, `<id>_reconstruction.*`), to open in ParaView. The full set's last
result is in docs/StressTest.md."""
import json
import os
import re
import shutil
import subprocess
import sys
import threading
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
FULL = os.environ.get("TOPOSPLINE_STRESS") == "full"
SEED = int(os.environ.get("TOPOSPLINE_STRESS_SEED", "13"))
ONLY = set(int(c) for c in os.environ.get("TOPOSPLINE_STRESS_ONLY", "").split(",") if c.strip())
DIAGNOSE = os.environ.get("TOPOSPLINE_STRESS_DIAGNOSE") == "1"
DUMP = os.environ.get("TOPOSPLINE_STRESS_DUMP", "")
# Each worker process runs this many cases, then a fresh one goes on: what ParaView keeps of
# hundreds of pipelines adds up (2.4 GB after 3 minutes of the full set).
CASES_PER_WORKER = 10
PVPYTHON = os.environ.get("PVPYTHON") or shutil.which("pvpython") or "pvpython"
THRESHOLDS = [0.5, 1, 2, 5, 10, 25, 50]
# Crops that once failed, in both sets whenever their file is present (after the seeded cases,
# whose ids they leave alone): full set seed 13, #109 and #176, where merged 1-cells met at a
# vertex of the boundary curve from both sides (a boundary junction no cancellation had made),
# and a listed junction was passed straight through by a rerouted 1-cell (docs/StressTest.md).
REGRESSIONS = [
    dict(file="rainier_ned1_1970_full.vti", i0=270, j0=352, w=136, h=48, percent=10.0, k=16),
    dict(file="msh_crater_2007_10m.vti", i0=25, j0=0, w=230, h=153, percent=5.0, k=21),
]
# Synthetic cases that once failed a 2-cell, in both sets (after the regression crops): each must
# reconstruct every 2-cell and (unless only="cells") verify, by the independent counter too, or
# the run fails. Full set seed 29: #248, whose boundary polygon cut across a neighbouring curve
# at 5 samples per segment (TwoCellReconstruction::BoundaryDensifications), and #246 and #291,
# where leaving out a slit outside the outer loop made the walk's (u, v) jump over more than half
# of the square's border; seed 13: #279, a nearly flat cell (2.6e-11 of range) whose sides
# differed by 4.8e-12 (a saddle left a few vertices off its node there is walked back since
# Session 36: it verifies now); seed 41:
# #201, a crop of a plateau DEM whose sides tied by rounding at a corner of a 299 grid.
REQUIRED = [
    dict(kind="mesh_grid", nx=83, ny=92, percent=2.0, k=2, seed=1004966290),
    dict(kind="mesh_grid", nx=113, ny=132, percent=0.5, k=10, seed=301360000),
    dict(kind="delaunay", points=5560, percent=5.0, k=4, seed=1393753101),
    dict(kind="delaunay", points=3213, percent=2.0, k=22, seed=1298341836),
    dict(kind="crop", file="r_volcano_maunga_whau.vti", i0=59, j0=10, w=23, h=51, percent=2.0, k=23, seed=1538941793),
    # Scattered points whose hull edges span the domain: a saddle 3-6 edges off its node
    # counted as on it while topological sampling matched saddles by distance alone (seed 41).
    dict(kind="delaunay", points=1407, percent=50.0, k=17, seed=281372017),
    dict(kind="delaunay", points=2172, percent=50.0, k=6, seed=750220743),
    # A saddle left off its node that verifies only when wanted one edge away (seed 41).
    dict(kind="noise", nx=24, ny=24, percent=25.0, k=30, seed=1935319987),
    dict(kind="mesh_grid", nx=87, ny=71, percent=1.0, k=20, seed=518899382),
    # Cells whose sides needed a grid over 512 while stage 3 doubled divisors of k (seeds 41, 29).
    dict(kind="delaunay", points=4871, percent=2.0, k=26, seed=1670037566),
    dict(kind="delaunay", points=3412, percent=5.0, k=22, seed=923347802),
    # A boundary saddle kept on a one-triangle grid corner without its maximum (seed 29).
    dict(kind="noise", nx=16, ny=16, percent=2.0, k=13, seed=136824485),
    # A boundary junction whose descent along the curve stopped beside a wanted minimum (seed 41).
    dict(kind="noise", nx=64, ny=64, percent=10.0, k=27, seed=1073766175),
    # A 2-cell beside a merged 1-cell that runs round a loop through its own saddle: the walk
    # retraced a stretch outside its loop that passed another loop point (seed 29; its verdict
    # is still 0: two boundary saddles a few vertices off their nodes).
    dict(kind="noise", nx=64, ny=64, percent=50.0, k=12, seed=1343509327, only="cells"),
    # A junction beside a one-triangle corner whose pit was placed across the corner's diagonal:
    # the junction's pair and the corner's maximum and saddle went missing (seed 53).
    dict(kind="noise", nx=24, ny=24, percent=25.0, k=3, seed=802912928),
    # A jittered grid whose corner vertex a boundary 1-cell's curve cut off: the vertex was in no
    # 2-cell (seed 53).
    dict(kind="mesh_grid", nx=91, ny=88, percent=50.0, k=2, seed=513933502),
    # Floods on Delaunay meshes whose plateaus, ordered by random ids, left a spurious
    # minimum-saddle pair and never converged (seeds 41 and 67).
    dict(kind="delaunay", points=2562, percent=25.0, k=23, seed=1030514989),
    dict(kind="delaunay", points=3112, percent=5.0, k=9, seed=1267327014),
    # A height fit whose dual program stalled in GLPK's simplex for over 15 minutes (seed 67).
    dict(kind="mesh_grid", nx=104, ny=47, percent=1.0, k=10, seed=1872602736),
    # A boundary saddle tied with the minimum below it (an integer DEM), sampled at the complex's
    # value below the junction that stage 3 had raised between them (seed 67).
    dict(kind="crop", file="r_volcano_maunga_whau.vti", i0=50, j0=11, w=30, h=49, percent=10.0, k=21, seed=1726055964),
    # Saddles left two or three vertices off their nodes, next to a spare one, with every extremum
    # in place (a boundary saddle beside a corner minimum; seeds 67 and 41): walked back one
    # vertex value at a time (WalkSpareSaddlesOntoMissing).
    dict(kind="noise", nx=32, ny=32, percent=10.0, k=5, seed=1564047253),
    dict(kind="noise", nx=64, ny=64, percent=25.0, k=18, seed=1311573360),
    # Strips two vertices wide, where every vertex lies on the boundary: topological sampling
    # took each for a domain corner and found no way up across the strip, and cut the wanted
    # boundary saddles down to the pits beside them (Session 37: 82 of 87 strips of 2 x 9, 9 x 2
    # and 2 x 12 failed, at 0 % too, where the input realizes its own complex).
    dict(kind="noise", nx=2, ny=9, percent=0.0, k=4, seed=2),
    dict(kind="noise", nx=9, ny=2, percent=5.0, k=4, seed=1),
    # A 1-cell piece of no length beside a domain corner, sampled k times at one point a few
    # ulps apart: its cell's walk was refused (zero-length edges, pinches) and 744 vertices were
    # left out (seed 97 #197; TwoCellParameterization merges such runs since Session 44).
    dict(kind="crop", file="r_volcano_maunga_whau.vti", i0=8, j0=12, w=78, h=48, percent=50.0, k=13, seed=1325395662),
    # A ridge and a valley leaving one boundary saddle half a spacing apart both claimed the
    # valley's first vertex, which kept a value above the saddle; the saddle formed eleven
    # vertices away (seed 97 #43; the vertex is the valley's since Session 45).
    dict(kind="noise", nx=48, ny=48, percent=50.0, k=24, seed=1453393452),
    # A ridge carved through the vertex by which a monkey saddle's third valley leaves: one of
    # the two saddles formed three vertices away (seed 97 #77; its link is held since Session 45).
    dict(kind="noise", nx=128, ny=128, percent=10.0, k=18, seed=163665149),
]


# --- the cases ----------------------------------------------------------------------------------
def make_cases(catalog_entries, full, seed):
    rng = np.random.default_rng(seed)
    cases = []

    def add(kind, **spec):
        spec.setdefault("percent", float(rng.choice(THRESHOLDS)))
        spec.setdefault("k", int(rng.integers(2, 31)))
        spec["kind"] = kind
        spec["seed"] = int(rng.integers(0, 2**31))
        spec["id"] = len(cases)
        cases.append(spec)

    noise_sizes = [16, 24, 32] if not full else [16, 24, 32, 48, 64, 100, 128, 200, 300, 500, 1000]
    for n in noise_sizes:
        for _ in range(2 if not full else (12 if n <= 200 else 3)):
            add("noise", nx=n, ny=n)
    for entry in catalog_entries:
        nx, ny = entry["dimensions"][:2]
        for _ in range(2 if not full else 20):
            limit = 80 if not full else 300
            w, h = int(rng.integers(16, min(limit, nx) + 1)), int(rng.integers(16, min(limit, ny) + 1))
            add("crop", file=entry["file"], i0=int(rng.integers(0, nx - w + 1)), j0=int(rng.integers(0, ny - h + 1)),
                w=w, h=h)
    for _ in range(3 if not full else 30):
        n = int(rng.integers(16, 40 if not full else 150))
        add("mesh_grid", nx=n, ny=int(rng.integers(16, 40 if not full else 150)))
    for _ in range(2 if not full else 20):
        add("delaunay", points=int(rng.integers(200, 800 if not full else 6000)))
    add("constant", nx=20, ny=15, value=1.0)
    add("constant", nx=33, ny=33, value=-7.25)
    add("near_constant", nx=30, ny=30, scale=1e-13)
    add("near_constant", nx=40, ny=25, scale=1e-300)
    add("extent", nx=40, ny=30, x0=5, y0=-3, z0=2)
    add("origin", nx=30, ny=30, origin=[1e6, -2e6, 5.0])
    add("spacing", nx=30, ny=30, spacing=[0.01, 3.0])
    if full:
        for _ in range(10):
            add("extent", nx=int(rng.integers(16, 80)), ny=int(rng.integers(16, 80)),
                x0=int(rng.integers(-50, 50)), y0=int(rng.integers(-50, 50)), z0=int(rng.integers(-5, 5)))
            # any scale, the two axes up to 1e3 apart (beyond 1e4 the input is refused)
            scale = float(10 ** rng.uniform(-3, 3))
            add("spacing", nx=int(rng.integers(16, 80)), ny=int(rng.integers(16, 80)),
                spacing=[scale, scale * float(10 ** rng.uniform(-3, 3))])
    for spec in REGRESSIONS:
        if any(entry["file"] == spec["file"] for entry in catalog_entries):
            add("crop", **spec)
    for spec in REQUIRED:
        spec = dict(spec)
        kind, case_seed, only = spec.pop("kind"), spec.pop("seed"), spec.pop("only", "verify")
        add(kind, **spec)
        cases[-1].update(seed=case_seed, required=only)
    # Images a few vertices across (one side 2 or 3, the other 2-12): last, so that no case
    # before them changes its id or its draws, and drawn from their own generator, so that they
    # are the same whichever catalog files are present. In the CI subset at 0 %, where the input
    # realizes its own complex (a heavier threshold can leave one that no values on so few
    # vertices realize: docs/Reconstruction.md, "Images a few vertices across").
    small = np.random.default_rng([seed, 2])
    for _ in range(4 if not full else 40):
        short, long_ = int(small.integers(2, 4)), int(small.integers(2, 13))
        nx, ny = (short, long_) if small.uniform() < 0.5 else (long_, short)
        percent = 0.0 if not full else float(small.choice([0.0] + THRESHOLDS))
        add("noise", nx=nx, ny=ny, percent=percent, k=int(small.integers(2, 31)))
        cases[-1]["seed"] = int(small.integers(0, 2**31))
    return cases


# --- the independent counter -------------------------------------------------------------------
def triangles_of_grid(nx, ny):
    """The complex's split of each quad along its (i+1,j)-(i,j+1) diagonal."""
    ids = np.arange(nx * ny).reshape(ny, nx)
    a, b, c, d = ids[:-1, :-1].ravel(), ids[:-1, 1:].ravel(), ids[1:, :-1].ravel(), ids[1:, 1:].ravel()
    return np.concatenate([np.column_stack([a, b, c]), np.column_stack([b, d, c])])


def vertex_links(triangles, n):
    """For each vertex: its link as a list of (u, w) edges."""
    links = [[] for _ in range(n)]
    for a, b, c in triangles.tolist():
        links[a].append((b, c))
        links[b].append((c, a))
        links[c].append((a, b))
    return links


def critical_points(values, triangles):
    """List of (vertex, index, multiplicity) by the rules in the module docstring."""
    n = len(values)
    order = np.lexsort((np.arange(n), values))
    rank = np.empty(n, dtype=np.int64)
    rank[order] = np.arange(n)
    links = vertex_links(triangles, n)
    found = []
    for v in range(n):
        edges = links[v]
        if not edges:
            continue
        # Walk the link: a cycle (interior) or a path (boundary).
        succ, pred = {}, {}
        for u, w in edges:
            succ[u] = w
            pred[w] = u
        start = next((u for u in succ if u not in pred), None)
        boundary = start is not None
        first = start if boundary else edges[0][0]
        walk = [first]
        while True:
            nxt = succ.get(walk[-1])
            if nxt is None or nxt == first:
                break
            walk.append(nxt)
        lower = [rank[u] < rank[v] for u in walk]
        if not boundary:
            changes = sum(1 for i in range(len(walk)) if lower[i] and not lower[i - 1])
            if not any(lower):
                found.append((v, 0, 1))
            elif all(lower):
                found.append((v, 2, 1))
            elif changes >= 2:
                found.append((v, 1, changes - 1))
            continue
        ends = int(lower[0]) + int(lower[-1])
        if ends == 0:
            found.append((v, 0, 1))
        elif ends == 2:
            found.append((v, 1, 1))
        if all(lower):
            found.append((v, 2, 1))
            continue
        # lower-link components (runs along the path) touching neither end of the path
        runs = 0
        i = 0
        while i < len(walk):
            if not lower[i]:
                i += 1
                continue
            j = i
            while j + 1 < len(walk) and lower[j + 1]:
                j += 1
            if i > 0 and j < len(walk) - 1:
                runs += 1
            i = j + 1
        if runs:
            found.append((v, 1, runs))
    return found


def route_junctions(triangles, descending_paths, critical_vertices):
    """Boundary vertices, on no node, where descending 1-cells come down the boundary from both
    boundary neighbours and none runs on along it: a monotone field falls into the domain there,
    a minimum and a saddle by the boundary rule. Boundary edges from the triangles (edges of one
    triangle); each path runs from its minimum up to its saddle."""
    uses = {}
    for tri in triangles.tolist():
        for a, b in ((tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])):
            key = (min(a, b), max(a, b))
            uses[key] = uses.get(key, 0) + 1
    boundary = {key for key, count in uses.items() if count == 1}
    from_above, rising = {}, set()
    for path in descending_paths:
        for i in range(1, len(path) - 1):
            v = path[i]
            if (min(v, path[i + 1]), max(v, path[i + 1])) in boundary:
                from_above.setdefault(v, set()).add(path[i + 1])
            if (min(v, path[i - 1]), max(v, path[i - 1])) in boundary:
                rising.add(v)
    return sorted(v for v, above in from_above.items()
                  if len(above) == 2 and v not in rising and v not in critical_vertices)


def descending_paths_of(block):
    """The vertex ids of each descending 1-cell of a complex's 1-cell block, minimum first."""
    from vtkmodules.util.numpy_support import vtk_to_numpy
    mesh_ids = vtk_to_numpy(block.GetPointData().GetArray("MeshCellId")).astype(int)
    kinds = vtk_to_numpy(block.GetCellData().GetArray("SeparatrixType")).astype(int)
    paths = []
    for c in range(block.GetNumberOfCells()):
        if kinds[c] != 0:
            continue
        ids = block.GetCell(c).GetPointIds()
        paths.append([int(mesh_ids[ids.GetId(k)]) for k in range(ids.GetNumberOfIds())])
    return paths


def graph_distance_ok(found, nodes, neighbours, hops):
    """Vertices of `found` farther than `hops` edges from every vertex of `nodes`."""
    reach = set(nodes)
    frontier = set(nodes)
    for _ in range(hops):
        frontier = {w for u in frontier for w in neighbours[u]} - reach
        reach |= frontier
    return [v for v in found if v not in reach]


# --- one case, in the worker process ----------------------------------------------------------
def worker(cases_file, first):
    from paraview.simple import LoadPlugin, TrivialProducer, XMLImageDataReader, Delete
    from paraview import servermanager as sm
    from vtkmodules.util.numpy_support import numpy_to_vtk, vtk_to_numpy
    from vtkmodules.vtkCommonCore import vtkPoints, vtkCommand
    from vtkmodules.vtkCommonDataModel import vtkPolyData, vtkCellArray
    from vtkmodules.vtkFiltersCore import vtkDelaunay2D
    from vtkmodules.util.misc import calldata_type
    from vtkmodules.util.vtkConstants import VTK_STRING
    import topospline_testing as tt

    import paraview.simple as simple
    LoadPlugin(tt.plugin_path(), remote=False)
    MorseSmaleComplex, SimplifyMorseSmaleComplex = simple.MorseSmaleComplex, simple.SimplifyMorseSmaleComplex
    Smooth1Cells, Reconstruct2Cells = simple.Smooth1Cells, simple.Reconstruct2Cells
    with open(cases_file) as f:
        cases = json.load(f)

    image = tt.image_data

    def polydata(points2d, triangles, values):
        pd = vtkPolyData()
        pts = vtkPoints()
        pts.SetData(numpy_to_vtk(np.column_stack([points2d, np.zeros(len(points2d))]).astype(np.float64), deep=1))
        pd.SetPoints(pts)
        cells = vtkCellArray()
        from vtkmodules.util.numpy_support import numpy_to_vtkIdTypeArray
        offsets = numpy_to_vtkIdTypeArray(np.arange(0, 3 * len(triangles) + 1, 3, dtype=np.int64), deep=1)
        conn = numpy_to_vtkIdTypeArray(np.ascontiguousarray(triangles.ravel(), dtype=np.int64), deep=1)
        cells.SetData(offsets, conn)
        pd.SetPolys(cells)
        arr = numpy_to_vtk(np.ascontiguousarray(values, dtype=np.float64), deep=1)
        arr.SetName("f")
        pd.GetPointData().AddArray(arr)
        return pd

    def build_input(case):
        rng = np.random.default_rng(case["seed"])
        kind = case["kind"]
        if kind == "noise":
            v = rng.uniform(0, 1, (case["ny"], case["nx"]))
            return image(v), v.ravel(), triangles_of_grid(case["nx"], case["ny"])
        if kind == "crop":
            reader = XMLImageDataReader(FileName=[tt.find_dataset(case["file"])])
            reader.UpdatePipeline()
            data = sm.Fetch(reader)
            Delete(reader)
            nx, ny, _ = data.GetDimensions()
            allv = vtk_to_numpy(data.GetPointData().GetArray("elevation")).reshape(ny, nx)
            v = np.array(allv[case["j0"]:case["j0"] + case["h"], case["i0"]:case["i0"] + case["w"]], dtype=np.float64)
            return image(v), v.ravel(), triangles_of_grid(case["w"], case["h"])
        if kind == "mesh_grid":
            nx, ny = case["nx"], case["ny"]
            x, y = np.meshgrid(np.arange(nx, dtype=float), np.arange(ny, dtype=float))
            pts = np.column_stack([x.ravel(), y.ravel()]) + rng.uniform(-0.2, 0.2, (nx * ny, 2))
            v = np.sin(x.ravel() / 5.0) * np.cos(y.ravel() / 7.0) + 0.3 * rng.uniform(0, 1, nx * ny)
            tris = triangles_of_grid(nx, ny)
            return polydata(pts, tris, v), v, tris
        if kind == "delaunay":
            n = case["points"]
            pts = np.concatenate([rng.uniform(0, 1, (n, 2)), [[0, 0], [1, 0], [0, 1], [1, 1]]])
            v = np.sin(6 * pts[:, 0]) * np.cos(5 * pts[:, 1]) + 0.2 * rng.uniform(0, 1, len(pts))
            cloud = polydata(pts, np.zeros((0, 3), dtype=np.int64), v)
            delaunay = vtkDelaunay2D()
            delaunay.SetInputData(cloud)
            delaunay.Update()
            out = delaunay.GetOutput()
            tris = vtk_to_numpy(out.GetPolys().GetConnectivityArray()).reshape(-1, 3).astype(np.int64)
            return polydata(pts, tris, v), v, tris
        if kind == "constant":
            v = np.full((case["ny"], case["nx"]), case["value"])
            return image(v), v.ravel(), triangles_of_grid(case["nx"], case["ny"])
        if kind == "near_constant":
            v = 1.0 + case["scale"] * rng.uniform(0, 1, (case["ny"], case["nx"]))
            return image(v), v.ravel(), triangles_of_grid(case["nx"], case["ny"])
        nx, ny = case["nx"], case["ny"]
        x, y = np.meshgrid(np.arange(nx, dtype=float), np.arange(ny, dtype=float))
        v = np.sin(x / 4.0) * np.cos(y / 5.0) + 0.05 * rng.uniform(0, 1, (ny, nx))
        if kind == "extent":
            return image(v, extent_start=(case["x0"], case["y0"], case["z0"])), v.ravel(), triangles_of_grid(nx, ny)
        if kind == "origin":
            return image(v, origin=case["origin"]), v.ravel(), triangles_of_grid(nx, ny)
        if kind == "spacing":
            return image(v, spacing=case["spacing"] + [1.0]), v.ravel(), triangles_of_grid(nx, ny)
        raise ValueError(kind)

    for case in cases[first:first + CASES_PER_WORKER]:
        print("START %d" % case["id"], flush=True)
        result = {"id": case["id"], "errors": []}
        started = time.time()
        data, values, triangles = build_input(case)
        producer = TrivialProducer()
        producer.GetClientSideObject().SetOutput(data)
        ms = MorseSmaleComplex(Input=producer)
        ms.ScalarField = ["POINTS", "f"]
        simplify = SimplifyMorseSmaleComplex(Input=ms, PersistenceThreshold=case["percent"])
        smooth = Smooth1Cells(Input=simplify, CurveSegments=case["k"])
        reconstruct = Reconstruct2Cells(Input=smooth)
        # pvpython prints through VTK's output window, so the filters' errors are caught by
        # observers (the driver also counts error lines printed while the case runs)
        @calldata_type(VTK_STRING)
        def on_error(caller, event, text):
            result["errors"].append("%s: %s" % (caller.GetClassName(), text.strip()[-400:]))

        result["warnings"] = []

        @calldata_type(VTK_STRING)
        def on_warning(caller, event, text):
            # Without VTK's "Warning: In <file>, line <n> <class> (<address>): " prefix, and
            # long enough for the verdict's list of spurious and missing points on large cases.
            message = text.strip()
            message = message[message.find("): ") + 3:] if "): " in message else message
            result["warnings"].append("%s: %s" % (caller.GetClassName(), message[:4000]))

        for proxy in (ms, simplify, smooth, reconstruct):
            proxy.GetClientSideObject().AddObserver(vtkCommand.ErrorEvent, on_error)
            if DIAGNOSE:
                proxy.GetClientSideObject().AddObserver(vtkCommand.WarningEvent, on_warning)
        reconstruct.UpdatePipeline()
        # the built-in session: the outputs are here, no need for Fetch's reduction filters
        out = reconstruct.GetClientSideObject().GetOutputDataObject(0)
        complex_ = simplify.GetClientSideObject().GetOutputDataObject(0)
        result["seconds"] = time.time() - started
        fd = out.GetFieldData()
        recon = out.GetPointData().GetArray("Reconstructed")
        verdict = fd.GetArray("TopologyVerified")
        result["verdict"] = int(verdict.GetValue(0)) if verdict else -1
        kept = fd.GetArray("SamplingKeptExact")
        result["kept_exact"] = bool(kept is not None and kept.GetValue(0) == 1)
        result["failed_cells"] = int(fd.GetArray("FailedTwoCells").GetValue(0)) if fd.GetArray("FailedTwoCells") else -1
        expected = [0, 0, 0]
        nodes = {0: [], 1: [], 2: []}
        junctions = []
        if complex_ is not None and complex_.GetNumberOfBlocks() > 0 and complex_.GetBlock(0) is not None \
                and complex_.GetBlock(0).GetPointData().GetArray("CriticalIndex") is not None:
            cps = complex_.GetBlock(0).GetPointData()
            index = vtk_to_numpy(cps.GetArray("CriticalIndex")).astype(int)
            vertex = vtk_to_numpy(cps.GetArray("VertexId")).astype(int)
            for i, v in zip(index, vertex):
                expected[i] += 1
                nodes[i].append(int(v))
            # The boundary junctions, derived here from the 1-cells' routes; the complex's own
            # list must agree.
            if complex_.GetNumberOfBlocks() > 1 and complex_.GetBlock(1) is not None:
                junctions = route_junctions(triangles, descending_paths_of(complex_.GetBlock(1)),
                                            set(nodes[0] + nodes[1] + nodes[2]))
            ja = complex_.GetFieldData().GetArray("BoundaryJunctionVertexId")
            listed = sorted(int(ja.GetValue(i)) for i in range(ja.GetNumberOfTuples())) if ja is not None else []
            result["junction_disagreement"] = listed != junctions
            expected[0] += len(junctions)
            expected[1] += len(junctions)
        result["expected"] = expected
        # The geometry where the input is: the 1-cells inside the input's bounds (an image's
        # extent need not start at 0, nor its z at 0).
        result["outside"] = False
        if complex_ is not None and complex_.GetNumberOfBlocks() > 1 and complex_.GetBlock(1) is not None \
                and complex_.GetBlock(1).GetNumberOfPoints() > 0:
            lines, domain = complex_.GetBlock(1).GetBounds(), data.GetBounds()
            slack = 1e-9 * max(domain[1] - domain[0], domain[3] - domain[2], 1e-300)
            result["outside"] = any(lines[2 * a] < domain[2 * a] - slack or lines[2 * a + 1] > domain[2 * a + 1] + slack
                                    for a in range(3))
        if recon is not None and recon.GetNumberOfTuples() == len(values):
            sampled = vtk_to_numpy(recon).astype(np.float64)
            found = critical_points(sampled, triangles)
            counted = [0, 0, 0]
            for v, i, m in found:
                counted[i] += m
            result["counted"] = counted
            neighbours = [set() for _ in range(len(values))]
            for a, b, c in triangles.tolist():
                neighbours[a] |= {b, c}
                neighbours[b] |= {a, c}
                neighbours[c] |= {a, b}
            far = 0
            for index in range(3):
                near_nodes = nodes[index] + (junctions if index < 2 else [])
                hops = 3 if junctions and index < 2 else 2
                far += len(graph_distance_ok([v for v, i, m in found if i == index], near_nodes, neighbours, hops))
            result["far"] = far
            if DIAGNOSE:
                result["missing"], result["extra"] = unmatched_points(found, nodes, junctions, neighbours)
            if DUMP:
                dump_case(case["id"], smooth, out)
            # of the range (constant fields: of the magnitude)
            scale = np.ptp(values) if np.ptp(values) > 0 else max(float(np.max(np.abs(values))), 1.0)
            result["max_error_percent"] = float(100 * np.max(np.abs(sampled - values)) / scale)
        else:
            result["counted"] = None
        print("RESULT " + json.dumps(result), flush=True)
        for proxy in (reconstruct, smooth, simplify, ms, producer):
            Delete(proxy)


# --- the driver ---------------------------------------------------------------------------------
def describe(case):
    skip = {"id", "seed", "kind"}
    return "#%d %s %s seed %d" % (case["id"], case["kind"],
                                  " ".join("%s=%s" % (k, v) for k, v in case.items() if k not in skip), case["seed"])


PROBLEMS = ("errors", "refused for memory", "crashes", "verdict 0", "count mismatches", "far critical points",
            "dishonest verdicts", "geometry outside the input", "junction lists unequal")
# The filters' refusal of a run that would not fit in memory, with its estimate ("... need about
# N GB ... available"): counted apart from other errors, as the documented answer to such a run.
MEMORY_REFUSAL = re.compile(r"need about [0-9.e+]+ GB")


def judge(r, totals):
    """The problems of one case's result, counted into totals."""
    problems = []
    if "crash" in r:
        totals["crashes"] += 1
        return ["crash (%s)" % r["crash"]]
    if r["errors"] and all(MEMORY_REFUSAL.search(e) for e in r["errors"]):
        totals["refused for memory"] += 1
        problems.append("refused for memory: %s" % r["errors"][0][-300:])
        return problems  # no output to judge
    if r["errors"]:
        totals["errors"] += 1
        problems.append("errors: %s" % r["errors"][0][:300])
    if r["verdict"] != 1:
        totals["verdict 0"] += 1
        problems.append("verdict %d (failed 2-cells %d)" % (r["verdict"], r["failed_cells"]))
    if r["counted"] != r["expected"]:
        totals["count mismatches"] += 1
        problems.append("independent count %s, complex %s" % (r["counted"], r["expected"]))
    if r.get("far"):
        totals["far critical points"] += 1
        problems.append("%d critical points far from their nodes" % r["far"])
    if r.get("outside"):
        totals["geometry outside the input"] += 1
        problems.append("1-cells outside the input's bounds")
    if r.get("junction_disagreement"):
        totals["junction lists unequal"] += 1
        problems.append("the complex's boundary junctions differ from its 1-cells' routes")
    if r["verdict"] == 1 and (r["counted"] != r["expected"] or r.get("far") or r["failed_cells"] != 0):
        totals["dishonest verdicts"] += 1
        problems.append("DISHONEST VERDICT: 1 although the independent check disagrees or 2-cells failed")
    return problems


def unmatched_points(found, nodes, junctions, neighbours):
    """Per index: node vertices with no found critical point of that index on them or one edge
    away (missing), and found ones with no such node (extra)."""
    missing, extra = {}, {}
    for index in range(3):
        wanted = nodes[index] + (junctions if index < 2 else [])
        found_here = [v for v, i, m in found if i == index]
        missing[index] = sorted(set(graph_distance_ok(wanted, found_here, neighbours, 1)))
        extra[index] = sorted(set(graph_distance_ok(found_here, wanted, neighbours, 1)))
    return missing, extra


def dump_case(case_id, smooth, reconstruction):
    from paraview.vtk.vtkIOXML import vtkXMLMultiBlockDataWriter, vtkXMLDataSetWriter
    os.makedirs(DUMP, exist_ok=True)
    writer = vtkXMLMultiBlockDataWriter()
    writer.SetInputData(smooth.GetClientSideObject().GetOutputDataObject(0))
    writer.SetFileName(os.path.join(DUMP, "%d_smoothed.vtm" % case_id))
    writer.Write()
    data_writer = vtkXMLDataSetWriter()
    data_writer.SetInputData(reconstruction)
    extension = "vtp" if reconstruction.IsA("vtkPolyData") else "vtu" if reconstruction.IsA("vtkUnstructuredGrid") else "vti"
    data_writer.SetFileName(os.path.join(DUMP, "%d_reconstruction.%s" % (case_id, extension)))
    data_writer.Write()


def main():
    sys.path.insert(0, HERE)
    import topospline_testing as tt
    present = []
    for entry in tt.catalog():
        if tt.find_dataset(entry["file"]):
            present.append(entry)
        else:
            print("SKIP %s: not found (large data sets live in ../shared/data)" % entry["file"], flush=True)
    cases = make_cases(present, FULL, SEED)
    if ONLY:
        cases = [c for c in cases if c["id"] in ONLY]
    if not FULL:
        # the CI subset: crops of the data sets shipped in the repo only, so it runs the same
        # everywhere
        cases = [c for c in cases
                 if c["kind"] != "crop" or os.path.exists(os.path.join(tt.test_data_dir(), c["file"]))]
    print("%d cases, seed %d (%s set)" % (len(cases), SEED, "full" if FULL else "CI"), flush=True)
    import tempfile
    results = {}
    # Smallest first, so that a run cut short has covered every kind of case.
    order = sorted(cases, key=lambda c: (c.get("nx", c.get("w", 40)) * c.get("ny", c.get("h", 40))
                                         if c["kind"] != "delaunay" else c["points"], c["id"]))
    by_id = {c["id"]: c for c in cases}
    with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as f:
        json.dump(order, f)
        cases_file = f.name
    position = 0
    timeout = 3600 if FULL else 600
    while position < len(cases):
        proc = subprocess.Popen([PVPYTHON, os.path.abspath(__file__), "--worker", cases_file, str(position)],
                                stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        current = None
        state = {"started": time.time(), "timed out": False, "running": True}
        output = []

        def watchdog(proc=proc, state=state):
            # a hung case sends no line: the reader alone would wait forever
            while state["running"]:
                if time.time() - state["started"] > timeout and not state["timed out"]:
                    state["timed out"] = True
                    proc.kill()
                time.sleep(2)

        threading.Thread(target=watchdog, daemon=True).start()
        for line in proc.stdout:
            output.append(line)
            if line.startswith("START "):
                current = int(line.split()[1])
                current_position = next(i for i, c in enumerate(order) if c["id"] == current)
                state["started"] = time.time()
                printed_errors = []
            elif line.startswith("RESULT "):
                r = json.loads(line[7:])
                r["errors"] += printed_errors
                results[r["id"]] = r
                current = None
                problems = judge(r, dict.fromkeys(PROBLEMS, 0))
                print("%s %s: %.1f s, L_inf %.1f %% of the range%s" % (
                    "FAIL" if problems else "ok", describe(by_id[r["id"]]), r["seconds"], r.get("max_error_percent", -1),
                    (": " + "; ".join(problems)) if problems else ""), flush=True)
                if DIAGNOSE and problems:
                    for warning in r.get("warnings", []):
                        print("   warning: " + " ".join(warning.split()), flush=True)
                    print("   missing (vertex ids by index 0/1/2): %s; extra: %s" % (r.get("missing"), r.get("extra")),
                          flush=True)
            elif line.strip() and current is not None and ("ERR" in line or "rror" in line or "Segmentation" in line):
                printed_errors.append(line.strip()[:300])
        code = proc.wait()
        state["running"] = False
        if current is None and code != 0 and not any(line.startswith("START ") for line in output):
            sys.exit("the stress worker failed before its first case:\n" + "".join(output[-30:]))
        if current is not None:
            tail = [line.strip() for line in output[-6:] if not line.startswith(("START", "RESULT"))]
            results[current] = {"id": current, "crash": ("time-out after %d s" % timeout) if state["timed out"] else
                                "exit code %d: %s" % (code, " | ".join(tail)[-500:])}
            print("FAIL %s: crash (%s)" % (describe(by_id[current]), results[current]["crash"]), flush=True)
            position = current_position + 1
        elif code != 0 and not state["timed out"]:
            sys.exit("the stress worker failed between cases (exit code %d):\n%s" % (code, "".join(output[-30:])))
        else:
            position = min(position + CASES_PER_WORKER, len(cases))
    os.unlink(cases_file)

    totals = dict.fromkeys(PROBLEMS, 0)
    totals["cases"] = len(cases)
    print("\nsummary of the failed cases:")
    for case in cases:
        problems = judge(results.get(case["id"], {"crash": "no result"}), totals)
        if problems:
            print("  FAIL %s: %s" % (describe(case), "; ".join(problems)), flush=True)
    print("totals: %(cases)d cases, %(crashes)d crashes or time-outs, %(errors)d with errors, %(refused for memory)d "
          "refused for memory (with the estimate), %(verdict 0)d verdicts "
          "not 1, %(count mismatches)d independent-count mismatches, %(far critical points)d with far critical points, "
          "%(dishonest verdicts)d dishonest verdicts, %(geometry outside the input)d with 1-cells outside the input, "
          "%(junction lists unequal)d with boundary junctions unequal to the routes'" % totals, flush=True)
    # Not a problem: topological sampling keeps F o Phi where it matches the complex better than
    # the sampling's result (a guarantee; counted to see whether it is ever needed).
    print("F o Phi kept by topological sampling: %d cases" % sum(1 for r in results.values() if r.get("kept_exact")),
          flush=True)
    # Asserted now: no crash or hang, and a verdict of 1 only where the independent check agrees.
    # Errors and verdicts of 0 on valid input are still open (docs/StressTest.md); with
    # TOPOSPLINE_STRESS_STRICT=1 they fail the run too.
    hard = (totals["crashes"] + totals["dishonest verdicts"] + totals["geometry outside the input"] +
            totals["junction lists unequal"])
    if not FULL:
        # The CI subset also holds the counts: the sampled field has exactly the simplified
        # complex's critical points on every case (the full set does not yet: StressTest.md).
        hard += totals["count mismatches"]
    def required_failed(case):
        r = results.get(case["id"], {"crash": "no result"})
        if case["required"] == "cells":
            return "crash" in r or r["errors"] or r["failed_cells"] != 0
        return bool(judge(r, dict.fromkeys(PROBLEMS, 0)))
    required_failures = [c["id"] for c in cases if c.get("required") and required_failed(c)]
    if required_failures:
        print("required cases that failed (they must reconstruct every 2-cell, most also verify): %s"
              % required_failures, flush=True)
    hard += len(required_failures)
    if os.environ.get("TOPOSPLINE_STRESS_STRICT") == "1":
        hard += (totals["errors"] + totals["refused for memory"] + totals["verdict 0"] + totals["count mismatches"] +
                 totals["far critical points"])
    print("stress test %s" % ("FAILED" if hard else "passed (no crash, no dishonest verdict%s)"
                               % ("" if FULL else ", counts equal")), flush=True)
    sys.exit(1 if hard else 0)


if __name__ in ("__main__", "__vtkconsole__") or os.path.basename(sys.argv[0]) == os.path.basename(__file__):
    if len(sys.argv) > 1 and sys.argv[1] == "--worker":
        sys.path.insert(0, HERE)
        worker(sys.argv[2], int(sys.argv[3]))
    else:
        main()
