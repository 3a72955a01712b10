"""The fixed costs of a small run (issue 16): the mortar evaluation kept between
calls, the numpy grid of the contact search, the imports a run leaves out.

No timings are asserted: each test checks that a shortcut gives what the long
way gives, or counts the work done."""

import subprocess
import sys

import numpy as np
import pytest

from skfem_mortar.contact import search
from skfem_mortar.contact.search import box_pairs, nearest_vertex, segment_boxes
import test_search
from test_search import _brute as _brute_pairs, _chain


# ---------------------------------------------------------------- the search grid
@pytest.mark.parametrize("grid_points", [10**9, 0])  # the grid; the k-d tree
@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("margin", [0.0, 0.02, 0.4])
def test_box_pairs_of_grid_and_tree_equal_brute_force(monkeypatch, grid_points, seed, margin):
    """Both range queries of :func:`box_pairs` (the grid up to ``GRID_POINTS``,
    ``cKDTree`` above) give every overlapping pair and no other (exact test)."""
    monkeypatch.setattr(search, "GRID_POINTS", grid_points)
    rng = np.random.default_rng(seed)
    xs, ss = _chain(rng, 300, 0.05)
    xm, sm = _chain(rng, 200, 0.08)
    xm += xs[:, 150:151] - xm[:, 100:101]  # the chains cross
    # touching boxes: the slave's first segment ends exactly where a master box starts
    xs[:, 0] = xm[:, 5] - [margin, 0.0]
    i, j = box_pairs(*segment_boxes(xs, ss), *segment_boxes(xm, sm), margin)
    bi, bj = _brute_pairs(*segment_boxes(xs, ss), *segment_boxes(xm, sm), margin)
    np.testing.assert_array_equal(i, bi)
    np.testing.assert_array_equal(j, bj)
    assert len(i) > 0


def test_grid_examines_linearly_many_candidates(monkeypatch):
    """The counting test of the search (a linear number of candidates, not
    n^2) on the grid: ``GRID_POINTS`` above its sizes."""
    monkeypatch.setattr(search, "GRID_POINTS", 10**9)
    test_search.test_search_examines_linearly_many_candidates(monkeypatch)


def _brute_nearest(x, p):
    d = np.sqrt((p[0][:, None] - x[0]) ** 2 + (p[1][:, None] - x[1]) ** 2)
    k = np.argmin(d, axis=1)  # the first of equal minima
    return d[np.arange(p.shape[1]), k], k


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("m", [3, 400])
def test_nearest_vertex_equals_brute_force(seed, m):
    """Against every distance: equal to the last bit (the same formula), the
    same vertex (random points: no ties), points far outside the vertices'
    box (the tree's fallback) included."""
    rng = np.random.default_rng(seed)
    x, _ = _chain(rng, m, 0.1)
    near = x[:, rng.integers(0, m, 500)] + rng.normal(scale=0.05, size=(2, 500))
    far = rng.normal(scale=50.0, size=(2, 60))
    p = np.concatenate([near, far], axis=1)
    d, k = nearest_vertex(x, p)
    bd, bk = _brute_nearest(x, p)
    np.testing.assert_array_equal(d, bd)
    np.testing.assert_array_equal(k, bk)


def test_nearest_vertex_breaks_ties_by_the_lowest_index():
    """Points midway between two vertices of a surface (a straight chain, the
    grid's case; 60 x 600 pairs, past the all-pairs count): the lower index."""
    g = np.arange(600.0)
    x = np.stack([g, np.zeros_like(g)])
    p = np.stack([g[:60] + 0.5, np.full(60, 0.25)])
    d, k = nearest_vertex(x, p)
    np.testing.assert_array_equal(k, np.arange(60))
    np.testing.assert_array_equal(d, np.full(60, np.sqrt(0.5 * 0.5 + 0.25 * 0.25)))


def test_nearest_vertex_refuses_no_vertices():
    with pytest.raises(ValueError, match="x"):
        nearest_vertex(np.zeros((2, 0)), np.zeros((2, 3)))


# ---------------------------------------------------- the kept mortar evaluation
def _hertz_pair():
    from skfem_mortar.app.runner import run_scene
    _, result, _ = run_scene("hertz", {"refine": -2}, "mortar", return_result=True)
    pair = next(it for it in result.model.items if hasattr(it, "discretization"))
    return pair, result.z.copy()


