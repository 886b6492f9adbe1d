//! A left-invariant total order on a Bieberbach group, which orders the copies of one point
//! for the symbolic perturbation in a way every element of the group respects.
//!
//! The perturbation of a cospherical tie ranks the lifted points of the test. Two copies
//! `g·p` and `h·p` of one point must be ranked the same way as `k·g·p` and `k·h·p` for every
//! element `k`, or the triangulation of a covering space is not invariant under the group and
//! does not project to a triangulation of the manifold. Ranking them by `g⁻¹∘h` makes the
//! ranks invariant; they are a total order exactly when the group is left-orderable.
//!
//! The order is built from homomorphisms to the integers. An element `x ↦ A·x + t`, with
//! `t = τ·M/q` (`τ` an integer row, `M/q` the fine lattice), maps to `τ·u` for a column `u`
//! fixed by every linear part (`R·u = u`, `R` the action on lattice rows): that is a
//! homomorphism, since `τ(g∘h) = τ(h)·R_g + τ(g)`. Its kernel is a smaller Bieberbach group,
//! whose own linear parts fix more columns; the chain goes on until the columns span the
//! space. An element is positive when its first non-zero value along the chain is. This
//! order exists for every closed flat manifold of positive first Betti number: the Klein
//! bottle, and every flat 3-manifold but the Hantzsche–Wendt space (the didicosm), whose
//! group is not left-orderable (Boyer, Rolfsen and Wiest). There the copies are ordered by
//! coset, then by the translation between them (`FlatManifold::copy_order`).

use crate::predicates::Sign;

/// The chain of integer columns `u` (see the module's documentation).
#[derive(Clone, Debug)]
pub(super) struct LeftOrder<const D: usize> {
    functionals: Vec<[i64; D]>,
}

/// Rank of at most `D` integer vectors of dimension `D ≤ 3`.
fn rank<const D: usize>(v: &[[i64; D]]) -> usize {
    let minor2 = |a: &[i64; D], b: &[i64; D], i: usize, j: usize| a[i] * b[j] - a[j] * b[i];
    match v.len() {
        0 => 0,
        1 => usize::from(v[0].iter().any(|&x| x != 0)),
        2 => {
            let pairs = (0..D).flat_map(|i| (i + 1..D).map(move |j| (i, j)));
            if pairs.clone().any(|(i, j)| minor2(&v[0], &v[1], i, j) != 0) {
                2
            } else {
                rank(&v[..1]).max(rank(&v[1..]))
            }
        }
        _ => {
            let full = D == 3
                && v[0][0] * minor2(&v[1], &v[2], 1, 2) - v[0][1] * minor2(&v[1], &v[2], 0, 2)
                    + v[0][2] * minor2(&v[1], &v[2], 0, 1)
                    != 0;
            if full {
                3
            } else {
                (0..v.len())
                    .map(|skip| {
                        let rest: Vec<[i64; D]> =
                            (0..v.len()).filter(|&k| k != skip).map(|k| v[k]).collect();
                        rank(&rest)
                    })
                    .max()
                    .unwrap_or(0)
            }
        }
    }
}

impl<const D: usize> LeftOrder<D> {
    /// The order of the group whose cosets are `(R, s)` (the action on lattice rows and the
    /// translation in units of `M/q`), the identity's first; `None` when no chain of
    /// fixed columns spans the space (the group is not left-orderable).
    ///
    /// Fixed columns are sought among the integer columns of entries in `[-2, 2]`, and
    /// whether a coset meets a kernel among its elements of offsets in `[-3, 3]`: ample for the
    /// signed permutations and hexagonal turns of the spaces here (whose fixed spaces have
    /// bases of 0 and ±1); the tests check the order's axioms on every space.
    pub(super) fn new(cosets: &[([[i32; D]; D], [i32; D])], q: i32) -> Option<Self> {
        let small: Vec<[i64; D]> = (0..5i64.pow(D as u32))
            .map(|k| std::array::from_fn(|i| (k / 5i64.pow(i as u32)) % 5 - 2))
            .filter(|u: &[i64; D]| u.iter().any(|&x| x != 0))
            .collect();
        let offsets: Vec<[i64; D]> = (0..7i64.pow(D as u32))
            .map(|k| std::array::from_fn(|i| (k / 7i64.pow(i as u32)) % 7 - 3))
            .collect();
        let fixes = |r: &[[i32; D]; D], u: &[i64; D]| {
            (0..D).all(|i| (0..D).map(|j| r[i][j] as i64 * u[j]).sum::<i64>() == u[i])
        };
        let mut functionals: Vec<[i64; D]> = Vec::new();
        while functionals.len() < D {
            // the cosets met by the kernel of the chain so far
            let members: Vec<&[[i32; D]; D]> = cosets
                .iter()
                .filter(|(_, s)| {
                    offsets.iter().any(|o| {
                        functionals.iter().all(|u| {
                            (0..D)
                                .map(|i| (s[i] as i64 + q as i64 * o[i]) * u[i])
                                .sum::<i64>()
                                == 0
                        })
                    })
                })
                .map(|(r, _)| r)
                .collect();
            let before = functionals.len();
            for u in &small {
                if members.iter().all(|r| fixes(r, u)) {
                    let mut more = functionals.clone();
                    more.push(*u);
                    if rank(&more) == more.len() {
                        functionals = more;
                    }
                }
            }
            if functionals.len() == before {
                return None;
            }
        }
        Some(LeftOrder { functionals })
    }

    /// The sign of the element whose translation is `τ·M/q`: `Positive` in the positive
    /// cone, `Negative` for its inverse, `Zero` for the identity alone.
    pub(super) fn sign(&self, tau: [i32; D]) -> Sign {
        for u in &self.functionals {
            let v: i64 = (0..D).map(|i| tau[i] as i64 * u[i]).sum();
            if v != 0 {
                return if v > 0 {
                    Sign::Positive
                } else {
                    Sign::Negative
                };
            }
        }
        Sign::Zero
    }
}
