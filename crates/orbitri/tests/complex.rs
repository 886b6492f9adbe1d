//! The triangulation of the space as a Δ-complex (`Triangulation::complex`), above all while
//! the engine still stores a covering: one cell per orbit, each facet glued to exactly one
//! facet of a neighbour by an element that carries the neighbour's vertices onto this cell's,
//! the gluings inverse to each other, Euler's relation counted on the complex itself, and
//! the same complex as the 1-sheeted triangulation once the same points convert to it.
//! (The universal-cover checker, `tests/universal.rs` and `tests/manifolds.rs`, checks the
//! cells themselves: empty spheres, facet orbits met twice, total volume.)

use std::collections::BTreeSet;

use orbitri::sort::SplitMix;
use orbitri::{Complex, FlatManifold, FlatSpace, FlatTorus2, FlatTorus3, InputId, Triangulation};

fn random<const D: usize>(n: usize, seed: u64, scale: [f64; D]) -> Vec<[f64; D]> {
    let mut r = SplitMix::new(seed);
    (0..n)
        .map(|_| std::array::from_fn(|i| r.unit() * scale[i]))
        .collect()
}

/// Every check on the complex of `tri` that needs nothing but its group.
fn check_complex<const D: usize, const N: usize, S: FlatSpace<D, N>>(
    tri: &Triangulation<D, N, S>,
    what: &str,
) -> Complex<D, N, S::Elem> {
    let space = tri.space();
    let x = tri.complex().unwrap_or_else(|e| panic!("{what}: {e}"));
    let rows = x.cells.len();
    assert_eq!(rows, tri.number_of_cells(), "{what}");
    assert_eq!(
        rows * tri.sheets(),
        tri.number_of_stored_cells(),
        "{what}: every orbit has one copy per sheet"
    );
    assert_eq!(x.cells, tri.cells(orbitri::Copies::Unique), "{what}");
    assert!(x.neighbors.len() == rows && x.mirrors.len() == rows && x.gluings.len() == rows);
    let mut facets = BTreeSet::new();
    for k in 0..rows {
        for i in 0..N {
            let (m, j, g) = (
                x.neighbors[k][i] as usize,
                x.mirrors[k][i] as usize,
                x.gluings[k][i],
            );
            assert!(m < rows && j < N, "{what}: cell {k} facet {i}");
            // the facet seen from the other side comes back, by the inverse gluing
            assert_eq!(
                (x.neighbors[m][j] as usize, x.mirrors[m][j] as usize),
                (k, i),
                "{what}: cell {k} facet {i}"
            );
            assert_eq!(
                space.compose(x.gluings[m][j], g),
                space.identity(),
                "{what}: gluings of cell {k} facet {i} are not inverse"
            );
            // the neighbour's facet, moved by the gluing, is this cell's facet
            let here: BTreeSet<(InputId, S::Elem)> = (0..N)
                .filter(|&a| a != i)
                .map(|a| (x.cells[k].vertices[a], x.cells[k].offsets[a]))
                .collect();
            let there: BTreeSet<(InputId, S::Elem)> = (0..N)
                .filter(|&b| b != j)
                .map(|b| {
                    let c = &x.cells[m];
                    (c.vertices[b], space.compose(g, c.offsets[b]))
                })
                .collect();
            assert_eq!(
                here.len(),
                N - 1,
                "{what}: a facet's lifted vertices are distinct"
            );
            assert_eq!(here, there, "{what}: cell {k} facet {i} is glued wrongly");
            facets.insert((k.min(m), if k < m { i } else { j }, k.max(m)));
        }
    }
    // every facet of the complex is shared by exactly two cell sides
    assert_eq!(2 * facets.len(), N * rows, "{what}: facet sides pair up");
    // Euler's relation on the complex itself (closed flat manifolds: χ = 0), counting its
    // edges; in 2D the facets are the edges: V − E + F = V − F/2 = 0
    let v = tri.number_of_vertices() as i64;
    let e = tri.edges().len() as i64;
    let f = facets.len() as i64;
    let c = rows as i64;
    let chi = if D == 2 { v - f + c } else { v - e + f - c };
    assert_eq!(chi, 0, "{what}: V={v} E={e} F={f} C={c}");
    if D == 2 {
        assert_eq!(e, f, "{what}: the edges are the facets");
    }
    x
}

