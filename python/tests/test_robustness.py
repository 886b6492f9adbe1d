"""The Python API under misuse and stress: one section per fix of the reliability issue."""

import os
import signal
import threading
import time

import numpy as np
import pytest

import orbitri

import freud  # noqa: E402  (a test dependency: pip install .[test])
from simplices import canonical  # noqa: E402


def _check_fills_the_box(tri):
    """Every simplex positively oriented, and their volumes fill the box once (one simplex
    per simplex of the torus, also while it is stored in a covering)."""
    lifted = tri.points[tri.simplices] + tri.offsets @ tri.lattice
    d = lifted[:, 1:] - lifted[:, :1]
    vol = np.linalg.det(d) / (2 if tri.dimension == 2 else 6)
    assert (vol > 0).all()
    box = abs(np.linalg.det(tri.lattice))
    assert abs(vol.sum() - box) <= 1e-9 * box


# --- freud's 2D convention --------------------------------------------------------------


def test_freud_2d_points_have_a_zero_third_column():
    rng = np.random.default_rng(13)
    xy = rng.random((300, 2)) * [1.5, 1.0]
    xyz = np.column_stack([xy, np.zeros(len(xy))])
    want = orbitri.PeriodicDelaunay(xy, [1.5, 1.0])
    tilted = np.array([[1.5, 0.0], [0.25, 1.0]])
    for box in (
        [1.5, 1.0],
        np.array([[1.5, 0.0], [0.0, 1.0]]),
        freud.box.Box(1.5, 1.0, is2D=True),
        freud.box.Box.from_box([1.5, 1.0]),
    ):
        tri = orbitri.PeriodicDelaunay(xyz, box)
        assert tri.dimension == 2 and tri.points.shape == (300, 2)
        assert canonical(tri.simplices, tri.offsets) == canonical(want.simplices, want.offsets)
    # tilted: a 2 × 2 matrix, or freud's box with xy (freud's tilt: b = (xy·Ly, Ly))
    for box in (tilted, freud.box.Box(1.5, 1.0, xy=0.25, is2D=True)):
        vor = orbitri.periodic_voronoi(xyz, box)
        assert len(vor) == 300 and abs(vor.volumes.sum() - 1.5) < 1e-12
    # insert and locate take them too
    ids = tri.insert([[0.2, 0.3, 0.0]])
    assert ids.tolist() == [300]
    verts, _, _ = tri.locate([0.2, 0.3, 0.0])
    assert 300 in verts.tolist()


def test_freud_2d_points_off_the_plane_and_mixed_dimensions_are_errors():
    rng = np.random.default_rng(14)
    xyz = np.column_stack([rng.random((10, 2)), np.zeros(10)])
    xyz[7, 2] = 0.5
    for box in ([1.0, 1.0], np.eye(2), freud.box.Box.square(1.0)):
        with pytest.raises(ValueError, match=r"2D points must have 2 columns, or 3 whose last is 0.*point 7 has z = 0.5"):
            orbitri.PeriodicDelaunay(xyz, box)
    tri = orbitri.PeriodicDelaunay(xyz[:5], [1.0, 1.0])
    with pytest.raises(ValueError, match="point 2 has z = 0.5"):
        tri.insert(xyz[5:])
    assert len(tri.points) == 5
    # a 3D box for 2D points: no silent cut to the first two axes
    xy = rng.random((10, 2))
    for box in (freud.box.Box.cube(1.0), np.eye(3), [1.0, 1.0, 1.0, 0.0, 0.0, 0.0]):
        with pytest.raises(ValueError, match="a 3D box for 2D points"):
            orbitri.PeriodicDelaunay(xy, box)
    with pytest.raises(ValueError, match="a 2D box for 3D points"):
        orbitri.lattice_matrix(freud.box.Box.square(1.0), 3)
    # three numbers are read by the points: [Lx, Ly, Lz] in 3D, [Lx, Ly, xy] in 2D
    assert orbitri.PeriodicDelaunay(xy, [1.0, 1.0, 0.25]).lattice.tolist() == [[1.0, 0.0], [0.25, 1.0]]


