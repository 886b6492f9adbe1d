//! The `.npy` reader on any bytes: it must not panic, and either return points (finite
//! numbers, at least one row) or a parse error that names the file.
//! `crates/orbitri/tests/readers.rs` checks the same, and more, with proptest on fixed seeds.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use orbitri::Error;

fn check<const D: usize>(data: &[u8]) {
    let file = Path::new("fuzz.npy");
    match orbitri::io::parse_npy::<D>(data, file) {
        Ok(points) => {
            assert!(!points.is_empty());
            assert!(points.as_flattened().iter().all(|x| x.is_finite()));
        }
        Err(e @ Error::Parse { .. }) => {
            assert!(e.to_string().starts_with("fuzz.npy:1: "), "{e}");
        }
        Err(e) => panic!("{e:?} is not a parse error naming the file"),
    }
}

fuzz_target!(|data: &[u8]| {
    check::<2>(data);
    check::<3>(data);
});
