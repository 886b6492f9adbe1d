//! The ten closed flat 3-manifolds (Conway–Rossetti's platycosms), each in a standard
//! presentation whose fundamental domain is the box `[0, L1) × [0, L2) × [0, L3)` (sheared
//! in the second amphicosm; a 60° rhombus of side `L1` times `[0, L3)` for the tricosm and
//! hexacosm): the translations `T` are given by their lattice rows, the other cosets by
//! `x ↦ A·x + t`. `a1 = (1, 0, 0)` and `a2 = (½, √3/2, 0)` span a hexagonal cross-section.
//!
//! | name | generators besides `T` | `T` | index |
//! |---|---|---|---|
//! | torocosm | — | `L1 e1, L2 e2, L3 e3` | 1 |
//! | dicosm | `(x, y, z) ↦ (−x, −y, z + L3)` | `L1 e1, L2 e2, 2L3 e3` | 2 |
//! | tricosm (`L1 = L2`) | a third of a turn about `e3`, then `+ L3 e3` | `L1 a1, L1 a2, 3L3 e3` | 3 |
//! | tetracosm (`L1 = L2`) | `(x, y, z) ↦ (−y, x, z + L3)` | `L1 e1, L1 e2, 4L3 e3` | 4 |
//! | hexacosm (`L1 = L2`) | a sixth of a turn about `e3`, then `+ L3 e3` | `L1 a1, L1 a2, 6L3 e3` | 6 |
//! | didicosm | `(x + 2L1, −y + L2/2, −z)`, `(−x, y + L2/2, −z + L3/2)` | `4L1 e1, L2 e2, L3 e3` | 4 |
//! | first amphicosm | `(x, y, z) ↦ (x + L1, −y, z)` | `2L1 e1, L2 e2, L3 e3` | 2 |
//! | second amphicosm | `(x, y, z) ↦ (x + L1, −y, z)` | `2L1 e1, L2 e2, L2/2 e2 + L3 e3` | 2 |
//! | first amphidicosm | `(−x, −y, z + L3/2)`, `(x + 2L1, −y, z)` | `4L1 e1, L2 e2, L3 e3` | 4 |
//! | second amphidicosm | `(−x, −y, z + L3/2)`, `(x + 2L1, −y + L2/2, z)` | `4L1 e1, L2 e2, L3 e3` | 4 |
//!
//! The dicosm, tricosm, tetracosm and hexacosm screw along the third axis (`L3` is the
//! advance of one screw); the didicosm (Hantzsche–Wendt) has three screw axes, one per
//! coordinate axis; the amphicosms glide along the first axis and reflect the second; the
//! amphidicosms screw half a turn about the third axis and glide along the first in mirrors
//! across the second. Their first homology groups tell them apart (`Z³`, `Z ⊕ Z₂²`,
//! `Z ⊕ Z₃`, `Z ⊕ Z₂`, `Z`, `Z₄²`, `Z² ⊕ Z₂`, `Z²`, `Z ⊕ Z₂²`, `Z ⊕ Z₄`, in the order of
//! the table), which the tests check. The fundamental domain is the slab of `T`'s domain
//! below `1/index` along the axis the cosets shift (the third for the screws, the first
//! otherwise). The tricosm and hexacosm store their points in lattice coordinates (see
//! [`FlatManifold`]'s lattice frame and `metric.rs`).

use super::flat_manifold::{mat_mul, Coset, FlatManifold};
use super::metric::Gram;
use crate::error::{Error, Result};

