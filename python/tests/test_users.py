"""What users of ASE, MDAnalysis, freud, pandas, matplotlib, scipy and VTK hand over and
expect back, tested against those packages themselves: boxes as they write them, their
systems, neighbour lists, tables, pictures and files."""

import subprocess

import numpy as np
import pytest

import orbitri

import ase  # noqa: E402  (test dependencies: pip install .[test])
import ase.build
import ase.geometry
import freud
import MDAnalysis as mda
from MDAnalysis.lib.mdamath import triclinic_vectors
import pandas as pd

from test_orbitri import _cli  # noqa: E402


def _fcc(n, a=0.1):
    basis = np.array([[0, 0, 0], [0.5, 0.5, 0], [0.5, 0, 0.5], [0, 0.5, 0.5]])
    cells = np.array([[i, j, k] for i in range(n) for j in range(n) for k in range(n)])
    return (cells[:, None, :] + basis).reshape(-1, 3) * a


# -- boxes ---------------------------------------------------------------------------


CELLPARS = [
    [10, 10, 10, 90, 90, 90],
    [3, 4, 5, 90, 90, 120],
    [5.1, 6.2, 7.3, 81, 97, 104],
    [4, 4, 4, 60, 60, 60],
]


@pytest.mark.parametrize("cellpar", CELLPARS)
def test_cellpar_is_ase_s_and_mdanalysis_s_box(cellpar):
    box = orbitri.Box.from_cellpar(*cellpar)
    np.testing.assert_allclose(box.matrix, ase.geometry.cellpar_to_cell(cellpar), atol=1e-12)
    np.testing.assert_allclose(box.matrix, triclinic_vectors(np.array(cellpar, dtype=float)), atol=1e-5)
    np.testing.assert_allclose(box.cellpar(), cellpar, rtol=1e-12)
    # one sequence, as ase's cellpar() and MDAnalysis's dimensions give them
    assert orbitri.Box.from_cellpar(np.array(cellpar)) == box


def test_cellpar_errors_name_the_problem():
    with pytest.raises(ValueError, match="make no cell"):
        orbitri.Box.from_cellpar(1, 1, 1, 120, 120, 120)
    with pytest.raises(ValueError, match="cell angle β is 180"):
        orbitri.Box.from_cellpar(1, 1, 1, 90, 180, 90)
    with pytest.raises(ValueError, match="cell length a is -1"):
        orbitri.Box.from_cellpar(-1, 1, 90)
    with pytest.raises(ValueError, match=r"\[a, b, c, alpha, beta, gamma\] \(3D\) or \[a, b, gamma\] \(2D\), not 4"):
        orbitri.Box.from_cellpar(1, 1, 1, 90)
    with pytest.raises(ValueError, match="must be finite"):
        orbitri.Box.from_cellpar(1, 1, np.nan)


def test_six_numbers_that_look_like_angles_name_from_cellpar():
    pts = np.random.default_rng(0).random((50, 3)) * 10
    with pytest.raises(ValueError) as e:
        orbitri.PeriodicDelaunay(pts, [10, 10, 10, 90, 90, 90])
    message = str(e.value)
    assert "orbitri.Box.from_cellpar(10, 10, 10, 90, 90, 90)" in message
    assert "freud's tilt factors [Lx, Ly, Lz, xy, xz, yz]" in message
    assert "skewed" not in message
    with pytest.raises(ValueError, match=r"Box.from_cellpar\(1, 1, 60\)"):
        orbitri.PeriodicDelaunay(pts[:, :2] / 10, [1, 1, 60])
    # the explicit constructors say what the numbers are
    vor = orbitri.periodic_voronoi(pts, orbitri.Box.from_cellpar([10, 10, 10, 90, 90, 90]))
    assert abs(vor.volumes.sum() - 1000) < 1e-9
    # small tilts stay freud's
    assert orbitri.lattice_matrix([1, 1, 1, 0.5, 0.25, 0], 3)[2, 0] == 0.25


