//! The same engine on the 2D flat torus, through its 2D plug-in only: the triangulations
//! equal CGAL's (canonical triangle lists of the anchor harness, cocircular square grids
//! included) and pass an independent brute-force check.

use std::collections::HashMap;

use orbitri::space::{FlatTorus, Ladder, Lattice};
use orbitri::{Engine, OrbitSpace};

fn data(name: &str) -> String {
    std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data")
            .join(name),
    )
    .unwrap()
}

fn numbers<T: std::str::FromStr>(line: &str) -> Vec<T>
where
    T::Err: std::fmt::Debug,
{
    line.split_whitespace()
        .map(|s| s.parse().unwrap())
        .collect()
}

/// Inserts the points of an anchor input file (first line: the periods) in file order.
fn triangulate(name: &str) -> (Engine<FlatTorus<2>, 3>, Vec<[f64; 2]>) {
    let text = data(&format!("{name}.txt"));
    let mut lines = text.lines().filter(|l| !l.trim().is_empty());
    let per: Vec<f64> = numbers(lines.next().unwrap());
    let pts: Vec<[f64; 2]> = lines.map(numbers::<f64>).map(|v| [v[0], v[1]]).collect();
    let torus = FlatTorus::<2>::cuboid([per[0], per[1]]).unwrap();
    let mut e = Engine::new(torus);
    for p in &pts {
        e.insert(e.space().lattice().wrap(*p).0);
    }
    e.try_one_sheet();
    e.is_valid().unwrap();
    (e, pts)
}

/// Canonical triangles as the anchor writes them: (index, offset) pairs sorted by index,
/// offsets translated to componentwise minimum 0, lines sorted.
fn canonical(e: &Engine<FlatTorus<2>, 3>) -> Vec<[i64; 9]> {
    let mut out: Vec<[i64; 9]> = e
        .cell_ids()
        .map(|c| {
            let cell = e.cell(c);
            let mut pairs: Vec<(u32, [i8; 2])> = (0..3)
                .map(|i| (e.point_of(cell.v[i]), cell.off[i]))
                .collect();
            pairs.sort_unstable();
            for k in 0..2 {
                let m = pairs.iter().map(|p| p.1[k]).min().unwrap();
                pairs.iter_mut().for_each(|p| p.1[k] -= m);
            }
            let mut line = [0i64; 9];
            for (i, (v, o)) in pairs.iter().enumerate() {
                line[i] = *v as i64;
                line[3 + 2 * i] = o[0] as i64;
                line[4 + 2 * i] = o[1] as i64;
            }
            line
        })
        .collect();
    out.sort_unstable();
    out
}

#[test]
fn the_engine_triangulates_the_2d_torus_as_cgal_does() {
    for name in ["rand2_n30_s1", "rand2_n1000_s1", "sq10_int", "sq10_unit"] {
        let (e, _) = triangulate(name);
        let dump = data(&format!("{name}.dump2"));
        let mut lines = dump.lines();
        let header: Vec<usize> = numbers(lines.next().unwrap());
        let expected: Vec<[i64; 9]> = lines
            .map(|l| numbers::<i64>(l).try_into().unwrap())
            .collect();
        assert_eq!(
            (e.sheets(), e.points().len(), e.number_of_cells()),
            (header[0], header[1], header[2]),
            "{name}"
        );
        assert_eq!(
            canonical(&e),
            expected,
            "{name}: triangles differ from CGAL's"
        );
    }
}

#[test]
fn brute_force_empty_circles_and_areas() {
    for name in ["rand2_n30_s1", "sq10_unit"] {
        let (e, _) = triangulate(name);
        let m = e.space().lattice().vectors();
        let lift =
            |p: [f64; 2], o: [i8; 2]| [p[0] + o[0] as f64 * m[0][0], p[1] + o[1] as f64 * m[1][1]];
        let mut area = 0.0;
        let mut edges: HashMap<Vec<(u32, [i8; 2])>, usize> = HashMap::new();
        for c in e.cell_ids() {
            let cell = e.cell(c);
            let p: Vec<[f64; 2]> = (0..3)
                .map(|i| lift(e.points()[e.point_of(cell.v[i]) as usize], cell.off[i]))
                .collect();
            let (ax, ay, bx, by) = (
                p[1][0] - p[0][0],
                p[1][1] - p[0][1],
                p[2][0] - p[0][0],
                p[2][1] - p[0][1],
            );
            let d = ax * by - ay * bx;
            assert!(d > 0.0, "{name}: triangle {c} is not counter-clockwise");
            area += d / 2.0;
            // circumcenter, then every copy of every point must be outside (or on) the circle
            let (la, lb) = (ax * ax + ay * ay, bx * bx + by * by);
            let z = [
                p[0][0] + (by * la - ay * lb) / (2.0 * d),
                p[0][1] + (ax * lb - bx * la) / (2.0 * d),
            ];
            let r2 = (p[0][0] - z[0]).powi(2) + (p[0][1] - z[1]).powi(2);
            for q in e.points() {
                for ox in -3i8..=3 {
                    for oy in -3i8..=3 {
                        let l = lift(*q, [ox, oy]);
                        let d2 = (l[0] - z[0]).powi(2) + (l[1] - z[1]).powi(2);
                        assert!(
                            d2 >= r2 * (1.0 - 1e-9),
                            "{name}: a point is inside the circle of triangle {c}"
                        );
                    }
                }
            }
            for skip in 0..3 {
                let mut f: Vec<(u32, [i8; 2])> = (0..3)
                    .filter(|&i| i != skip)
                    .map(|i| (e.point_of(cell.v[i]), cell.off[i]))
                    .collect();
                for k in 0..2 {
                    let mn = f.iter().map(|x| x.1[k]).min().unwrap();
                    f.iter_mut().for_each(|x| x.1[k] -= mn);
                }
                f.sort_unstable();
                *edges.entry(f).or_default() += 1;
            }
        }
        let domain = m[0][0] * m[1][1];
        assert!(
            (area - domain * e.sheets() as f64).abs() < 1e-9 * domain,
            "{name}: areas sum to {area}"
        );
        assert!(
            edges.values().all(|&n| n == 2 * e.sheets()),
            "{name}: an edge is not shared by two triangles"
        );
        // Euler: V − E + F = 0 on the torus
        assert_eq!(
            e.points().len() as i64 - edges.len() as i64 + e.number_of_cells() as i64,
            0
        );
    }
}

#[test]
fn the_square_ladder_is_16_8_4_2_1_and_the_grid_is_9() {
    let torus = FlatTorus::<2>::cuboid([1.0, 1.0]).unwrap();
    let sheets: Vec<usize> = (0..torus.levels()).map(|k| torus.sheets(k)).collect();
    assert_eq!(sheets, [16, 8, 4, 2, 1]);
    let grid = FlatTorus::with_ladder(torus.lattice().clone(), Ladder::Grid);
    assert_eq!((grid.levels(), grid.sheets(0)), (2, 9));
}

#[test]
fn tiny_sets_stay_in_a_covering() {
    for kind in [Ladder::Grid, Ladder::Halving] {
        let torus = FlatTorus::<2>::with_ladder(Lattice::cuboid([1.0, 1.0]).unwrap(), kind);
        let mut e = Engine::new(torus);
        for p in [[0.1, 0.2], [0.7, 0.4], [0.3, 0.8]] {
            e.insert(p);
            e.is_valid().unwrap();
            assert!(e.sheets() > 1);
        }
        // 2 triangles per vertex copy on a torus
        assert_eq!(e.number_of_cells(), 2 * 3 * e.sheets());
    }
}
