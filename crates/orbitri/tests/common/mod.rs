//! Independent checks: nothing here calls the predicates or the engine's geometry.
#![allow(dead_code)]

pub mod universal;

use std::collections::{BTreeSet, HashMap};

use orbitri::sort::SplitMix;
use orbitri::{CellView, Copies, FlatSpace, InputId, PeriodicDelaunay3, Triangulation};

pub fn uniform(n: usize, seed: u64, scale: [f64; 3]) -> Vec<[f64; 3]> {
    let mut r = SplitMix::new(seed);
    (0..n)
        .map(|_| {
            [
                r.unit() * scale[0],
                r.unit() * scale[1],
                r.unit() * scale[2],
            ]
        })
        .collect()
}

fn lift(p: &[f64; 3], o: &[i8; 3], m: &[[f64; 3]; 3]) -> [f64; 3] {
    std::array::from_fn(|c| p[c] + (0..3).map(|k| o[k] as f64 * m[k][c]).sum::<f64>())
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn det(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
        + a[2] * (b[0] * c[1] - b[1] * c[0])
}

/// Circumcenter by Cramer's rule on `2 (p_i − p_0)·x = |p_i|² − |p_0|²`.
fn circumcenter(p: &[[f64; 3]; 4]) -> [f64; 3] {
    let d: Vec<[f64; 3]> = (1..4).map(|i| sub(p[i], p[0])).collect();
    let rhs: Vec<f64> = d
        .iter()
        .map(|v| 0.5 * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]))
        .collect();
    let den = det(d[0], d[1], d[2]);
    let mut x = [0.0; 3];
    for k in 0..3 {
        let rows: Vec<[f64; 3]> = (0..3)
            .map(|i| {
                let mut r = d[i];
                r[k] = rhs[i];
                r
            })
            .collect();
        x[k] = det(rows[0], rows[1], rows[2]) / den;
    }
    [x[0] + p[0][0], x[1] + p[0][1], x[2] + p[0][2]]
}

fn invert(m: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let d = det(m[0], m[1], m[2]);
    let c = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    // rows of M⁻¹ as columns of the cofactor matrix: x·M⁻¹ = fractional coordinates
    let cols = [c(m[1], m[2]), c(m[2], m[0]), c(m[0], m[1])];
    std::array::from_fn(|i| std::array::from_fn(|j| cols[j][i] / d))
}

/// Brute-force verification of a periodic Delaunay triangulation:
/// positive volumes summing to sheets × domain volume; every facet shared by exactly two
/// cells (per copy); and every circumsphere empty of all periodic copies of all points
/// (points on the sphere allowed, relative tolerance 1e-9).
pub fn brute_force_check(tri: &PeriodicDelaunay3, input: &[[f64; 3]]) {
    let m = tri.space().lattice().vectors();
    let inv = invert(&m);
    let vol_dom = det(m[0], m[1], m[2]).abs();
    let sheets = tri.sheets() as f64;
    let cells = tri.cells(Copies::Stored);
    let pts: Vec<[f64; 3]> = (0..input.len())
        .map(|i| tri.point(tri.vertex_of_input(InputId::new(i))))
        .collect();
    let mut total = 0.0;
    for c in &cells {
        let p: [[f64; 3]; 4] =
            std::array::from_fn(|i| lift(&pts[c.vertices[i].index()], &c.offsets[i], &m));
        let v = det(sub(p[1], p[0]), sub(p[2], p[0]), sub(p[3], p[0])) / 6.0;
        // slivers of rounded grid points can be thinner than f64 resolves; the exact
        // orientation is checked by `is_valid`, the volume sum below catches overlaps
        assert!(v > -1e-12 * vol_dom, "cell {c:?} has volume {v}");
        total += v;
    }
    assert!(
        (total - sheets * vol_dom).abs() <= 1e-9 * sheets * vol_dom,
        "volumes sum to {total}, expected {}",
        sheets * vol_dom
    );
    let mut facets: HashMap<Vec<(InputId, [i8; 3])>, usize> = HashMap::new();
    for c in &cells {
        for skip in 0..4 {
            let mut f: Vec<(InputId, [i8; 3])> = (0..4)
                .filter(|&i| i != skip)
                .map(|i| (c.vertices[i], c.offsets[i]))
                .collect();
            for k in 0..3 {
                let mn = f.iter().map(|x| x.1[k]).min().unwrap();
                f.iter_mut().for_each(|x| x.1[k] -= mn);
            }
            f.sort_unstable();
            *facets.entry(f).or_default() += 1;
        }
    }
    let per = 2 * tri.sheets();
    for (f, n) in &facets {
        assert_eq!(*n, per, "facet {f:?} appears {n} times, expected {per}");
    }
    // distinct input points (first occurrences) only
    let firsts: Vec<usize> = {
        let fo = tri.first_occurrences();
        (0..input.len()).filter(|&i| fo[i].index() == i).collect()
    };
    for c in &cells {
        let p: [[f64; 3]; 4] =
            std::array::from_fn(|i| lift(&pts[c.vertices[i].index()], &c.offsets[i], &m));
        // a sliver's circumcenter is not computable in f64; its emptiness is left to the
        // exact check of `is_valid`
        let l2 = (0..4)
            .flat_map(|i| (0..4).map(move |j| (i, j)))
            .map(|(i, j)| sub(p[i], p[j]))
            .map(|d| d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
            .fold(0.0f64, f64::max);
        if det(sub(p[1], p[0]), sub(p[2], p[0]), sub(p[3], p[0])).abs() < 1e-9 * l2.powf(1.5) {
            continue;
        }
        let z = circumcenter(&p);
        let r2 = (0..3).map(|k| (p[0][k] - z[k]).powi(2)).sum::<f64>();
        let r = r2.sqrt();
        let fz: [f64; 3] = std::array::from_fn(|j| (0..3).map(|k| z[k] * inv[k][j]).sum());
        let span: [f64; 3] =
            std::array::from_fn(|j| r * (0..3).map(|k| inv[k][j] * inv[k][j]).sum::<f64>().sqrt());
        for &i in &firsts {
            let q = pts[i];
            let fq: [f64; 3] = std::array::from_fn(|j| (0..3).map(|k| q[k] * inv[k][j]).sum());
            let lo: [i32; 3] =
                std::array::from_fn(|j| (fz[j] - fq[j] - span[j]).floor() as i32 - 1);
            let hi: [i32; 3] =
                std::array::from_fn(|j| (fz[j] - fq[j] + span[j] * 1.001).floor() as i32);
            for x in lo[0]..=hi[0] {
                for y in lo[1]..=hi[1] {
                    for w in lo[2]..=hi[2] {
                        let o = [x as i8, y as i8, w as i8];
                        if (0..4).any(|k| c.vertices[k].index() == i && c.offsets[k] == o) {
                            continue;
                        }
                        let l = lift(&q, &o, &m);
                        let d2 = (0..3).map(|k| (l[k] - z[k]).powi(2)).sum::<f64>();
                        assert!(d2 >= r2 * (1.0 - 1e-9), "point {i} at offset {o:?} is inside the circumsphere of {c:?}: {d2} < {r2}");
                    }
                }
            }
        }
    }
}

/// Canonical cell set as in the CGAL oracle dumps: (id, offset) pairs sorted by id, offsets
/// translated so that their componentwise minimum is 0, lines sorted.
pub fn canonical_cells(cells: &[CellView]) -> Vec<[i64; 16]> {
    let mut out: Vec<[i64; 16]> = cells
        .iter()
        .map(|c| {
            let mut pairs: Vec<(InputId, [i8; 3])> =
                (0..4).map(|i| (c.vertices[i], c.offsets[i])).collect();
            pairs.sort_unstable();
            for k in 0..3 {
                let mn = pairs.iter().map(|x| x.1[k]).min().unwrap();
                pairs.iter_mut().for_each(|x| x.1[k] -= mn);
            }
            let mut line = [0i64; 16];
            for (i, (v, o)) in pairs.iter().enumerate() {
                line[i] = i64::from(v.0);
                for k in 0..3 {
                    line[4 + 3 * i + k] = o[k] as i64;
                }
            }
            line
        })
        .collect();
    out.sort_unstable();
    out
}

pub fn data_dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data")
}