def test_lammps_gromacs_freud_and_matrix_boxes():
    # LAMMPS: tilts are lengths; freud's from_box takes LAMMPS-style lengths and tilt factors
    lammps = orbitri.Box.from_lammps(-1, 9, 0, 8, 2, 8, 2.0, 1.0, -1.5)
    fb = freud.box.Box(10, 8, 6, 2.0 / 8, 1.0 / 6, -1.5 / 6)
    np.testing.assert_allclose(lammps.matrix, fb.to_matrix().T, atol=1e-12)
    np.testing.assert_allclose(orbitri.Box.from_freud(fb).matrix, lammps.matrix, atol=1e-12)
    np.testing.assert_allclose(orbitri.Box.from_freud([10, 8, 6, 0.25, 1 / 6, -0.25]).matrix, lammps.matrix, atol=1e-12)
    assert orbitri.Box.from_lammps(0, 2, 0, 3, 1.0).matrix.tolist() == [[2, 0], [1, 3]]
    assert orbitri.Box.from_freud(freud.box.Box.square(3)).dimension == 2
    assert orbitri.Box.from_freud([3, 4]).matrix.tolist() == [[3, 0], [0, 4]]
    with pytest.raises(ValueError, match="6 or 9 numbers"):
        orbitri.Box.from_lammps(0, 1, 0, 1, 0, 1, 0)
    with pytest.raises(ValueError, match="3 or 9 numbers, not 6"):
        orbitri.Box.from_gromacs([1] * 6)
    with pytest.raises(ValueError, match="2×2 or 3×3"):
        orbitri.Box.from_matrix(np.eye(4))
    # each is accepted wherever a box is
    rng = np.random.default_rng(2)
    pts = rng.random((500, 3)) @ lammps.matrix
    for box in (lammps, fb, lammps.matrix):
        vor = orbitri.periodic_voronoi(pts, box)
        assert abs(vor.volumes.sum() - lammps.volume) < 1e-9 * lammps.volume
    np.testing.assert_array_equal(orbitri.lattice_matrix(lammps, 3), lammps.matrix)


def test_gromacs_box_line_is_what_mdanalysis_reads(tmp_path):
    line = "   4.00000   5.00000   6.00000   0.00000   0.00000   1.00000   0.00000  -1.50000   2.00000"
    gro = tmp_path / "box.gro"
    gro.write_text("box\n    1\n    1SOL     OW    1   0.100   0.200   0.300\n" + line + "\n")
    u = mda.Universe(str(gro))
    # MDAnalysis reads nm as Å (×10)
    np.testing.assert_allclose(orbitri.Box.from_gromacs(line).matrix * 10, triclinic_vectors(u.dimensions), atol=1e-3)
    np.testing.assert_allclose(orbitri.Box.from_gromacs(line).matrix, [[4, 0, 0], [1, 5, 0], [-1.5, 2, 6]])


# -- systems -------------------------------------------------------------------------


def test_ase_atoms():
    atoms = ase.build.bulk("Cu", "fcc", a=3.6, cubic=True).repeat((3, 3, 3))
    tri = orbitri.PeriodicDelaunay(atoms)
    np.testing.assert_allclose(tri.lattice, np.asarray(atoms.cell))
    vor = orbitri.periodic_voronoi(atoms)
    assert abs(vor.volumes.sum() - atoms.get_volume()) < 1e-9 * atoms.get_volume()
    # a triclinic primitive cell, rattled
    prim = ase.build.bulk("Cu", "fcc", a=3.6).repeat((4, 4, 4))
    prim.rattle(1e-3, seed=1)
    vor = orbitri.periodic_voronoi(prim)
    assert abs(vor.volumes.sum() - prim.get_volume()) < 1e-9 * prim.get_volume()
    nl = vor.neighbor_list(min_area_fraction=0.01)
    assert (nl.counts == 12).all()


def test_ase_atoms_must_be_periodic():
    slab = ase.build.fcc111("Cu", size=(3, 3, 3), vacuum=5.0)
    assert slab.pbc.tolist() == [True, True, False]
    with pytest.raises(ValueError, match=r"not periodic along z \(pbc=\[True, True, False\]\).*atoms.pbc = True"):
        orbitri.PeriodicDelaunay(slab)
    slab.pbc = True
    vor = orbitri.periodic_voronoi(slab)
    assert abs(vor.volumes.sum() - slab.get_volume()) < 1e-9 * slab.get_volume()
    with pytest.raises(ValueError, match="have no cell"):
        orbitri.PeriodicDelaunay(ase.Atoms("H2", positions=[[0, 0, 0], [1, 0, 0]], pbc=True))


