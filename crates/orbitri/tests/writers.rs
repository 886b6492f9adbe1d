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

#[test]
fn absurd_picture_options_are_typed_errors_before_any_output() {
    use orbitri::io::{write_svg, SvgOptions};
    let tri = square();
    let opts = |copies, width| SvgOptions {
        copies,
        width,
        ..SvgOptions::default()
    };
    let cases = [
        (opts(3, 100_000.0), "width", "100000"),
        (opts(3, 0.5), "width", "0.5"),
        (opts(3, f64::NAN), "width", "NaN"),
        (opts(3, f64::INFINITY), "width", "inf"),
        (opts(1000, 800.0), "copies", "1000"),
        (opts(SvgOptions::MAX_COPIES + 1, 800.0), "copies", "51"),
    ];
    for (o, name, shown) in cases {
        match o.validate(5) {
            Err(orbitri::Error::InvalidOption { option, value, .. }) => {
                assert_eq!((option, value.as_str()), (name, shown));
            }
            other => panic!("{o:?}: {other:?}"),
        }
        // write_svg refuses them too, with the typed error inside, and writes nothing
        let mut out = Vec::new();
        let e = write_svg(&mut out, &tri, &o).unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::InvalidInput);
        let inner = e.get_ref().unwrap().downcast_ref::<orbitri::Error>();
        assert!(
            matches!(inner, Some(orbitri::Error::InvalidOption { option, .. }) if *option == name),
            "{e}"
        );
        assert!(out.is_empty());
    }
    // copies² × points is bounded: 20² copies of 5000 points are 2 000 000, one more is not
    assert!(opts(20, 800.0).validate(5000).is_ok());
    let e = opts(20, 800.0).validate(5001).unwrap_err().to_string();
    assert_eq!(
        e,
        "copies 20 is out of range: 20² copies of 5001 points make 2000400 points to draw, more than 2000000"
    );
    // the limits themselves are fine, and so is 0 copies (drawn as 1)
    for o in [opts(50, 8192.0), opts(0, 1.0), SvgOptions::default()] {
        let mut out = Vec::new();
        write_svg(&mut out, &tri, &o).unwrap();
        assert!(out.starts_with(b"<svg"));
    }
    // the height follows the domain's aspect ratio, and is bounded too
    let tall = PeriodicDelaunay2::build(
        FlatTorus2::cuboid([1.0, 9.0]).unwrap(),
        &[[0.5, 0.5], [0.2, 4.0], [0.7, 8.0]],
    )
    .unwrap();
    let mut out = Vec::new();
    write_svg(&mut out, &tall, &opts(3, 1000.0)).unwrap();
    let mut out = Vec::new();
    let e = write_svg(&mut out, &tall, &opts(3, 2000.0)).unwrap_err();
    assert_eq!(
        e.to_string(),
        "width 2000 is out of range: the picture would be 13765 pixels high (the domain's aspect ratio), more than 8192"
    );
    assert!(out.is_empty());
}

/// A cell as the `cells` file writes it: input ids, then offsets.
type Row = (Vec<u32>, Vec<i32>);

/// The `cells` file, read back: its header and one (input ids, offsets) row per line.
fn read_cells(text: &str) -> ([usize; 3], Vec<Row>) {
    let mut lines = text.lines();
    let head: Vec<usize> = lines
        .next()
        .unwrap()
        .split(' ')
        .map(|x| x.parse().unwrap())
        .collect();
    let rows = lines
        .map(|l| {
            let x: Vec<i64> = l.split(' ').map(|x| x.parse().unwrap()).collect();
            let ids = x[..3].iter().map(|&v| v as u32).collect();
            (ids, x[3..].iter().map(|&v| v as i32).collect())
        })
        .collect();
    ([head[0], head[1], head[2]], rows)
}

#[test]
fn the_cells_file_lists_the_complex_in_a_covering_and_in_one_sheet() {
    // five points stay in a covering; a thousand reach one sheet
    let many: Vec<[f64; 2]> = (0..1000)
        .map(|i| {
            let t = i as f64;
            [
                (t * 0.618_033_988_75).fract(),
                (t * 0.414_213_562_37).fract(),
            ]
        })
        .collect();
    let big = PeriodicDelaunay2::build(FlatTorus2::cuboid([1.0, 1.0]).unwrap(), &many).unwrap();
    let small = square();
    assert!(!small.is_one_sheeted() && big.is_one_sheeted());
    for tri in [small, big] {
        let mut out = Vec::new();
        orbitri::io::write_cells(&mut out, &tri).unwrap();
        let (head, rows) = read_cells(&String::from_utf8(out).unwrap());
        let complex = tri.complex().unwrap();
        assert_eq!(
            head,
            [tri.sheets(), tri.number_of_vertices(), complex.cells.len()]
        );
        let want: Vec<Row> = complex
            .cells
            .iter()
            .map(|c| {
                let ids = c.vertices.iter().map(|v| v.0).collect();
                let off = c.offsets.iter().flatten().map(|&o| i32::from(o)).collect();
                (ids, off)
            })
            .collect();
        assert_eq!(rows, want);
    }
}
