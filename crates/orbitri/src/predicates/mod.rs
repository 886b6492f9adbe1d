//! Exact geometric predicates on lifted points `p + o·M` (a point of the domain plus a lattice
//! offset), never rounded: a floating-point filter with a proven error bound first, an exact
//! big-integer evaluation when the filter cannot decide, and the symbolic perturbation of
//! Devillers and Teillaud for cospherical ties.
//!
//! Error bounds (u = 2⁻⁵³). A lifted difference component `d = (p_i − p_0) + Σ_k t_k M_kc`
//! is evaluated as `fl(fl(p_i − p_0) + fl(Σ t_k M_kc))`; with `B = |fl(p_i − p_0)| + Σ |t_k M_kc|`
//! its absolute error is below `6u·B` (one rounding in the difference, at most three in the
//! lattice sum, one in the final addition, and one for evaluating `B` itself). The determinants
//! are then bounded term by term in [`filter`]; inputs outside `[2⁻²⁰⁰, 2²⁰⁰]` per row skip the
//! filter, so no intermediate value can underflow or overflow.

pub mod exact;
pub mod filter;
pub mod spherical;
pub mod wide;

/// The sign of a predicate.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Sign {
    Negative,
    Zero,
    Positive,
}

impl Sign {
    /// The opposite sign.
    #[inline]
    pub fn flip(self) -> Sign {
        match self {
            Sign::Negative => Sign::Positive,
            Sign::Zero => Sign::Zero,
            Sign::Positive => Sign::Negative,
        }
    }
}

impl From<std::cmp::Ordering> for Sign {
    fn from(o: std::cmp::Ordering) -> Sign {
        match o {
            std::cmp::Ordering::Less => Sign::Negative,
            std::cmp::Ordering::Equal => Sign::Zero,
            std::cmp::Ordering::Greater => Sign::Positive,
        }
    }
}

/// The symbolic perturbation of a cospherical in-sphere test for a given order of the
/// points (lifted points of a flat space, or points of the sphere; `compare(a, b)` on
/// indices, `N` meaning the query): from the largest down, the first non-zero coefficient
/// of the perturbed determinant, the orientation of `s` with that point replaced by `q`,
/// and for the query itself minus the orientation of `s` (`Zero` only when `s` is flat:
/// every coefficient then vanishes). The order must be invariant under the group of the
/// space, so that every copy of a configuration gets the same answer.
pub(crate) fn perturbed_by<T: Copy, const N: usize>(
    s: &[T; N],
    q: T,
    orient: impl Fn(&[T; N]) -> Sign,
    compare: impl Fn(usize, usize) -> Sign,
) -> Sign {
    const { assert!(N < 8) };
    let mut all = [0, 1, 2, 3, 4, 5, 6, 7];
    let order = &mut all[..=N];
    for i in 1..=N {
        let mut j = i;
        while j > 0 && compare(order[j - 1], order[j]) == Sign::Positive {
            order.swap(j - 1, j);
            j -= 1;
        }
    }
    for &idx in order.iter().rev() {
        if idx == N {
            // the query's own coefficient: positive for the cells of a triangulation
            return orient(s).flip();
        }
        let mut t = *s;
        t[idx] = q;
        let o = orient(&t);
        if o != Sign::Zero {
            return o;
        }
    }
    unreachable!("the order holds the query")
}