def test_kept_evaluation_answers_as_a_new_kernel_call(monkeypatch):
    """Calls at the same positions and options are answered from the last
    kernel call, with exactly the values of a new call (the kernel's values do
    not depend on what else it computes) and without the ``G``/``H`` not asked
    for; other positions, other multipliers for ``H``, a new reach make a
    new call."""
    from skfem_mortar.contact import mortar_kernel
    pair, z = _hertz_pair()
    d = pair.discretization
    calls = []
    real = d._kernel

    def counting(*a, **k):
        calls.append(k.get("tangent"))
        return real(*a, **k)

    monkeypatch.setattr(d, "_kernel", counting)
    d._last = None
    full = pair.evaluate(z, tangent=True, with_lam=True)
    assert full.H is not None and len(calls) == 1
    lean = pair.evaluate(z, tangent=False, with_lam=False)
    g_only = pair.evaluate(z, tangent=True, with_lam=False)
    again = pair.evaluate(z, tangent=True, with_lam=True)
    assert len(calls) == 1  # all three from the kept call
    assert lean.G is None and lean.H is None and g_only.H is None and g_only.G is not None
    assert again.H is full.H
    fresh = mortar_kernel.evaluate(pair.slave.x(z), pair.slave.segments, pair.master.x(z),
                                   pair.master.segments, tangent=False, **d._extra(
                                       pair.slave.x(z), pair.master.x(z))[0],
                                   **d._kernel_options)
    for name in ("area", "mask"):
        np.testing.assert_array_equal(getattr(lean, name), getattr(fresh, name))
    # the kept call had H: its cells without multipliers went in a first-order pass of
    # their own (mortar_kernel.passes), so a node's contributions to g (the same values)
    # are added in another order than in a new call's one pass: g and D to round-off
    # (measured 3.4e-21 on a g of 2.3e-5 with SuperLU's state; bit for bit with PARDISO's)
    assert abs(lean.g - fresh.g).max() <= 1e-15 * abs(fresh.g).max()
    assert abs(lean.info["D"] - fresh.info["D"]).max() <= 1e-15 * abs(fresh.info["D"]).max()
    for name in ("g", "area", "mask"):
        assert not getattr(lean, name).flags.writeable
    # H for other multipliers, other positions: new calls
    z2 = z.copy()
    z2[pair._normal] *= 2.0
    pair.evaluate(z2, tangent=True, with_lam=True)
    assert len(calls) == 2
    pair.evaluate(z2, tangent=False, with_lam=False)  # positions as before: kept
    assert len(calls) == 2
    z3 = z2.copy()
    z3[pair.slave.dofs()[1]] += 1e-9
    pair.evaluate(z3, tangent=False, with_lam=False)
    assert len(calls) == 3
    # a tangent the kept call did not compute
    pair.evaluate(z3, tangent=True, with_lam=False)
    assert len(calls) == 4
    # a new reference (another search reach) at the same positions
    pair.converged_positions = (pair.slave.x(z) + 1e-3, pair.master.x(z))
    pair.evaluate(z3, tangent=False, with_lam=False)
    assert len(calls) == 5


def test_a_hertz_run_calls_the_mortar_kernel_once_per_assembly_and_step_end(monkeypatch):
    """The KKT check after the last assembly and the outputs after the step
    reuse the kernel's calls: one call per Newton assembly, plus the
    preflight's and one after the step's end moved the search reach."""
    from skfem_mortar.app.runner import run_scene
    from skfem_mortar.contact import mortar_method
    calls = []
    real = mortar_method.Mortar.evaluate

    def count_kernel(self, xs, xm, lam, tangent):
        kernel = self._kernel
        self._kernel = lambda *a, **k: (calls.append(1), kernel(*a, **k))[1]
        try:
            return real(self, xs, xm, lam, tangent)
        finally:
            self._kernel = kernel

    monkeypatch.setattr(mortar_method.Mortar, "evaluate", count_kernel)
    summary = run_scene("hertz", {"refine": -2}, "mortar", steps=1)
    its = sum(s["newton_iterations"] for s in summary["steps"])
    assert len(calls) == (its + 1) + 2


# ------------------------------------------------------------ imports of a run
#: modules a small run without progress bar does not need: the search's grid and
#: the series' own VTU writer replace scipy.spatial and meshio (0.1 and 0.05 s of
#: imports), tqdm (25 ms with its version lookup) is imported only for a progress
#: bar, and the checkpoint's run id is os.urandom's, not uuid's (its import, 3 ms,
#: brings platform); socket stays (scipy.sparse imports it via numpy.testing)
UNNEEDED = ("scipy.spatial", "meshio", "uuid", "tqdm")


