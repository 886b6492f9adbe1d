//! Sequences of insertions, removals and moves on any bytes, in a square and a hexagonal
//! torus: nothing may panic, every operation either works or returns a typed error that
//! changes nothing, the triangulation is valid after each step, and at the end it equals a
//! fresh build of the surviving points. `crates/orbitri/tests/dynamic.rs` runs the same
//! property with proptest on fixed seeds in CI.
#![no_main]

use libfuzzer_sys::fuzz_target;
use orbitri::{Copies, FlatTorus2, InputId, PeriodicDelaunay2};

/// A coordinate from one byte: a 16-step grid (cocircular sets and duplicates), sometimes
/// outside the box, sometimes not a number.
fn coord(b: u8) -> f64 {
    match b {
        250 => f64::NAN,
        251 => f64::INFINITY,
        _ => (b % 48) as f64 / 16.0 - 1.0,
    }
}

fuzz_target!(|data: &[u8]| {
    for lattice in [[[1.0, 0.0], [0.0, 1.0]], [[1.0, 0.0], [0.5, 0.75f64.sqrt()]]] {
        let mut tri = PeriodicDelaunay2::new(FlatTorus2::triclinic(lattice).unwrap());
        for op in data.chunks_exact(4) {
            let n = tri.number_of_input_points();
            let id = InputId(u32::from_le_bytes([op[1], op[2], 0, 0]) % (n as u32 + 2));
            let p = [coord(op[2]), coord(op[3])];
            let before = tri.number_of_cells();
            let ok = match op[0] % 4 {
                0 | 1 => tri.insert(p).is_ok(),
                2 => tri.remove(id).is_ok(),
                _ => tri.move_point(id, p).is_ok(),
            };
            if !ok {
                assert_eq!(tri.number_of_cells(), before, "a failed operation changed nothing");
            }
            if tri.number_of_vertices() > 0 {
                tri.is_valid().unwrap();
            }
        }
        let first = tri.first_occurrences();
        let live: Vec<[f64; 2]> = (0..first.len())
            .filter(|&i| first[i] != InputId::NONE)
            .map(|i| tri.point(tri.vertex_of_input(InputId::new(i))))
            .collect();
        if let Ok(fresh) = PeriodicDelaunay2::build(tri.space().clone(), &live) {
            if fresh.sheets() == tri.sheets() {
                assert_eq!(fresh.number_of_cells(), tri.number_of_cells());
                assert_eq!(fresh.cells(Copies::Unique).len(), tri.cells(Copies::Unique).len());
            }
        }
    }
});