/// The screw by `1/turns` of a turn (3 or 6) about the third axis, advancing `l3`, over the
/// hexagonal lattice of side `l1`: `T` has rows `a1 = l1·e1`, `a2 = l1·(½, √3/2, 0)` and
/// `turns·l3·e3`. In lattice coordinates the sixth of a turn maps `a1 ↦ a2` and
/// `a2 ↦ a2 − a1`, an integer matrix; the Gram matrix of `(a1, a2, a3)` is
/// `[[l1², l1²/2, 0], [l1²/2, l1², 0], [0, 0, (turns·l3)²]]`, used doubled to be integral.
fn hexagonal_screw(name: &'static str, l1: f64, l3: f64, turns: i32) -> Result<FlatManifold<3>> {
    let s = 3f64.sqrt() / 2.0;
    let lz = turns as f64 * l3;
    let rows = [[l1, 0.0, 0.0], [l1 / 2.0, l1 * s, 0.0], [0.0, 0.0, lz]];
    let zz = 2 * (turns as i64) * (turns as i64);
    let gram = Gram::new([
        [(2, l1), (1, l1), (0, 0.0)],
        [(1, l1), (2, l1), (0, 0.0)],
        [(0, 0.0), (0, 0.0), (zz, l3)],
    ])?;
    let sixth = [[0, 1, 0], [-1, 1, 0], [0, 0, 1]];
    let step = if turns == 3 {
        mat_mul(&sixth, &sixth)
    } else {
        sixth
    };
    // cos and sin of the multiples of 60°, exact but for √3/2
    let (cos, sin) = ([1.0, 0.5, -0.5, -1.0, -0.5, 0.5], [0.0, s, s, 0.0, -s, -s]);
    let mut r = [[1, 0, 0], [0, 1, 0], [0, 0, 1]];
    let mut cosets = Vec::new();
    for c in 0..turns {
        let k = (c * 6 / turns) as usize;
        let linear = [
            [cos[k], -sin[k], 0.0],
            [sin[k], cos[k], 0.0],
            [0.0, 0.0, 1.0],
        ];
        cosets.push((r, [0, 0, c], linear));
        r = mat_mul(&r, &step);
    }
    FlatManifold::in_lattice_frame(name, rows, gram, turns, &cosets, 2)
}

const I: [[i8; 3]; 3] = [[1, 0, 0], [0, 1, 0], [0, 0, 1]];

fn coset(linear: [[i8; 3]; 3], shift: [i32; 3]) -> Coset<3> {
    Coset { linear, shift }
}

fn diag(a: i8, b: i8, c: i8) -> [[i8; 3]; 3] {
    [[a, 0, 0], [0, b, 0], [0, 0, c]]
}

impl FlatManifold<3> {
    /// The names [`Self::platycosm`] takes.
    pub const PLATYCOSMS: [&'static str; 10] = [
        "torocosm",
        "dicosm",
        "tricosm",
        "tetracosm",
        "hexacosm",
        "didicosm",
        "first-amphicosm",
        "second-amphicosm",
        "first-amphidicosm",
        "second-amphidicosm",
    ];