/// The rows of numbers of a whitespace-separated file in `tests/data`.
fn rows<T: std::str::FromStr>(file: &str) -> Vec<Vec<T>>
where
    T::Err: std::fmt::Debug,
{
    let text = std::fs::read_to_string(data_dir().join(file)).unwrap();
    text.lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| l.split_whitespace().map(|s| s.parse().unwrap()).collect())
        .collect()
}

/// Reads an oracle input: first line the periods, then points.
pub fn read_oracle_input(name: &str) -> ([f64; 3], Vec<[f64; 3]>) {
    let r: Vec<Vec<f64>> = rows(&format!("{name}.txt"));
    (
        [r[0][0], r[0][1], r[0][2]],
        r[1..].iter().map(|v| [v[0], v[1], v[2]]).collect(),
    )
}

/// Reads an oracle dump: header and canonical lines.
pub fn read_dump(name: &str) -> ((usize, usize, usize), Vec<[i64; 16]>) {
    let r: Vec<Vec<i64>> = rows(&format!("{name}.dump3"));
    let h = &r[0];
    (
        (h[0] as usize, h[1] as usize, h[2] as usize),
        r[1..]
            .iter()
            .map(|v| std::array::from_fn(|i| v[i]))
            .collect(),
    )
}

/// `cells³` conventional cells of a cubic crystal with lattice constant `a` and the given
/// basis (fractions of a cell).
pub fn crystal(cells: usize, basis: &[[f64; 3]], a: f64) -> Vec<[f64; 3]> {
    let mut out = Vec::new();
    for i in 0..cells {
        for j in 0..cells {
            for k in 0..cells {
                for b in basis {
                    out.push([
                        (i as f64 + b[0]) * a,
                        (j as f64 + b[1]) * a,
                        (k as f64 + b[2]) * a,
                    ]);
                }
            }
        }
    }
    out
}

/// The cells as sets of (point coordinates, element), canonical modulo the group: equal
/// for two triangulations of one point set in the same space, whatever the ids.
pub fn geometry<const D: usize, const N: usize, S: FlatSpace<D, N>>(
    tri: &Triangulation<D, N, S>,
) -> BTreeSet<Vec<(Vec<u64>, S::Elem)>> {
    let pts = tri.points();
    let mut order: Vec<u32> = (0..pts.len() as u32).collect();
    order.sort_by(|&x, &y| pts[x as usize].partial_cmp(&pts[y as usize]).unwrap());
    let mut rank = vec![0; pts.len()];
    for (r, &v) in order.iter().enumerate() {
        rank[v as usize] = r as u32;
    }
    tri.cells(Copies::Unique)
        .iter()
        .map(|c| {
            let mut pairs: Vec<(u32, S::Elem)> = (0..N)
                .map(|k| {
                    (
                        rank[tri.vertex_of_input(c.vertices[k]).index()],
                        c.offsets[k],
                    )
                })
                .collect();
            tri.space().canonical_face(&mut pairs);
            pairs
                .iter()
                .map(|&(r, g)| {
                    (
                        pts[order[r as usize] as usize].map(f64::to_bits).to_vec(),
                        g,
                    )
                })
                .collect()
        })
        .collect()
}