def test_mdanalysis_universe_and_atomgroup():
    n = 400
    dims = np.array([20.0, 22.0, 24.0, 80.0, 100.0, 110.0])
    u = mda.Universe.empty(n, trajectory=True)
    frac = np.random.default_rng(3).random((n, 3))
    u.atoms.positions = (frac @ triclinic_vectors(dims)).astype(np.float32)
    u.dimensions = dims
    volume = mda.lib.mdamath.box_volume(dims)
    for system in (u, u.atoms, u.atoms[:200]):
        vor = orbitri.periodic_voronoi(system)
        assert abs(vor.volumes.sum() - volume) < 1e-9 * volume
    # the lattice is lengths and angles, read as such (not as freud's tilts)
    tri = orbitri.PeriodicDelaunay(u)
    np.testing.assert_allclose(tri.lattice, triclinic_vectors(dims), atol=1e-4)
    # the same cells as freud's, given the right box
    fbox = freud.box.Box.from_matrix(tri.lattice.T)
    theirs = freud.locality.Voronoi().compute((fbox, u.atoms.positions.astype(np.float64)))
    np.testing.assert_allclose(orbitri.periodic_voronoi(u).volumes, theirs.volumes, rtol=1e-4)
    u.dimensions = None
    with pytest.raises(ValueError, match="has no box"):
        orbitri.PeriodicDelaunay(u)


def test_freud_system_tuples():
    # tilts exact in float32, freud's precision
    box = freud.box.Box(2.0, 1.5, 1.0, 0.25, 0.0, 0.125)
    pts = box.wrap(box.make_absolute(np.random.default_rng(4).random((300, 3)))).astype(np.float64)
    theirs = freud.locality.Voronoi().compute((box, pts)).volumes
    np.testing.assert_allclose(orbitri.periodic_voronoi((box, pts)).volumes, theirs, rtol=1e-9)
    np.testing.assert_allclose(orbitri.periodic_voronoi(([2.0, 1.5, 1.0, 0.25, 0.0, 0.125], pts)).volumes, theirs, rtol=1e-9)
    # 2D: N × 3 points with z = 0 in a 2D box
    box2 = freud.box.Box.square(2.0)
    p2 = np.column_stack([np.random.default_rng(5).random((100, 2)) * 2 - 1, np.zeros(100)])
    assert orbitri.PeriodicDelaunay((box2, p2)).dimension == 2
    with pytest.raises(TypeError, match="not a system"):
        orbitri.PeriodicDelaunay(np.zeros((5, 3)))


# -- neighbours ----------------------------------------------------------------------


