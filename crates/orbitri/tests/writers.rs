//! The writers' guards: no bare `NaN` or `inf` in JSON, and options that would allocate
//! without bound are refused with typed errors.

use orbitri::{FlatTorus2, PeriodicDelaunay2};

fn square() -> PeriodicDelaunay2 {
    let pts = [
        [0.1, 0.2],
        [0.7, 0.4],
        [0.3, 0.8],
        [0.55, 0.15],
        [0.85, 0.9],
    ];
    PeriodicDelaunay2::build(FlatTorus2::cuboid([1.0, 1.0]).unwrap(), &pts).unwrap()
}

#[test]
fn voronoi_json_writes_null_for_non_finite_numbers() {
    let tri = square();
    let mut cells = tri.voronoi_cells();
    let mut clean = Vec::new();
    orbitri::io::write_voronoi_json(&mut clean, &tri, &cells).unwrap();
    // hand-made non-finite values in every kind of number the cells hold
    cells[0].volume = f64::NAN;
    cells[0].vertices[0][0] = f64::INFINITY;
    cells[0].centroid[1] = f64::NEG_INFINITY;
    cells[1].position[0] = f64::NAN;
    cells[1].faces[0].area = f64::NAN;
    let mut out = Vec::new();
    orbitri::io::write_voronoi_json(&mut out, &tri, &cells).unwrap();
    let text = String::from_utf8(out).unwrap();
    for bare in ["NaN", "nan", "inf"] {
        assert!(!text.contains(bare), "{bare} in {text}");
    }
    assert!(text.contains("\"volume\":null"), "{text}");
    assert!(text.contains("\"area\":null"), "{text}");
    assert!(text.contains("\"position\":[null,"), "{text}");
    // five numbers became null, nothing else changed
    let clean = String::from_utf8(clean).unwrap();
    assert_eq!(text.matches("null").count(), 5);
    assert_eq!(text.matches(',').count(), clean.matches(',').count());
}
