//! The closed flat 3-manifolds (Conway–Rossetti's platycosms) whose holonomy acts by signed
//! permutations, each in a standard presentation whose fundamental domain is the box
//! `[0, L1) × [0, L2) × [0, L3)` (sheared in the second amphicosm): the translations `T`
//! are given by their lattice rows, the other cosets by `x ↦ A·x + t`.
//!
//! | name | generators besides `T` | `T` | index |
//! |---|---|---|---|
//! | torocosm | — | `L1 e1, L2 e2, L3 e3` | 1 |
//! | dicosm | `(x, y, z) ↦ (−x, −y, z + L3)` | `L1 e1, L2 e2, 2L3 e3` | 2 |
//! | tetracosm (`L1 = L2`) | `(x, y, z) ↦ (−y, x, z + L3)` | `L1 e1, L1 e2, 4L3 e3` | 4 |
//! | didicosm | `(x + 2L1, −y + L2/2, −z)`, `(−x, y + L2/2, −z + L3/2)` | `4L1 e1, L2 e2, L3 e3` | 4 |
//! | first amphicosm | `(x, y, z) ↦ (x + L1, −y, z)` | `2L1 e1, L2 e2, L3 e3` | 2 |
//! | second amphicosm | `(x, y, z) ↦ (x + L1, −y, z)` | `2L1 e1, L2 e2, L2/2 e2 + L3 e3` | 2 |
//! | first amphidicosm | `(−x, −y, z + L3/2)`, `(x + 2L1, −y, z)` | `4L1 e1, L2 e2, L3 e3` | 4 |
//! | second amphidicosm | `(−x, −y, z + L3/2)`, `(x + 2L1, −y + L2/2, z)` | `4L1 e1, L2 e2, L3 e3` | 4 |
//!
//! The dicosm and the tetracosm screw along the third axis (`L3` is the length along it);
//! the didicosm (Hantzsche–Wendt) has three screw axes, one per coordinate axis; the
//! amphicosms glide along the first axis and reflect the second; the amphidicosms screw
//! half a turn about the third axis and glide along the first in mirrors across the second.
//! Their first homology groups tell them apart (`Z³`, `Z ⊕ Z₂²`, `Z ⊕ Z₂`, `Z₄²`,
//! `Z² ⊕ Z₂`, `Z²`, `Z ⊕ Z₂²`, `Z ⊕ Z₄`, in the order of the table), which the tests check. The fundamental domain is
//! the slab of `T`'s domain below `1/index` along the axis the cosets shift (the third for
//! the screws, the first otherwise).

use super::flat_manifold::{Coset, FlatManifold};
use crate::error::{Error, Result};

const I: [[i8; 3]; 3] = [[1, 0, 0], [0, 1, 0], [0, 0, 1]];

fn coset(linear: [[i8; 3]; 3], shift: [i32; 3]) -> Coset<3> {
    Coset { linear, shift }
}

fn diag(a: i8, b: i8, c: i8) -> [[i8; 3]; 3] {
    [[a, 0, 0], [0, b, 0], [0, 0, c]]
}

impl FlatManifold<3> {
    /// The names [`Self::platycosm`] takes.
    pub const PLATYCOSMS: [&'static str; 8] = [
        "torocosm",
        "dicosm",
        "tetracosm",
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
            "tricosm" | "hexacosm" => Err(Error::InvalidBox(format!(
                "the {name} turns a hexagonal cross-section by a {} of a turn, which is \
                 irrational in Cartesian coordinates; its exact predicates (in lattice \
                 coordinates with an exact Gram matrix) are not in this version: one of {}",
                if name == "tricosm" { "third" } else { "sixth" },
                Self::PLATYCOSMS.join(", ")
            ))),
            _ => Err(Error::InvalidBox(format!(
                "unknown flat 3-manifold {name:?}: one of {}",
                Self::PLATYCOSMS.join(", ")
            ))),
        }
    }
}
