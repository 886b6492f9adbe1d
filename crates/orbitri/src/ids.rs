//! Typed ids: one type per kind of index, so that the compiler refuses to use one where
//! another is meant. Each is a `u32` underneath (`#[repr(transparent)]`, zero-cost); `index`
//! gives the `usize` to index a store with, `NONE` (`u32::MAX`) marks an unset slot.
//!
//! - [`CellId`]: a slot of the engine's cell store.
//! - [`VertexId`]: a vertex of the stored triangulation; in a covering space each point has
//!   one vertex per sheet, in the 1-sheeted quotient the vertex of a point has its id.
//! - [`PointId`]: a distinct point, in the engine's order of insertion (the facade's
//!   "vertex": duplicates share one).
//! - [`InputId`]: the position of a point among all the points given, in the order given
//!   (what the output lists, the writers and the Python bindings call an id).

use std::fmt;
use std::hash::{Hash, Hasher};
use std::sync::atomic::AtomicU32;
use std::sync::atomic::Ordering::Relaxed;

use rayon::prelude::*;

macro_rules! id {
    ($(#[$doc:meta])* $name:ident) => {
        $(#[$doc])*
        #[repr(transparent)]
        #[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
        pub struct $name(pub u32);

        impl $name {
            /// Marks a missing id.
            pub const NONE: Self = $name(u32::MAX);

            /// The id of index `i`, which must fit in a `u32`.
            #[inline(always)]
            pub const fn new(i: usize) -> Self {
                debug_assert!(i <= u32::MAX as usize);
                $name(i as u32)
            }

            /// The id as an index.
            #[inline(always)]
            pub const fn index(self) -> usize {
                self.0 as usize
            }

        }

        // SAFETY: `#[repr(transparent)]` over `u32`.
        unsafe impl TransparentU32 for $name {}

        /// Hashes as its number; a slice of ids as one slice of numbers (a derived `Hash`
        /// would write them one by one: the gift wrapping's facet keys are arrays of ids).
        impl Hash for $name {
            #[inline]
            fn hash<H: Hasher>(&self, state: &mut H) {
                self.0.hash(state)
            }

            #[inline]
            fn hash_slice<H: Hasher>(data: &[Self], state: &mut H) {
                // SAFETY: `#[repr(transparent)]` over `u32`: the ids are `u32`s in memory.
                let raw =
                    unsafe { std::slice::from_raw_parts(data.as_ptr().cast::<u32>(), data.len()) };
                u32::hash_slice(raw, state)
            }
        }

        impl From<u32> for $name {
            #[inline(always)]
            fn from(i: u32) -> Self {
                $name(i)
            }
        }

        impl From<$name> for u32 {
            #[inline(always)]
            fn from(id: $name) -> u32 {
                id.0
            }
        }

        /// The plain number, as the writers print ids.
        impl fmt::Display for $name {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                fmt::Display::fmt(&self.0, f)
            }
        }
    };
}

id!(
    /// A slot of the cell store ([`crate::tds::Tds`]); `NONE` is "no neighbour".
    CellId
);
id!(
    /// A vertex of the stored triangulation: in a covering space, one per copy of a point
    /// (see [`crate::Engine::point_of`]); in the 1-sheeted quotient, the point's own id.
    VertexId
);
id!(
    /// A distinct point, indexing the engine's points: a vertex of the quotient.
    PointId
);
id!(
    /// The position of a point among all the points given to a triangulation, in the order
    /// given; duplicates are listed by the id of their first occurrence.
    InputId
);

/// A type laid out as a `u32` (the ids: `#[repr(transparent)]` over one).
///
/// # Safety
/// Implement only for types with the size, alignment and bit validity of `u32`.
pub(crate) unsafe trait TransparentU32: Copy {}

/// A store of ids as atomics, for threads that write it at once (each its own entries,
/// or racing to a result that does not depend on the order).
pub(crate) fn atomics<T: TransparentU32>(ids: &mut [T]) -> &[AtomicU32] {
    const { assert!(std::mem::align_of::<u32>() == std::mem::align_of::<AtomicU32>()) };
    // SAFETY: `T` is laid out as a `u32` (`TransparentU32`), which `AtomicU32` has the size
    // and bit validity of and here the alignment (checked above); the mutable borrow is
    // exclusive while the atomics live.
    unsafe { std::slice::from_raw_parts(ids.as_mut_ptr().cast(), ids.len()) }
}

/// Records that inputs `input(n)`, `n < count`, became the points `point_input.len() + n`
/// (a bulk insertion whose points were all new): each names the other, in `input_point`
/// and `point_input`. On rayon's pool: the inputs come in a random order, and one by one
/// their entries cost 16 ms of a build of 10⁶ points in a square.
pub(crate) fn record_new_inputs(
    (point_input, input_point): (&mut Vec<InputId>, &mut [PointId]),
    count: usize,
    input: impl Fn(usize) -> InputId + Sync,
) {
    let first = point_input.len();
    point_input.par_extend((0..count).into_par_iter().map(&input));
    let slots = atomics(input_point);
    (0..count)
        .into_par_iter()
        .with_min_len(1 << 12)
        .for_each(|n| {
            slots[input(n).index()].store((first + n) as u32, Relaxed);
        });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_as_atomics_write_the_store() {
        let mut ids = vec![PointId::NONE; 4];
        let shared = atomics(&mut ids);
        shared[2].store(7, Relaxed);
        shared[0].fetch_max(3, Relaxed);
        assert_eq!(
            ids,
            [PointId::NONE, PointId::NONE, PointId(7), PointId::NONE]
        );
    }

    #[test]
    fn new_inputs_and_their_points_name_each_other() {
        // two points already; 20 000 inputs of which every other one becomes a point,
        // in a shuffled order
        let mut point_input = vec![InputId(5), InputId(9)];
        let mut input_point = vec![PointId::NONE; 20_000];
        let order: Vec<u32> = (0..10_000u32).map(|n| (n * 7919 % 10_000) * 2).collect();
        let tables = (&mut point_input, &mut input_point[..]);
        record_new_inputs(tables, order.len(), |n| InputId(order[n]));
        assert_eq!(point_input.len(), 10_002);
        assert_eq!(&point_input[..2], &[InputId(5), InputId(9)]);
        for (n, &i) in order.iter().enumerate() {
            assert_eq!(point_input[2 + n], InputId(i));
            assert_eq!(input_point[i as usize], PointId::new(2 + n));
        }
        assert!(input_point
            .iter()
            .skip(1)
            .step_by(2)
            .all(|&p| p == PointId::NONE));
    }

    #[test]
    fn ids_are_their_numbers() {
        assert_eq!(std::mem::size_of::<[CellId; 4]>(), 16);
        assert_eq!(CellId::NONE.0, u32::MAX);
        assert_eq!(VertexId::new(7).index(), 7);
        assert_eq!(u32::from(InputId::from(3)), 3);
        assert_eq!(format!("{}", PointId(12)), "12");
        assert!(InputId(2) < InputId(10));
        let hash = |x: &dyn Fn(&mut std::hash::DefaultHasher)| {
            let mut h = std::hash::DefaultHasher::new();
            x(&mut h);
            h.finish()
        };
        let ids = [VertexId(3), VertexId(u32::MAX), VertexId(7)];
        assert_eq!(
            hash(&|h| ids.hash(h)),
            hash(&|h| [3u32, u32::MAX, 7].hash(h))
        );
        assert_eq!(hash(&|h| CellId(9).hash(h)), hash(&|h| 9u32.hash(h)));
    }
}