/// Sets of lifted simplices, each as sorted (input id, element) pairs.
type Lifted<E> = BTreeSet<Vec<(u32, E)>>;

/// A complex in the input ids and canonical elements of its cells, with each facet's pair
/// of cells as one canonical lifted set (the cell and its neighbour's far vertex moved by
/// the gluing): the same for any choice of representatives and any storage.
fn canonical<const D: usize, const N: usize, S: FlatSpace<D, N>>(
    space: &S,
    x: &Complex<D, N, S::Elem>,
) -> (Lifted<S::Elem>, Lifted<S::Elem>) {
    let pairs = |k: usize| -> Vec<(u32, S::Elem)> {
        (0..N)
            .map(|a| (x.cells[k].vertices[a].0, x.cells[k].offsets[a]))
            .collect()
    };
    let cells = (0..x.cells.len())
        .map(|k| {
            let mut p = pairs(k);
            space.canonical_face(&mut p);
            p
        })
        .collect();
    let mut glued = BTreeSet::new();
    for k in 0..x.cells.len() {
        for i in 0..N {
            let (m, j, g) = (
                x.neighbors[k][i] as usize,
                x.mirrors[k][i] as usize,
                x.gluings[k][i],
            );
            let mut p = pairs(k);
            let c = &x.cells[m];
            p.push((c.vertices[j].0, space.compose(g, c.offsets[j])));
            // the translate putting the first vertex at the identity, then sorted: two
            // translates of one set agree (the tori's group is the translations)
            let h = space.inverse(p.iter().min().unwrap().1);
            let mut moved: Vec<(u32, S::Elem)> =
                p.iter().map(|&(v, e)| (v, space.compose(h, e))).collect();
            moved.sort_unstable();
            glued.insert(moved);
        }
    }
    (cells, glued)
}

#[test]
fn tori_in_coverings_give_glued_complexes() {
    for n in 1..=10 {
        let seed = 40 + n as u64;
        let square = FlatTorus2::cuboid([1.0, 1.0]).unwrap();
        let tri = Triangulation::build(square, &random(n, seed, [1.0; 2])).unwrap();
        check_complex(&tri, &format!("square, {n} points"));
        let oblique = FlatTorus2::triclinic([[1.0, 0.0], [0.3, 0.6]]).unwrap();
        let tri = Triangulation::build(oblique, &random(n, seed, [1.0, 0.6])).unwrap();
        check_complex(&tri, &format!("oblique, {n} points"));
        let cube = FlatTorus3::cuboid([1.0, 1.5, 0.75]).unwrap();
        let tri = Triangulation::build(cube, &random(n, seed, [1.0, 1.5, 0.75])).unwrap();
        let x = check_complex(&tri, &format!("cuboid, {n} points"));
        if n <= 3 {
            assert!(tri.sheets() > 1 && !x.cells.is_empty());
        }
        let skew = [[1.0, 0.0, 0.0], [0.25, 1.0, 0.0], [-0.5, 0.375, 0.75]];
        let tri = Triangulation::build(
            FlatTorus3::triclinic(skew).unwrap(),
            &random(n, seed, [1.0, 1.0, 0.75]),
        )
        .unwrap();
        check_complex(&tri, &format!("triclinic, {n} points"));
    }
}

#[test]
fn manifolds_in_coverings_give_glued_complexes() {
    for n in [1, 2, 3, 6, 12, 40] {
        let klein = FlatManifold::klein_bottle(1.0, 1.3).unwrap();
        let tri = Triangulation::build(klein, &random(n, 7 + n as u64, [1.0, 1.3])).unwrap();
        check_complex(&tri, &format!("Klein bottle, {n} points"));
        for name in FlatManifold::PLATYCOSMS {
            let box_ = [1.0, 1.0, 1.25];
            let m = FlatManifold::platycosm(name, box_).unwrap();
            let tri = Triangulation::build(m, &random(n, 9 + n as u64, box_)).unwrap();
            check_complex(&tri, &format!("{name}, {n} points"));
        }
    }
}

