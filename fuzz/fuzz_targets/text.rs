//! The text reader on any bytes: it must not panic, and either return points (every row
//! of D finite numbers) or a parse error that names the file. `crates/orbitri/tests/readers.rs`
//! checks the same, and more, with proptest on fixed seeds.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use orbitri::Error;

fn check<const D: usize>(data: &[u8]) {
    let file = Path::new("fuzz.txt");
    match orbitri::io::parse_text::<D>(data, file) {
        Ok(points) => {
            assert!(!points.is_empty());
            assert!(points.as_flattened().iter().all(|x| x.is_finite()));
        }
        Err(e @ Error::Parse { .. }) => {
            assert!(e.to_string().starts_with("fuzz.txt:"), "{e}");
            assert!(e.to_string().len() < 1000, "{e}");
        }
        Err(e) => panic!("{e:?} is not a parse error naming the file"),
    }
}

fuzz_target!(|data: &[u8]| {
    check::<2>(data);
    check::<3>(data);
});