# --- threads ----------------------------------------------------------------------------


def test_one_triangulation_shared_by_threads():
    rng = np.random.default_rng(15)
    tri = orbitri.PeriodicDelaunay(rng.random((3000, 3)), [1.0, 1.0, 1.0])
    batches = [rng.random((400, 3)) for _ in range(12)]
    errors = []
    start = threading.Barrier(4)

    def guarded(work):
        def run():
            try:
                start.wait()
                work()
            except BaseException as e:  # noqa: BLE001 (reported below)
                errors.append(e)

        return run

    def writer(k):
        for b in batches[k::2]:
            ids = tri.insert(b)
            assert len(ids) == len(b)

    def reader():
        for _ in range(6):
            vor = tri.voronoi()
            assert abs(vor.volumes.sum() - 1.0) < 1e-9
            n = len(tri.points)
            # (two attribute reads are two snapshots: a writer may insert between them)
            assert tri.simplices.shape[1] == 4 and tri.offsets.shape[1:] == (4, 3)
            tri.vertex_neighbors(n - 1)
            tri.locate([0.5, 0.5, 0.5])

    threads = [threading.Thread(target=guarded(f)) for f in (lambda: writer(0), lambda: writer(1), reader, reader)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []
    assert tri.number_of_input_points == 3000 + 12 * 400
    _check_fills_the_box(tri)
    # the same triangulation as the bulk build of the points in their input order
    bulk = orbitri.PeriodicDelaunay(tri.points, [1.0, 1.0, 1.0])
    assert canonical(tri.simplices, tri.offsets) == canonical(bulk.simplices, bulk.offsets)


# --- insert is all or nothing ---------------------------------------------------------


def test_insert_checks_every_point_before_inserting_any():
    rng = np.random.default_rng(11)
    tri = orbitri.PeriodicDelaunay(rng.random((20, 2)), [1.0, 1.0])
    cells = canonical(tri.simplices, tri.offsets)
    # the error names the row of the batch (not the input id it would have had: 22)
    with pytest.raises(ValueError, match=r"^point 2: coordinate 1 is NaN, not a finite number$"):
        tri.insert([[0.1, 0.2], [0.3, 0.4], [0.5, np.nan]])
    with pytest.raises(ValueError, match=r"^point 1: coordinate 0 is -inf"):
        tri.insert(np.array([[0.1, 0.2], [-np.inf, 0.4]]))
    assert tri.number_of_input_points == 20 and len(tri.points) == 20
    assert canonical(tri.simplices, tri.offsets) == cells
    assert tri.insert([[0.1, 0.2], [0.3, 0.4]]).tolist() == [20, 21]


# --- vertex_neighbors takes integer ids -------------------------------------------------


def test_vertex_neighbors_takes_integers_in_range():
    rng = np.random.default_rng(12)
    tri = orbitri.PeriodicDelaunay(rng.random((50, 3)), [1.0, 1.0, 1.0])
    ids, shifts = tri.vertex_neighbors(3)
    for same in (np.int64(3), np.int32(3), np.uint8(3)):
        i2, s2 = tri.vertex_neighbors(same)
        np.testing.assert_array_equal(i2, ids)
        np.testing.assert_array_equal(s2, shifts)
    for bad in (-1, 50, 2**70, np.int64(-5)):
        with pytest.raises(IndexError, match=rf"point {bad} does not exist: the ids of the 50 input points are 0 to 49"):
            tri.vertex_neighbors(bad)
    for bad in (1.5, 3.0, np.float64(3.0), "3", None):
        with pytest.raises(TypeError):
            tri.vertex_neighbors(bad)


# --- try_one_sheet after incremental insertion -------------------------------------------


def test_try_one_sheet_brings_clustered_batches_to_the_bulk_result():
    # 2D clustered points: 8 clusters of 30 points (σ = 0.03) in a unit square, inserted
    # in 4 batches of about 60 after a first point; the bulk build of the same points ends
    # in the torus (1 sheet), the incremental one stays in the 4-sheeted covering
    rng = np.random.default_rng(0)
    centres = rng.random((8, 2))
    pts = (centres[:, None, :] + 0.03 * rng.standard_normal((8, 30, 2))).reshape(-1, 2) % 1.0
    rng.shuffle(pts)
    bulk = orbitri.PeriodicDelaunay(pts, [1.0, 1.0])
    assert bulk.sheets == 1
    tri = orbitri.PeriodicDelaunay(pts[:1], [1.0, 1.0])
    for batch in np.array_split(pts[1:], 4):
        tri.insert(batch)
    assert tri.sheets == 4 and not tri.is_one_sheeted
    _check_fills_the_box(tri)
    # the covering's simplices, one per orbit, are the torus's Delaunay triangulation
    assert canonical(tri.simplices, tri.offsets) == canonical(bulk.simplices, bulk.offsets)
    assert tri.try_one_sheet() is True
    assert tri.sheets == 1 and tri.is_one_sheeted
    _check_fills_the_box(tri)
    # the same Delaunay triangulation as the bulk build's (the points are in general
    # position: it is unique), with the same input ids
    np.testing.assert_array_equal(tri.points, bulk.points)
    assert len(tri.simplices) == len(bulk.simplices)
    assert canonical(tri.simplices, tri.offsets) == canonical(bulk.simplices, bulk.offsets)
    # and it stays correct after more insertions
    tri.insert(rng.random((30, 2)))
    _check_fills_the_box(tri)


# --- Ctrl-C -----------------------------------------------------------------------------


def _latency_of_ctrl_c(call, delay=0.3):
    """Sends SIGINT to this process `delay` seconds into `call` (which must take longer);
    returns the seconds from the signal to the KeyboardInterrupt."""
    fired = []

    def fire():
        fired.append(time.perf_counter())
        os.kill(os.getpid(), signal.SIGINT)

    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    timer = threading.Timer(delay, fire)
    try:
        timer.start()
        with pytest.raises(KeyboardInterrupt):
            call()
        return time.perf_counter() - fired[0]
    finally:
        timer.cancel()
        timer.join()
        signal.signal(signal.SIGINT, previous)


def test_ctrl_c_stops_the_construction():
    pts = np.random.default_rng(16).random((1_000_000, 3))
    latency = _latency_of_ctrl_c(lambda: orbitri.PeriodicDelaunay(pts, [1.0, 1.0, 1.0]))
    assert latency < 1.0, f"KeyboardInterrupt {latency:.2f} s after the signal"


def test_ctrl_c_stops_the_voronoi_cells():
    # (10⁶ points: the cells of 2·10⁵ took less than the signal's 0.3 s on two threads)
    pts = np.random.default_rng(17).random((1_000_000, 3))
    tri = orbitri.PeriodicDelaunay(pts, [1.0, 1.0, 1.0])
    latency = _latency_of_ctrl_c(tri.voronoi)
    assert latency < 1.0, f"KeyboardInterrupt {latency:.2f} s after the signal"
    # the triangulation is untouched (an insertion waits for the abandoned computation)
    assert tri.insert([[0.5, 0.5, 0.5]]).tolist() == [1_000_000]
    assert tri.number_of_input_points == 1_000_001


def test_voronoi_cells_of_a_changed_triangulation_are_an_error_not_stale():
    rng = np.random.default_rng(18)
    tri = orbitri.PeriodicDelaunay(rng.random((200, 3)), [1.0, 1.0, 1.0])
    vor = tri.voronoi()
    before = vor.volumes.copy()
    first = vor.cells()  # computed on first use, from the same triangulation
    assert len(first) == 200 and abs(sum(c["volume"] for c in first) - 1.0) < 1e-12
    late = tri.voronoi()
    tri.insert(rng.random((5, 3)))
    # the measures stay those of the triangulation measured
    assert np.array_equal(vor.volumes, before) and len(vor) == 200
    assert len(vor.cells()) == 200  # computed before the change: kept
    with pytest.raises(ValueError, match="changed since voronoi"):
        late.neighbors()
    fresh = tri.voronoi()
    assert len(fresh.cells()) == 205 and abs(fresh.volumes.sum() - 1.0) < 1e-12


def test_every_scale_gives_the_same_simplices_and_scaled_volumes():
    rng = np.random.default_rng(4)
    pts = np.floor(rng.random((300, 3)) * 2**20) / 2**20
    base = orbitri.PeriodicDelaunay(pts, [1.0, 1.0, 1.0])
    for k in (-1000, -100, 100, 1000):
        s = 2.0**k
        tri = orbitri.PeriodicDelaunay(pts * s, [s, s, s])
        assert np.array_equal(tri.simplices, base.simplices)
        assert np.array_equal(tri.offsets, base.offsets)
        if abs(k) <= 100:
            vol = tri.voronoi().volumes
            assert np.array_equal(vol, base.voronoi().volumes * s**3)
    # a box whose volume no double holds: the triangulation works, its volumes are an error
    big = orbitri.PeriodicDelaunay(pts * 1e110, [1e110] * 3)
    assert big.sheets == 1
    with pytest.raises(ValueError, match="outside the range of doubles"):
        big.voronoi()


def test_voronoi_of_nearly_coincident_points_is_finite_and_sums():
    rng = np.random.default_rng(5)
    pts = rng.random((100, 3))
    shifted = pts[:20] + 1.0  # unwrapped MD coordinates: near-duplicates after wrapping
    ulp = np.nextafter(pts[20:30], 2.0)
    vor = orbitri.periodic_voronoi(np.vstack([pts, shifted, ulp]), [1.0, 1.0, 1.0])
    assert np.all(np.isfinite(vor.volumes)) and np.all(vor.volumes >= 0)
    first = np.unique(orbitri.PeriodicDelaunay(np.vstack([pts, shifted, ulp]), [1.0] * 3).duplicates)
    assert abs(vor.volumes[first].sum() - 1.0) < 1e-12


def test_insert_of_a_point_out_of_reach_is_a_value_error_and_changes_nothing():
    box = np.array([[1.0, 0.0, 0.0], [0.3, 0.9, 0.0], [-0.2, 0.2, 1.1]])
    tri = orbitri.PeriodicDelaunay(np.random.default_rng(2).random((50, 3)), box)
    cells = canonical(tri.simplices, tri.offsets)
    with pytest.raises(ValueError, match=r"^point 1: .* too far from the domain"):
        tri.insert([[0.5, 0.5, 0.5], [1e300, 0.0, 0.0]])
    assert tri.number_of_input_points == 50
    assert canonical(tri.simplices, tri.offsets) == cells


@pytest.fixture
def progress_off():
    yield
    orbitri.set_progress(False)


def test_progress_reaches_a_hook_in_both_phases(progress_off):
    calls = []
    orbitri.set_progress(lambda *a: calls.append(a))
    points = np.random.default_rng(4).random((300_000, 3))
    orbitri.PeriodicDelaunay(points, [1.0, 1.0, 1.0]).voronoi()
    phases = [c[0] for c in calls]
    assert phases[0] == "triangulating" and phases[-1] == "Voronoi cells"
    for phase in ("triangulating", "Voronoi cells"):
        mine = [c for c in calls if c[0] == phase]
        done = [c[1] for c in mine]
        # reported while running, never backwards, never past the total, closed at the end
        assert len(mine) >= 3, phase
        assert done == sorted(done) and all(0 <= d <= c[2] for d, c in zip(done, mine))
        assert mine[-1][3] is True and mine[-1][1] == mine[-1][2]
        assert not any(c[3] for c in mine[:-1])


def test_progress_bar_on_stderr(progress_off, capfd):
    orbitri.set_progress(True)
    orbitri.PeriodicDelaunay(np.random.default_rng(5).random((400_000, 3)), [1.0, 1.0, 1.0])
    err = capfd.readouterr().err
    assert "orbitri: triangulating" in err and "%" in err
    orbitri.set_progress(False)
    orbitri.PeriodicDelaunay(np.random.default_rng(5).random((400_000, 3)), [1.0, 1.0, 1.0])
    assert "orbitri" not in capfd.readouterr().err
    with pytest.raises(ValueError, match="set_progress takes"):
        orbitri.set_progress("sometimes")