/// Whether `tri`, in a covering, converts to the 1-sheeted torus; if so, its complex before
/// and after is one.
fn converts_to_one_complex<const D: usize, const N: usize, S: FlatSpace<D, N>>(
    tri: &mut Triangulation<D, N, S>,
    what: &str,
) -> bool {
    if tri.is_one_sheeted() {
        return false;
    }
    let before = canonical(
        tri.space(),
        &check_complex(tri, &format!("{what}, covering")),
    );
    if !tri.try_one_sheet() {
        return false;
    }
    let after = canonical(
        tri.space(),
        &check_complex(tri, &format!("{what}, quotient")),
    );
    assert!(before == after, "{what}: the complexes differ");
    true
}

/// Points inserted one at a time stay in the covering until asked; the complex read from the
/// covering is the one read after moving to the 1-sheeted torus.
#[test]
fn the_covering_and_the_quotient_describe_one_complex() {
    let mut converted = 0;
    for seed in 0..12u64 {
        let cube = FlatTorus3::cuboid([1.0; 3]).unwrap();
        let mut tri = Triangulation::new(cube);
        for p in random(60 + 5 * seed as usize, seed, [1.0; 3]) {
            tri.insert(p).unwrap();
        }
        let square = FlatTorus2::cuboid([1.0; 2]).unwrap();
        let mut flat = Triangulation::new(square);
        for p in random(12 + seed as usize, seed, [1.0; 2]) {
            flat.insert(p).unwrap();
        }
        converted += usize::from(converts_to_one_complex(
            &mut tri,
            &format!("3D, seed {seed}"),
        ));
        converted += usize::from(converts_to_one_complex(
            &mut flat,
            &format!("2D, seed {seed}"),
        ));
    }
    assert!(
        converted >= 4,
        "only {converted} sets converted: test nothing"
    );
}

/// Few points in special positions (one, or a small grid on the axes of the group's screw
/// motions), whose images tie in many ways: every covering is the lift of a triangulation of
/// the manifold, since copies of a point are ranked by the group's left order. The
/// didicosm's group has none; there a tie among images under different screw motions may
/// not be broken alike, which `complex` reports instead of a wrong complex.
#[test]
fn ties_among_images_are_broken_alike_for_every_copy() {
    let box_ = [1.0, 1.0, 1.25];
    let mut refused = 0;
    for k in 1..=2usize {
        for shift in [0.5, 0.25, 0.0] {
            let grid: Vec<[f64; 3]> = (0..k * k * k)
                .map(|i| [i % k, i / k % k, i / k / k].map(|x| (x as f64 + shift) / k as f64))
                .map(|g| [g[0], g[1], g[2] * 1.25])
                .collect();
            for name in FlatManifold::PLATYCOSMS {
                let m = FlatManifold::platycosm(name, box_).unwrap();
                let tri = Triangulation::build(m, &grid).unwrap();
                let what = format!("{name}, grid {k}³ at {shift}");
                tri.is_valid().unwrap_or_else(|e| panic!("{what}: {e}"));
                match tri.complex() {
                    Err(orbitri::Error::NotInvariant { .. }) if name == "didicosm" => refused += 1,
                    _ => {
                        check_complex(&tri, &what);
                    }
                }
            }
            let klein = FlatManifold::klein_bottle(1.0, 1.25).unwrap();
            let square: Vec<[f64; 2]> = grid.iter().map(|p| [p[0], p[2]]).collect();
            let tri = Triangulation::build(klein, &square).unwrap();
            check_complex(&tri, &format!("Klein bottle, grid {k}² at {shift}"));
        }
    }
    // the didicosm's two grids centred on its screw axes are refused, and only those
    assert_eq!(refused, 2, "didicosm grids refused");
}