    /// The platycosm `name` (see the module's table) whose fundamental domain has sides
    /// `lengths`.
    ///
    /// ```
    /// use orbitri::{FlatManifold, ManifoldTriangulation3};
    /// let hw = FlatManifold::platycosm("didicosm", [1.0, 1.0, 1.3]).unwrap();
    /// assert!(hw.is_orientable() && hw.index() == 4);
    /// let dicosm = FlatManifold::platycosm("dicosm", [1.0, 1.0, 1.3]).unwrap();
    /// let pts: Vec<[f64; 3]> = (0..100)
    ///     .map(|i| {
    ///         let f = i as f64;
    ///         [(f * 0.618034) % 1.0, (f * 0.414214) % 1.0, (f * 0.732051) % 1.3]
    ///     })
    ///     .collect();
    /// let tri = ManifoldTriangulation3::build(dicosm, &pts).unwrap();
    /// assert!(tri.is_valid().is_ok());
    /// ```
    pub fn platycosm(name: &str, lengths: [f64; 3]) -> Result<Self> {
        let [l1, l2, l3] = lengths;
        if !lengths
            .iter()
            .all(|l| l.is_finite() && *l > 0.0 && (4.0 * l).is_finite())
        {
            return Err(Error::InvalidBox(format!(
                "the {name} needs three positive finite sides, got {lengths:?}"
            )));
        }
        let rows = |a: [f64; 3], b: [f64; 3], c: [f64; 3]| [a, b, c];
        let box_rows = |a: f64, b: f64, c: f64| rows([a, 0.0, 0.0], [0.0, b, 0.0], [0.0, 0.0, c]);
        match name {
            "torocosm" => {
                FlatManifold::new("torocosm", box_rows(l1, l2, l3), 1, &[coset(I, [0; 3])], 2)
            }
            "dicosm" => FlatManifold::new(
                "dicosm",
                box_rows(l1, l2, 2.0 * l3),
                2,
                &[coset(I, [0; 3]), coset(diag(-1, -1, 1), [0, 0, 1])],
                2,
            ),
            "tetracosm" => {
                if l1 != l2 {
                    return Err(Error::InvalidBox(format!(
                        "the tetracosm turns a square cross-section: L1 = L2 needed, got {l1} and {l2}"
                    )));
                }
                let quarter = [[0, -1, 0], [1, 0, 0], [0, 0, 1]];
                let half = diag(-1, -1, 1);
                let three = [[0, 1, 0], [-1, 0, 0], [0, 0, 1]];
                FlatManifold::new(
                    "tetracosm",
                    box_rows(l1, l1, 4.0 * l3),
                    4,
                    &[
                        coset(I, [0; 3]),
                        coset(quarter, [0, 0, 1]),
                        coset(half, [0, 0, 2]),
                        coset(three, [0, 0, 3]),
                    ],
                    2,
                )
            }
            "didicosm" => FlatManifold::new(
                "didicosm",
                box_rows(4.0 * l1, l2, l3),
                2,
                &[
                    coset(I, [0; 3]),
                    coset(diag(1, -1, -1), [1, 1, 0]),
                    coset(diag(-1, 1, -1), [0, 1, 1]),
                    coset(diag(-1, -1, 1), [1, 0, 1]),
                ],
                0,
            ),
            "first-amphicosm" => FlatManifold::new(
                "first-amphicosm",
                box_rows(2.0 * l1, l2, l3),
                2,
                &[coset(I, [0; 3]), coset(diag(1, -1, 1), [1, 0, 0])],
                0,
            ),
            "second-amphicosm" => FlatManifold::new(
                "second-amphicosm",
                rows([2.0 * l1, 0.0, 0.0], [0.0, l2, 0.0], [0.0, l2 / 2.0, l3]),
                2,
                &[coset(I, [0; 3]), coset(diag(1, -1, 1), [1, 0, 0])],
                0,
            ),
            "first-amphidicosm" | "second-amphidicosm" => {
                // the glide also moves along y by half a period in the second
                let glide = if name.starts_with("first") {
                    [1, 0, 0]
                } else {
                    [1, 1, 0]
                };
                let screw = diag(-1, -1, 1);
                let mirror = diag(1, -1, 1);
                FlatManifold::new(
                    if name.starts_with("first") {
                        "first-amphidicosm"
                    } else {
                        "second-amphidicosm"
                    },
                    box_rows(4.0 * l1, l2, l3),
                    2,
                    &[
                        coset(I, [0; 3]),
                        coset(screw, [0, 0, 1]),
                        coset(mirror, glide),
                        // screw∘glide: x ↦ (−x − 2L1, y − L2/2·g_y, z + L3/2)
                        coset(diag(-1, 1, 1), [-glide[0], -glide[1], 1]),
                    ],
                    0,
                )
            }
            "tricosm" | "hexacosm" => {
                if l1 != l2 {
                    return Err(Error::InvalidBox(format!(
                        "the {name} turns a hexagonal cross-section of side L1: L1 = L2 needed, got {l1} and {l2}"
                    )));
                }
                let turns = if name == "tricosm" { 3 } else { 6 };
                hexagonal_screw(
                    if turns == 3 { "tricosm" } else { "hexacosm" },
                    l1,
                    l3,
                    turns,
                )
            }
            _ => Err(Error::InvalidBox(format!(
                "unknown flat 3-manifold {name:?}: one of {}",
                Self::PLATYCOSMS.join(", ")
            ))),
        }
    }
}