def test_neighbor_list_against_freud_and_scipy():
    box = freud.box.Box.cube(1.0)
    pts = np.random.default_rng(6).random((400, 3)).astype(np.float32).astype(np.float64)
    theirs = freud.locality.Voronoi().compute((box, pts)).nlist
    nl = orbitri.periodic_voronoi(pts, [1, 1, 1]).neighbor_list(min_area=1e-4)
    mine = nl.to_freud()
    assert isinstance(mine, freud.locality.NeighborList)
    np.testing.assert_array_equal(nl.counts, mine.neighbor_counts)
    # every face freud lists above 1e-4 is ours, with its area, distance and vector;
    # freud (3.4) leaves out a few real faces, in both directions: scipy finds them below
    at = {(q, p): k for k, (q, p) in enumerate(zip(mine.query_point_indices.tolist(), mine.point_indices.tolist()))}
    big = np.flatnonzero(theirs.weights > 1e-4)
    rows = [at[(q, p)] for q, p in zip(theirs.query_point_indices[big].tolist(), theirs.point_indices[big].tolist())]
    np.testing.assert_allclose(mine.weights[rows], theirs.weights[big], rtol=1e-5)
    np.testing.assert_allclose(mine.distances[rows], theirs.distances[big], rtol=1e-5)
    np.testing.assert_allclose(mine.vectors[rows], theirs.vectors[big], atol=1e-5)
    assert len(mine) - len(rows) < 0.01 * len(mine)
    # scipy's (qhull's) Voronoi diagram of 3 × 3 × 3 copies: the central copy's faces
    import scipy.spatial

    shifts = np.array([[x, y, z] for x in (-1, 0, 1) for y in (-1, 0, 1) for z in (-1, 0, 1)])
    copies = (pts[None] + shifts[:, None]).reshape(-1, 3)
    v = scipy.spatial.Voronoi(copies)
    centre = 13 * len(pts)  # the copy with shift (0, 0, 0)
    expected = {}
    for ridge_points, ridge in zip(v.ridge_points, v.ridge_vertices):
        for a, b in (ridge_points, ridge_points[::-1]):
            if centre <= a < centre + len(pts) and -1 not in ridge:
                face = v.vertices[ridge]
                normal = copies[b] - copies[a]
                basis = np.linalg.svd(np.cross(normal, np.eye(3)))[2][:2]  # two in-plane axes
                area = scipy.spatial.ConvexHull((face - face[0]) @ basis.T).volume
                if area >= 1e-4:
                    expected[(int(a - centre), int(b % len(pts)), *shifts[b // len(pts)].tolist())] = area
    ours = {}
    for i, j, s, area in zip(nl.i.tolist(), nl.j.tolist(), nl.shifts.tolist(), nl.areas):
        ours[(i, j, *s)] = area
        ours[(j, i, *(-np.array(s)).tolist())] = area
    assert set(ours) == set(expected)
    np.testing.assert_allclose([ours[k] for k in expected], list(expected.values()), rtol=1e-9)


def test_neighbor_list_arrays_and_area_cuts():
    vor = orbitri.periodic_voronoi(np.random.default_rng(7).random((300, 3)), [1.0, 1.0, 1.0])
    nl = vor.neighbor_list()
    ij, shifts, areas = vor.neighbors()
    assert len(nl) == len(ij)
    np.testing.assert_array_equal(nl.i, ij[:, 0])
    np.testing.assert_array_equal(nl.shifts, shifts)
    np.testing.assert_array_equal(nl.counts, vor.neighbor_counts)
    np.testing.assert_array_equal(np.diff(nl.indptr), nl.counts)
    p = vor._points
    np.testing.assert_allclose(nl.vectors, p[nl.j] + nl.shifts - p[nl.i])  # a unit cube
    # the Voronoi face of a pair lies halfway: a Delaunay edge of that length
    edges = orbitri.PeriodicDelaunay(p, [1, 1, 1]).edges()[2]
    assert set(np.round(nl.distances, 12)) <= set(np.round(edges, 12))
    # CSR rows: point k's neighbours, once per face
    for k in (0, 17, 299):
        row = sorted(nl.indices[nl.indptr[k] : nl.indptr[k + 1]].tolist())
        assert row == sorted([int(f["neighbor"]) for c in vor.cells() if c["id"] == k for f in c["faces"]])
    # absolute and relative cuts
    cut = vor.neighbor_list(min_area=0.01)
    assert (cut.areas >= 0.01).all() and len(cut) == (areas >= 0.01).sum()
    frac = vor.neighbor_list(min_area_fraction=0.05)
    s = vor.surface_areas
    assert (frac.areas >= 0.05 * np.maximum(s[frac.i], s[frac.j])).all()
    assert len(frac) < len(nl)
    df = nl.to_dataframe()
    assert list(df.columns) == ["i", "j", "shift_x", "shift_y", "shift_z", "area", "distance", "vector_x", "vector_y", "vector_z"]


def test_rounded_fcc_has_coordination_12_with_a_cut():
    # lattice constant 0.1: the rounded coordinates leave faces of about 1e-17
    vor = orbitri.periodic_voronoi(_fcc(4), [0.4, 0.4, 0.4])
    exact = vor.neighbor_list()
    assert exact.counts.max() > 12
    assert (vor.neighbor_list(min_area=1e-12).counts == 12).all()
    assert (vor.neighbor_list(min_area_fraction=1e-9).counts == 12).all()


def test_duplicates_share_their_first_occurrence_s_row():
    pts = np.random.default_rng(8).random((50, 2))
    pts = np.vstack([pts, pts[3]])
    nl = orbitri.periodic_voronoi(pts, [1.0, 1.0]).neighbor_list()
    assert nl.counts[50] == nl.counts[3]
    np.testing.assert_array_equal(nl.indices[nl.indptr[50] : nl.indptr[51]], nl.indices[nl.indptr[3] : nl.indptr[4]])


def test_neighbor_list_in_a_manifold():
    klein = orbitri.KleinBottle(1.0, 0.5)
    pts = np.random.default_rng(9).random((200, 2)) * [1.0, 0.5]
    tri = orbitri.Triangulation(pts, space=klein)
    nl = tri.voronoi().neighbor_list()
    cosets, offsets = nl.shifts
    a, t = klein.isometry(cosets, offsets)
    image = np.einsum("eij,ej->ei", a, tri.points[nl.j]) + t
    np.testing.assert_allclose(nl.vectors, image - tri.points[nl.i])
    with pytest.raises(ValueError, match="for tori"):
        nl.to_freud()


def test_vertex_neighbor_vertices_is_scipy_s_csr():
    import scipy.spatial

    pts = np.random.default_rng(10).random((200, 2))
    tri = orbitri.PeriodicDelaunay(pts, [1.0, 1.0])
    indptr, indices = tri.vertex_neighbor_vertices
    assert indptr.shape == (201,)
    for k in range(200):
        assert indices[indptr[k] : indptr[k + 1]].tolist() == sorted(set(tri.vertex_neighbors(k)[0].tolist()))
    # away from the boundary, the neighbours are scipy's
    s = scipy.spatial.Delaunay(pts)
    sp, si = s.vertex_neighbor_vertices
    inner = [k for k in range(200) if (np.abs(pts[k] - 0.5) < 0.2).all()]
    for k in inner:
        assert sorted(si[sp[k] : sp[k + 1]].tolist()) == indices[indptr[k] : indptr[k + 1]].tolist()


# -- conveniences --------------------------------------------------------------------


def test_reprs():
    pts = np.random.default_rng(11).random((300, 3))
    tri = orbitri.PeriodicDelaunay(pts, orbitri.Box.from_cellpar(1, 1, 1, 90, 90, 90))
    assert repr(tri) == (
        "<orbitri.PeriodicDelaunay: 300 points in 3D, 1 sheet, box "
        "Box.from_matrix([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])>"
    )
    vor = tri.voronoi()
    assert repr(vor) == "<orbitri.Voronoi: 300 cells of 300 points in 3D, total volume 1>"
    few = orbitri.PeriodicDelaunay(pts[:5], [1, 1, 1])
    assert repr(few).startswith("<orbitri.PeriodicDelaunay: 5 points in 3D, 27 sheets, box")
    assert repr(vor.neighbor_list()).startswith("<orbitri.NeighborList: ")
    k = orbitri.Triangulation(pts[:, :2] * [1, 0.5], space=orbitri.KleinBottle(1.0, 0.5))
    assert repr(k) == "<orbitri.Triangulation: 300 points in 2D, 1 sheet, space KleinBottle(1.0, 0.5)>"
    box = orbitri.Box.from_cellpar(3, 4, 5, 90, 90, 120)
    assert eval(repr(box), {"Box": orbitri.Box}) == box


def test_to_dataframe_is_the_command_s_csv(tmp_path):
    pts = np.random.default_rng(12).random((80, 3))
    pts[5] = pts[2]
    f = tmp_path / "p.txt"
    np.savetxt(f, pts)
    csv = tmp_path / "v.csv"
    subprocess.run([_cli(), "voronoi", str(f), "--box", "1", "1", "1", "-o", str(csv)], check=True)
    theirs = pd.read_csv(csv, index_col="id")
    ours = orbitri.periodic_voronoi(pts, [1, 1, 1]).to_dataframe()
    assert list(ours.columns) == list(theirs.columns)
    assert ours.loc[5, "duplicate_of"] == 2 and ours.loc[4, "duplicate_of"] == -1
    theirs["duplicate_of"] = theirs["duplicate_of"].fillna(-1).astype(int)
    pd.testing.assert_frame_equal(ours, theirs, check_dtype=False, rtol=1e-12)


def test_plot_colours_cells_by_area():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    pts = np.random.default_rng(13).random((40, 2)) * [2.0, 1.0]
    vor = orbitri.periodic_voronoi(pts, [2.0, 1.0])
    ax = vor.plot()
    cells = ax.collections[0]
    assert len(cells.get_paths()) == 40
    np.testing.assert_allclose(np.sort(cells.get_array()), np.sort(vor.volumes))
    ax.figure.canvas.draw()
    ax = vor.plot(copies=5, colorbar=False, points=False)
    assert len(ax.collections[0].get_paths()) == 40 * 25
    plt.close("all")
    with pytest.raises(ValueError, match="odd"):
        vor.plot(copies=2)
    with pytest.raises(ValueError, match="2D cells"):
        orbitri.periodic_voronoi(np.random.default_rng(1).random((20, 3)), [1, 1, 1]).plot()
    klein = orbitri.Triangulation(pts * [0.5, 0.5], space=orbitri.KleinBottle(1.0, 0.5)).voronoi()
    assert len(klein.plot().collections[0].get_paths()) == 40
    plt.close("all")


# -- files ---------------------------------------------------------------------------


def _read_vtu(path):
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy

    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(str(path))
    r.Update()
    grid = r.GetOutput()
    data = grid.GetCellData()
    arrays = {data.GetArrayName(k): vtk_to_numpy(data.GetArray(k)) for k in range(data.GetNumberOfArrays())}
    return grid, arrays


@pytest.mark.parametrize("dim", [2, 3])
def test_vtu_is_binary_and_vtk_reads_it(tmp_path, dim):
    box = [1.0] * dim
    pts = np.random.default_rng(14).random((300, dim))
    f = tmp_path / "p.npy"
    np.save(f, pts.astype(np.float32))  # float32 input
    pts = pts.astype(np.float32).astype(np.float64)
    vtu = tmp_path / "v.vtu"
    subprocess.run([_cli(), "voronoi", str(f), "--box", *map(str, box), "-o", str(vtu)], check=True)
    head = vtu.read_bytes()[:2000]
    assert b'compressor="vtkZLibDataCompressor"' in head and b'format="appended"' in head
    grid, cell = _read_vtu(vtu)
    vor = orbitri.periodic_voronoi(pts, box)
    assert grid.GetNumberOfCells() == 300
    np.testing.assert_array_equal(cell["id"], np.arange(300))
    assert cell["id"].dtype == np.int64
    np.testing.assert_allclose(cell["volume"], vor.volumes, rtol=1e-12)
    np.testing.assert_array_equal(cell["neighbours"], vor.neighbor_counts)
    np.testing.assert_allclose(cell["surface_area"], vor.surface_areas, rtol=1e-12)
    np.testing.assert_allclose(cell["centroid"][:, :dim], vor.centroids, rtol=1e-12)
    # VTK's own measure of the cells agrees
    q = __import__("vtk").vtkCellSizeFilter()
    q.SetInputData(grid)
    q.Update()
    name = "Area" if dim == 2 else "Volume"
    from vtk.util.numpy_support import vtk_to_numpy

    measured = vtk_to_numpy(q.GetOutput().GetCellData().GetArray(name))
    if dim == 2:
        np.testing.assert_allclose(measured, vor.volumes, rtol=1e-9)
    else:
        # VTK measures a polyhedron by its own triangulation, off by 1e-4 for a few cells
        close = np.isclose(measured, vor.volumes, rtol=1e-9)
        assert close.mean() > 0.95 and np.allclose(measured, vor.volumes, rtol=1e-3)
    # the triangulation as VTK
    t = tmp_path / "t.vtu"
    subprocess.run([_cli(), "triangulate", str(f), "--box", *map(str, box), "-o", str(t)], check=True)
    grid, _ = _read_vtu(t)
    assert grid.GetNumberOfCells() == len(orbitri.PeriodicDelaunay(pts, box).simplices)


def test_point_files_as_pandas_and_numpy_write_them(tmp_path):
    pts = np.random.default_rng(15).random((100, 3))
    expected = orbitri.periodic_voronoi(pts, [1, 1, 1]).volumes
    df = pd.DataFrame(pts, columns=["x", "y", "z"])
    files = {
        "index.csv": lambda f: df.to_csv(f),
        "noindex.csv": lambda f: df.to_csv(f, index=False),
        "extra.csv": lambda f: df.assign(type=1)[["type", "z", "x", "y"]].to_csv(f),
        "ints.npy": None,
    }
    for name, write in files.items():
        f = tmp_path / name
        if write:
            write(f)
            volumes = expected
        else:
            np.save(f, (pts * 1000).astype(np.int32))
            volumes = orbitri.periodic_voronoi((pts * 1000).astype(np.int32), [1000] * 3).volumes
        npz = tmp_path / (name + ".npz")
        subprocess.run([_cli(), "voronoi", str(f), "--box", *(["1"] * 3 if write else ["1000"] * 3), "-o", str(npz)], check=True)
        z = np.load(npz)
        assert sorted(z.files) == ["centroid", "duplicate_of", "id", "neighbours", "surface_area", "volume"]
        np.testing.assert_allclose(z["volume"], volumes, rtol=1e-12, err_msg=name)
        assert z["centroid"].shape == (100, 3) and z["id"].dtype == np.int64
    out = subprocess.run([_cli(), "voronoi", str(tmp_path / "noindex.csv"), "--box", "1", "1", "1", "-o", str(tmp_path / "v.txt")], capture_output=True, text=True)
    assert out.returncode == 2 and "cannot tell the output format from the extension .txt" in out.stderr