def test_a_small_mortar_run_does_not_import_scipy_spatial_or_meshio(tmp_path):
    """A small run (no progress bar) imports none of :data:`UNNEEDED`."""
    code = ("import sys\n"
            "from skfem_mortar.app import cli\n"
            f"cli.main(['run', 'hertz', '--method', 'mortar', '--set', 'refine=-2', '--out', "
            f"{str(tmp_path / 'run')!r}, '--no-progress'])\n"
            f"print(sorted(set({UNNEEDED!r}) & set(sys.modules)))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout
    assert out.strip().splitlines()[-1] == "[]"


# ------------------------------------------------------------ the hertz mesh
@pytest.mark.parametrize("refine", [-2, 0])
def test_hertz_boundary_nodes_equal_skfem(refine):
    """The mesh build's boundary nodes (numpy, no facet tables) are skfem's."""
    from skfem import MeshTri
    from skfem_mortar.scenes.hertz import _boundary_nodes, graded_quarter_disk
    mesh = graded_quarter_disk(8.0, 0.05 * 2.0 ** -refine, 0.5)
    m = MeshTri(mesh.p, mesh.t)
    np.testing.assert_array_equal(_boundary_nodes(m.t, m.p.shape[1]), m.boundary_nodes())


def test_hertz_boundary_nodes_int32_many_nodes():
    """int32 triangles (skfem's refined meshes) with node numbers whose square
    overflows int32: the keys are int64 (hertz refine=3 refined without end)."""
    from skfem import MeshTri
    from skfem_mortar.scenes.hertz import _boundary_nodes
    m = MeshTri.init_tensor(np.linspace(0, 1, 250), np.linspace(0, 1, 250))
    t = m.t.astype(np.int32)
    assert m.p.shape[1] ** 2 > np.iinfo(np.int32).max
    np.testing.assert_array_equal(_boundary_nodes(t, m.p.shape[1]), m.boundary_nodes())


# ------------------------------------------------------------ the VTU writer
@pytest.mark.parametrize("cell_type,k", [("triangle", 3), ("quad", 4), ("line", 2),
                                         ("line3", 3), ("triangle6", 6), ("vertex", 1)])
def test_vtu_text_reads_back_as_written(tmp_path, cell_type, k):
    """meshio reads the frame :func:`vtu_text` writes as the data it was given:
    points, cells, vector, scalar and integer point fields, cell fields of two
    blocks, exactly."""
    import meshio
    from skfem_mortar.output.io import vtu_text
    rng = np.random.default_rng(1)
    pts = np.column_stack([rng.normal(size=(12, 2)), np.zeros(12)])
    c1, c2 = rng.integers(0, 12, (5, k)), rng.integers(0, 12, (3, k))
    pd = {"displacement": rng.normal(size=(12, 3)), "pressure": rng.normal(size=12),
          "flag": rng.integers(0, 2, 12).astype(np.int64)}
    cd = {"sigma": [rng.normal(size=5), rng.normal(size=3)]}
    path = tmp_path / "f.vtu"
    path.write_text(vtu_text(pts, [(cell_type, c1), (cell_type, c2)], pd, cd))
    m = meshio.read(path)
    np.testing.assert_array_equal(m.points, pts)
    got = np.concatenate([b.data for b in m.cells])
    np.testing.assert_array_equal(got, np.concatenate([c1, c2]))
    assert {b.type for b in m.cells} == {cell_type}
    for name, v in pd.items():
        np.testing.assert_array_equal(m.point_data[name], v)
    np.testing.assert_array_equal(np.concatenate(m.cell_data["sigma"]), np.concatenate(cd["sigma"]))


def test_vtu_text_leaves_other_cells_and_dtypes_to_meshio():
    from skfem_mortar.output.io import vtu_text
    pts = np.zeros((6, 3))
    # the 3D bodies' cells (tetra, hexahedron and their quadratic forms) are written
    # here now; a cell type no body makes (a wedge) is still meshio's
    wedge = [("wedge", np.array([[0, 1, 2, 3, 4, 5]]))]
    tri = [("triangle", np.array([[0, 1, 2]]))]
    assert vtu_text(pts, wedge, {}, {}) is None
    assert vtu_text(pts, tri, {"b": np.ones(6, dtype=bool)}, {}) is None
    assert vtu_text(pts, tri, {}, {"s": [np.ones(1), np.ones(1)]}) is None  # blocks mismatch
