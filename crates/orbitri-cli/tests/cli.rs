//! The command as a user runs it: outputs, statistics, and errors with exit codes.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn orbitri(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_orbitri"))
        .args(args)
        .output()
        .unwrap()
}

/// `orbitri triangulate INPUT --box 1 1 1 EXTRA...`
fn triangulate_cube(input: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "triangulate",
        input.to_str().unwrap(),
        "--box",
        "1",
        "1",
        "1",
    ];
    args.extend_from_slice(extra);
    orbitri(&args)
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn random_text(n: usize) -> String {
    let mut s = String::from("# x y z\n");
    let mut x: u64 = 12345;
    for _ in 0..n {
        let mut c = [0.0; 3];
        for v in c.iter_mut() {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            *v = (x >> 11) as f64 / (1u64 << 53) as f64;
        }
        s.push_str(&format!("{}, {} {}\n", c[0], c[1], c[2]));
    }
    s
}

/// A `cells` file: its header's numbers, and its rows.
fn cells_file(text: &str) -> (Vec<usize>, Vec<Vec<i64>>) {
    let mut lines = text.lines();
    let header = lines
        .next()
        .unwrap()
        .split(' ')
        .map(|s| s.parse().unwrap())
        .collect();
    let rows = lines
        .map(|l| l.split(' ').map(|s| s.parse().unwrap()).collect())
        .collect();
    (header, rows)
}

#[test]
fn cells_output_matches_the_library() {
    let dir = tempfile::tempdir().unwrap();
    let input = write(dir.path(), "pts.txt", &random_text(1200));
    let out = dir.path().join("cells.txt");
    let o = triangulate_cube(&input, &["-o", out.to_str().unwrap(), "--stats"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (header, rows) = cells_file(&std::fs::read_to_string(&out).unwrap());
    assert_eq!(header[0], 1);
    assert_eq!(header[1], 1200);
    assert_eq!(rows.len(), header[2]);
    assert!(rows
        .iter()
        .all(|r| r.len() == 16 && r[..4].iter().all(|&v| (0..1200).contains(&v))));
    let pts: Vec<[f64; 3]> = orbitri::io::read_points(&input).unwrap();
    let tri =
        orbitri::PeriodicDelaunay3::build(orbitri::FlatTorus3::cuboid([1.0; 3]).unwrap(), &pts)
            .unwrap();
    assert_eq!(header[2], tri.number_of_cells());
    let stats = stderr(&o);
    for key in [
        "vertices=1200 ",
        "cells=",
        "sheets=1 ",
        "duplicates=0 ",
        "wrapped=0 ",
        "build_seconds=",
        "peak_rss_kb=",
    ] {
        assert!(stats.contains(key), "missing {key} in {stats}");
    }
}

/// A few points stay in the cube's 27-sheeted covering: the `cells` file and the JSON list
/// the torus's cells (one per orbit), which fill the cube once, and the JSON's gluing makes
/// each facet its neighbour's.
#[test]
fn a_covering_is_written_as_the_torus() {
    let dir = tempfile::tempdir().unwrap();
    let input = write(dir.path(), "few.txt", &random_text(3));
    let o = triangulate_cube(&input, &["--stats"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (header, rows) = cells_file(&String::from_utf8_lossy(&o.stdout));
    assert_eq!((header[0], header[1], header[2]), (27, 3, rows.len()));
    assert!(
        stderr(&o).contains(&format!("cells={} sheets=27 ", rows.len())),
        "{}",
        stderr(&o)
    );
    let pts: Vec<[f64; 3]> = orbitri::io::read_points(&input).unwrap();
    let corner = |r: &[i64], k: usize| -> Vec<f64> {
        (0..3)
            .map(|a| pts[r[k] as usize][a] + r[4 + 3 * k + a] as f64)
            .collect()
    };
    let volume: f64 = rows
        .iter()
        .map(|r| {
            let p: Vec<Vec<f64>> = (0..4).map(|k| corner(r, k)).collect();
            let e: Vec<Vec<f64>> = (1..4)
                .map(|k| (0..3).map(|a| p[k][a] - p[0][a]).collect())
                .collect();
            det(&e) / 6.0
        })
        .sum();
    assert!((volume - 1.0).abs() < 1e-12, "the cells fill {volume}");
    let o = triangulate_cube(&input, &["--format", "json"]);
    let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let get = |key: &str| -> Vec<Vec<serde_json::Value>> {
        serde_json::from_value(json[key].clone()).unwrap()
    };
    let (cells, offsets) = (get("cells"), get("offsets"));
    let (neighbors, mirrors, gluings) = (get("neighbors"), get("mirrors"), get("gluings"));
    assert_eq!(cells.len(), rows.len());
    let offset = |v: &serde_json::Value| -> Vec<i64> { serde_json::from_value(v.clone()).unwrap() };
    for c in 0..cells.len() {
        for i in 0..4 {
            let (n, j) = (
                neighbors[c][i].as_u64().unwrap() as usize,
                mirrors[c][i].as_u64().unwrap() as usize,
            );
            let g = offset(&gluings[c][i]);
            let mut here: Vec<(u64, Vec<i64>)> = (0..4)
                .filter(|&k| k != i)
                .map(|k| (cells[c][k].as_u64().unwrap(), offset(&offsets[c][k])))
                .collect();
            let mut there: Vec<(u64, Vec<i64>)> = (0..4)
                .filter(|&k| k != j)
                .map(|k| {
                    let o = offset(&offsets[n][k]);
                    (
                        cells[n][k].as_u64().unwrap(),
                        (0..3).map(|a| o[a] + g[a]).collect(),
                    )
                })
                .collect();
            here.sort();
            there.sort();
            assert_eq!(here, there, "cell {c}, facet {i}");
        }
    }
}

#[test]
fn json_npy_lattice_duplicates_and_wrapping() {
    let dir = tempfile::tempdir().unwrap();
    let rows = vec![
        [0.1, 0.2, 0.3],
        [1.1, 0.2, 0.3],
        [0.5, 0.5, 0.5],
        [0.9, 0.1, 0.7],
        [0.3, 0.8, 0.2],
    ];
    let npy = dir.path().join("p.npy");
    std::fs::write(&npy, orbitri::io::encode_npy(&rows)).unwrap();
    let o = orbitri(&[
        "triangulate",
        npy.to_str().unwrap(),
        "--lattice",
        "1",
        "0",
        "0",
        "0.2",
        "1",
        "0",
        "0",
        "-0.1",
        "1",
        "--format",
        "json",
        "--stats",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let json = String::from_utf8(o.stdout.clone()).unwrap();
    assert!(json.starts_with("{\"dimension\":3,\"sheets\":"), "{json}");
    // 1.1 − 1 is not 0.1 in binary: the wrapped point 1 differs from point 0, no duplicate
    assert!(json.contains("\"first_occurrence\":[0,1,2,3,4]"), "{json}");
    assert!(stderr(&o).contains("wrapped=1"));
}

#[test]
fn a_duplicate_takes_its_first_occurrence_id() {
    let dir = tempfile::tempdir().unwrap();
    let input = write(
        dir.path(),
        "d.txt",
        "0.25 0.25 0.25\n0.75 0.5 0.5\n1.25 0.25 0.25\n0.5 0.75 0.125\n0.125 0.5 0.875\n",
    );
    let o = triangulate_cube(&input, &["--stats"]);
    assert!(o.status.success());
    let text = String::from_utf8(o.stdout.clone()).unwrap();
    assert!(
        text.lines()
            .skip(1)
            .all(|l| !l.split(' ').take(4).any(|v| v == "2")),
        "id 2 is a duplicate of 0"
    );
    assert!(text.starts_with("27 4 "), "{}", &text[..20]);
    assert!(stderr(&o).contains("duplicates=1"));
}

#[test]
fn bad_input_gets_a_clear_error_and_exit_code_2() {
    let dir = tempfile::tempdir().unwrap();
    let cube = "--box 1 1 1";
    let cases = [
        (
            "nan.txt",
            "0 0 0\n0.5 nan 0.5\n",
            cube,
            "nan.txt:2: coordinate 1 is NaN",
        ),
        (
            "inf.txt",
            "0 0 0\n\n0.5 0.5 -inf\n",
            cube,
            "inf.txt:3: coordinate 2 is -inf",
        ),
        (
            "cols.txt",
            "0 0 0\n0.5 0.5\n",
            cube,
            "cols.txt:2: expected 3 coordinates, found 2",
        ),
        (
            "word.txt",
            "0 0 zero\n",
            cube,
            "word.txt:1: coordinate 2 'zero' is not a number",
        ),
        (
            "empty.txt",
            "# nothing\n\n",
            cube,
            "the file holds no points",
        ),
        (
            "a.txt",
            "0.5 0.5 0.5\n",
            "--box 1 0 1",
            "invalid box: length 1 is 0",
        ),
        (
            "b.txt",
            "0.5 0.5 0.5\n",
            "--box 1 -2 1",
            "invalid box: length 1 is -2",
        ),
        (
            "c.txt",
            "0.5 0.5 0.5\n",
            "--lattice 1 0 0 0 1 0 1 1 0",
            "singular lattice",
        ),
        (
            "d.txt",
            "0.5 0.5 0.5\n",
            "--lattice 1 0 0 30 0.1 0 0 0 1",
            "lattice too skewed",
        ),
        ("missing.txt", "", cube, "missing.txt: No such file"),
        (
            "field.txt",
            "0 0 0\n0.1,,0.3\n",
            cube,
            "field.txt:2: field 2 is empty",
        ),
        (
            "nul.txt",
            "0 0 0\n0.1 0.2 0.3\n0.1 0.2\x000.3\n",
            cube,
            "nul.txt:3: control character U+0000 at column 8",
        ),
    ];
    for (name, text, domain, msg) in cases {
        let path = if text.is_empty() {
            dir.path().join(name)
        } else {
            write(dir.path(), name, text)
        };
        let mut args = vec!["triangulate", path.to_str().unwrap()];
        args.extend(domain.split(' '));
        let o = orbitri(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        assert!(stderr(&o).contains(msg), "{args:?}: {}", stderr(&o));
    }
    // clap: missing domain
    let o = orbitri(&["triangulate", "x.txt"]);
    assert!(!o.status.success());
    // .npy files without points: 0 bytes, a cut header, 0 rows
    let full = orbitri::io::encode_npy(&[[0.5, 0.5, 0.5]]);
    for (name, bytes, msg) in [
        ("zero.npy", &b""[..], "zero.npy:1: empty file (0 bytes)"),
        ("cut.npy", &full[..9], "cut.npy:1: truncated .npy header"),
        (
            "rows.npy",
            &orbitri::io::encode_npy::<3>(&[])[..],
            "rows.npy:1: the file holds no points",
        ),
    ] {
        let path = dir.path().join(name);
        std::fs::write(&path, bytes).unwrap();
        let o = triangulate_cube(&path, &[]);
        assert_eq!(o.status.code(), Some(2), "{name}");
        assert!(stderr(&o).contains(msg), "{name}: {}", stderr(&o));
    }
    // a byte-order mark at the start is no error
    let bom = write(dir.path(), "bom.txt", "\u{feff}0.5 0.5 0.5\n");
    let o = triangulate_cube(&bom, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn numbers_are_read_as_rust_reads_them() {
    let dir = tempfile::tempdir().unwrap();
    let p3 = write(
        dir.path(),
        "p3.txt",
        "1e-4 2e-4 3e-4\n5e-4 1e-4 7e-4\n2e-4 6e-4 1e-4\n",
    );
    let p2 = write(dir.path(), "p2.txt", "0.1 0.2\n0.6 0.5\n0.3 0.8\n");
    let out = dir.path().join("out.txt");
    let out = out.to_str().unwrap();
    let run = |input: &Path, domain: &str| {
        let mut args = vec!["triangulate", input.to_str().unwrap()];
        args.extend(domain.split(' '));
        orbitri(&args)
    };
    // negative numbers with a negative exponent were unknown flags (`-2`); the flag after
    // the values stays a flag, also when the option could take more values
    for (input, domain) in [
        (&p3, "--lattice 1e-3 0 0 3e-4 9e-4 0 -2e-4 2e-4 1.1e-3 -o"),
        (&p2, "--lattice 1 0 -2e-1 1 -o"),
        (&p2, "--box 1 1 -o"),
        (&p2, "--lattice 1 -0 -.25 1E0 -o"),
    ] {
        let _ = std::fs::remove_file(out);
        let o = run(input, &format!("{domain} {out}"));
        assert!(o.status.success(), "{domain}: {}", stderr(&o));
        let text = std::fs::read_to_string(out).unwrap();
        // `SHEETS V C`: 3 points, in a covering space
        assert_eq!(text.split(' ').nth(1), Some("3"), "{domain}: {text}");
    }
    // a lattice of side 1e-300 with negative exponents: read, and triangulated
    let tiny = write(
        dir.path(),
        "tiny.txt",
        "1e-301 2e-301 3e-301
5e-301 4e-301 1e-301
7e-301 1e-301 6e-301
",
    );
    let o = run(
        &tiny,
        "--lattice 1e-300 0 0 3e-301 9e-301 0 -2e-301 2e-301 1.1e-300 --stats",
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("vertices=3"), "{}", stderr(&o));
    // infinities and NaN reach the library's typed box errors
    for (input, domain, msg) in [
        (&p2, "--box inf 1", "invalid box: length 0 is inf"),
        (&p2, "--box 1 -inf", "invalid box: length 1 is -inf"),
        (&p2, "--box 1 -nan", "invalid box: length 1 is NaN"),
        (&p2, "--box 1 -1e-3", "invalid box: length 1 is -0.001"),
        (&p3, "--box 1 1 -.5", "invalid box: length 2 is -0.5"),
        (
            &p2,
            "--lattice 1 0 -infinity 1",
            "invalid box: lattice vector 1, component 0 is -inf",
        ),
        // a wrong count still errors
        (&p2, "--lattice 1 0 0 1 -2e-1", "takes 4 numbers"),
        (&p2, "--lattice 1 -2e-1 0", "4 values required"),
        (&p2, "--box 1", "2 values required"),
        (
            &p3,
            "--box 1 1 1 -5",
            "--box takes the lengths LX LY [LZ], not 4 numbers",
        ),
        (&p3, "--box 1 1 1 1 1 1 -5", "unexpected argument '-5'"),
        (&p2, "--box 1 x", "invalid value 'x'"),
    ] {
        let o = run(input, domain);
        assert_eq!(o.status.code(), Some(2), "{domain}");
        assert!(stderr(&o).contains(msg), "{domain}: {}", stderr(&o));
    }
}

#[test]
fn draw_limits_name_the_flag_the_value_and_the_limit() {
    let dir = tempfile::tempdir().unwrap();
    let pts = dir.path().join("p2.txt");
    orbitri(&[
        "generate",
        "3000",
        "--dim",
        "2",
        "-o",
        pts.to_str().unwrap(),
    ]);
    let one = write(dir.path(), "one.txt", "0.5 0.5\n");
    let png = dir.path().join("t.png");
    for (input, args, msg) in [
        (&pts, "--box 1 1 --width 100000", "--width 100000 is out of range: a picture is 1 to 8192 pixels wide"),
        (&pts, "--box 1 1 --width -1e-3", "--width -0.001 is out of range"),
        (&pts, "--box 1 1 --width nan", "--width NaN is out of range"),
        (&pts, "--box 1 1 --copies 1000", "--copies 1000 is out of range: at most 50 per lattice direction"),
        (&one, "--box 1 1 --copies 51", "--copies 51 is out of range"),
        (&pts, "--box 1 1 --copies 30", "--copies 30 is out of range: 30² copies of 3000 points make 2700000 points to draw, more than 2000000"),
        (&one, "--box 1 9 --width 3000", "--width 3000 is out of range: the picture would be 20647 pixels high"),
    ] {
        let mut a = vec!["draw", input.to_str().unwrap(), "-o", png.to_str().unwrap()];
        a.extend(args.split(' '));
        let o = orbitri(&a);
        assert_eq!(o.status.code(), Some(2), "{args}");
        assert!(stderr(&o).contains(msg), "{args}: {}", stderr(&o));
        assert!(!png.exists());
    }
    // at the limits
    let svg = dir.path().join("t.svg");
    for (input, args) in [(&one, "--copies 50"), (&pts, "--copies 25 --width 8192")] {
        let mut a = vec![
            "draw",
            input.to_str().unwrap(),
            "--box",
            "1",
            "1",
            "-o",
            svg.to_str().unwrap(),
        ];
        a.extend(args.split(' '));
        let o = orbitri(&a);
        assert!(o.status.success(), "{args}: {}", stderr(&o));
    }
    let help = String::from_utf8(orbitri(&["draw", "--help"]).stdout).unwrap();
    assert!(
        help.contains("at most 50") && help.contains("1 to 8192"),
        "{help}"
    );
}

#[test]
fn generate_reproduces_the_anchor_points() {
    let o = orbitri(&["generate", "2", "--seed", "1"]);
    let text = String::from_utf8(o.stdout.clone()).unwrap();
    assert_eq!(
        text.lines().next().unwrap(),
        "0.5665615751722809 0.7457817572627011 0.9710027535867962"
    );
}

#[test]
fn demo_runs() {
    let o = orbitri(&["demo", "-n", "3000"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8(o.stdout.clone()).unwrap();
    assert!(
        text.contains("vertices=3000") && text.contains("5184 cells"),
        "{text}"
    );
}

#[test]
fn two_dimensional_boxes_and_lattices() {
    let dir = tempfile::tempdir().unwrap();
    let pts = dir.path().join("p2.txt");
    let o = orbitri(&["generate", "500", "--dim", "2", "-o", pts.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let input = pts.to_str().unwrap();
    for domain in [
        vec!["--box", "1", "1"],
        vec!["--lattice", "1", "0", "0.5", "0.8660254037844386"],
    ] {
        let mut args = vec!["triangulate", input];
        args.extend_from_slice(&domain);
        args.push("--stats");
        let o = orbitri(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        let text = String::from_utf8(o.stdout.clone()).unwrap();
        let mut lines = text.lines();
        // a torus has exactly 2 triangles per point
        assert_eq!(lines.next().unwrap(), "1 500 1000");
        let rows: Vec<Vec<i64>> = lines
            .map(|l| l.split(' ').map(|x| x.parse().unwrap()).collect())
            .collect();
        assert_eq!(rows.len(), 1000);
        // 3 ids and 3 offsets of 2 integers, every id used
        assert!(rows.iter().all(|r| r.len() == 9));
        let mut used = vec![false; 500];
        rows.iter()
            .for_each(|r| (0..3).for_each(|k| used[r[k] as usize] = true));
        assert!(used.iter().all(|&u| u));
        assert!(stderr(&o).contains("cells=1000 sheets=1"), "{}", stderr(&o));
    }
    // three numbers per line are not 2D points, and a 2D lattice takes 4 numbers
    let bad = write(dir.path(), "p3.txt", "0.1 0.2 0.3\n");
    let o = orbitri(&["triangulate", bad.to_str().unwrap(), "--box", "1", "1"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("p3.txt:1"), "{}", stderr(&o));
    let o = orbitri(&["triangulate", input, "--lattice", "1", "0", "0", "1", "0"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("4 numbers"), "{}", stderr(&o));
}

#[test]
fn draw_writes_svg_and_png() {
    let dir = tempfile::tempdir().unwrap();
    let pts = dir.path().join("p2.txt");
    orbitri(&["generate", "60", "--dim", "2", "-o", pts.to_str().unwrap()]);
    let svg = dir.path().join("t.svg");
    let o = orbitri(&[
        "draw",
        pts.to_str().unwrap(),
        "--box",
        "1",
        "1",
        "--copies",
        "2",
        "-o",
        svg.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.starts_with("<svg"));
    for id in ["voronoi", "delaunay", "points", "domain"] {
        assert!(text.contains(&format!("id=\"{id}\"")), "{id}");
    }
    // 60 points in 2×2 copies of the domain (plus copies on the window's edge)
    assert!(text.matches("<circle").count() >= 240);
    let png = dir.path().join("t.png");
    let o = orbitri(&[
        "draw",
        pts.to_str().unwrap(),
        "--lattice",
        "1",
        "0",
        "0.3",
        "0.9",
        "--width",
        "300",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    // width 300 in the IHDR chunk
    assert_eq!(u32::from_be_bytes(bytes[16..20].try_into().unwrap()), 300);
    let o = orbitri(&[
        "draw",
        pts.to_str().unwrap(),
        "--box",
        "1",
        "1",
        "1",
        "-o",
        "x.svg",
    ]);
    // draw's --box takes 2 lengths: the third is refused
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("unexpected argument '1'") && stderr(&o).contains("orbitri draw"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn voronoi_tables_cells_and_vtk() {
    let dir = tempfile::tempdir().unwrap();
    // 300 points, then one duplicate of point 7 (a period away)
    let mut text = random_text(300);
    let p7: Vec<f64> = text
        .lines()
        .nth(8)
        .unwrap()
        .split(|c: char| c == ',' || c.is_whitespace())
        .filter(|s| !s.is_empty())
        .map(|s| s.parse().unwrap())
        .collect();
    text.push_str(&format!("{} {} {}\n", p7[0] + 1.0, p7[1], p7[2]));
    let input = write(dir.path(), "pts.txt", &text);
    let csv = dir.path().join("v.csv");
    let nb = dir.path().join("nb.csv");
    let edges = dir.path().join("e.csv");
    let o = orbitri(&[
        "voronoi",
        input.to_str().unwrap(),
        "--box",
        "1",
        "1",
        "1",
        "-o",
        csv.to_str().unwrap(),
        "--neighbours",
        nb.to_str().unwrap(),
        "--edges",
        edges.to_str().unwrap(),
        "--stats",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let table = std::fs::read_to_string(&csv).unwrap();
    let mut lines = table.lines();
    assert_eq!(
        lines.next().unwrap(),
        "id,volume,neighbours,surface_area,centroid_x,centroid_y,centroid_z,duplicate_of"
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    // one row per input point, in input order; the duplicate says so and shares the cell
    assert_eq!(rows.len(), 301);
    assert!(rows.iter().enumerate().all(|(i, r)| r[0] == i.to_string()));
    assert_eq!(rows[300][7], "7");
    assert_eq!(rows[300][1..7], rows[7][1..7]);
    let total: f64 = rows[..300]
        .iter()
        .map(|r| r[1].parse::<f64>().unwrap())
        .sum();
    assert!((total - 1.0).abs() < 1e-12);
    // each pair once: twice the pairs = the faces counted over the distinct points
    let faces: usize = rows[..300]
        .iter()
        .map(|r| r[2].parse::<usize>().unwrap())
        .sum();
    let pairs = std::fs::read_to_string(&nb).unwrap().lines().count() - 1;
    assert_eq!(2 * pairs, faces);
    // Euler: E = V + C in 3D; the stats name the cells
    let edge_rows = std::fs::read_to_string(&edges).unwrap().lines().count() - 1;
    let err = stderr(&o);
    let cells: usize = err
        .split_whitespace()
        .find_map(|kv| kv.strip_prefix("cells="))
        .unwrap()
        .parse()
        .unwrap();
    assert_eq!(edge_rows, 300 + cells);
    assert!(err.contains("volume_sum="), "{err}");
    // JSON cells, VTK cells and the triangulation as VTK, 2D too
    for (name, format) in [("v.json", None), ("v.vtu", None), ("v.dat", Some("vtu"))] {
        let out = dir.path().join(name);
        let mut args = vec![
            "voronoi",
            input.to_str().unwrap(),
            "--box",
            "1",
            "1",
            "1",
            "-o",
            out.to_str().unwrap(),
        ];
        if let Some(f) = format {
            args.extend_from_slice(&["--format", f]);
        }
        let o = orbitri(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        // a binary VTU's XML header is text; its appended data is not
        let text = String::from_utf8_lossy(&std::fs::read(&out).unwrap()).into_owned();
        if name.ends_with("json") {
            assert!(text.starts_with("{\"dimension\":3"));
            assert_eq!(text.matches("\"neighbor\"").count(), faces);
        } else {
            assert!(text.contains("<VTKFile type=\"UnstructuredGrid\""));
            assert!(text.contains("NumberOfCells=\"300\""));
            assert!(text.contains("Name=\"faceoffsets\""));
            assert!(text.contains("compressor=\"vtkZLibDataCompressor\""));
            assert!(text.contains("<AppendedData encoding=\"raw\">"));
            for name in ["neighbours", "surface_area", "centroid"] {
                assert!(text.contains(&format!("Name=\"{name}\"")), "{name}");
            }
        }
    }
    let vtu = dir.path().join("t.vtu");
    let o = triangulate_cube(&input, &["--format", "vtu", "-o", vtu.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&std::fs::read(&vtu).unwrap()).into_owned();
    assert!(text.contains(&format!("NumberOfCells=\"{cells}\"")));
    let pts2 = dir.path().join("p2.txt");
    orbitri(&["generate", "50", "--dim", "2", "-o", pts2.to_str().unwrap()]);
    let npy = dir.path().join("v.npy");
    let o = orbitri(&[
        "voronoi",
        pts2.to_str().unwrap(),
        "--box",
        "1",
        "1",
        "-o",
        npy.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let bytes = std::fs::read(&npy).unwrap();
    assert_eq!(&bytes[..6], b"\x93NUMPY");
    let header = String::from_utf8_lossy(&bytes[10..80]).into_owned();
    // id, volume, neighbours, surface, centroid x y, duplicate_of
    assert!(header.contains("'shape': (50, 7)"), "{header}");
}

#[test]
fn extreme_and_elongated_boxes() {
    let dir = tempfile::tempdir().unwrap();
    // one point in a box of 1e100 (it panicked), its cells in the 27-sheeted covering
    let one = write(dir.path(), "one.txt", "3e99 1e99 7e99\n");
    let o = orbitri(&[
        "triangulate",
        one.to_str().unwrap(),
        "--box",
        "1e100",
        "1e100",
        "1e100",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).starts_with("27 1 "));
    // the same cells at 1e-100 and in the unit box, scaled by powers of ten the doubles
    // cannot scale exactly: compare the unit box with its power-of-two scalings instead
    let pts = write(dir.path(), "pts.txt", "0.25 0.5\n0.75 0.125\n0.5 0.875\n");
    let small = write(
        dir.path(),
        "small.txt",
        &format!(
            "{:e} {:e}\n{:e} {:e}\n{:e} {:e}\n",
            0.25 * 2f64.powi(-400),
            0.5 * 2f64.powi(-400),
            0.75 * 2f64.powi(-400),
            0.125 * 2f64.powi(-400),
            0.5 * 2f64.powi(-400),
            0.875 * 2f64.powi(-400)
        ),
    );
    let unit = orbitri(&["triangulate", pts.to_str().unwrap(), "--box", "1", "1"]);
    let side = format!("{:e}", 2f64.powi(-400));
    let tiny = orbitri(&[
        "triangulate",
        small.to_str().unwrap(),
        "--box",
        &side,
        &side,
    ]);
    assert!(
        unit.status.success() && tiny.status.success(),
        "{}",
        stderr(&tiny)
    );
    assert_eq!(unit.stdout, tiny.stdout);
    // elongated boxes: the documented error, at once (they hung)
    for b in [["1", "1", "1e-17"].as_slice(), &["1", "1e-10"]] {
        let mut args = vec!["triangulate", one.to_str().unwrap(), "--box"];
        args.extend_from_slice(b);
        let o = orbitri(&args);
        assert_eq!(o.status.code(), Some(2));
        assert!(stderr(&o).contains("too elongated"), "{}", stderr(&o));
    }
    // Voronoi volumes that doubles cannot hold: a typed error, not inf
    let o = orbitri(&[
        "voronoi",
        one.to_str().unwrap(),
        "--box",
        "1e110",
        "1e110",
        "1e110",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("outside the range of doubles"),
        "{}",
        stderr(&o)
    );
}

/// Every closed flat manifold the library triangulates, with the sides of its domain
/// (dyadic; the tetracosm's square cross-section) and its dimension.
fn manifolds() -> Vec<(&'static str, Vec<&'static str>)> {
    let mut out = vec![("klein", vec!["1", "0.75"])];
    for name in orbitri::FlatManifold::PLATYCOSMS {
        out.push((name, vec!["1", "1", "1.25"]));
    }
    out
}

/// `orbitri generate N --dim D` into `dir`.
fn generated(dir: &Path, n: usize, dim: usize, seed: u64) -> PathBuf {
    let p = dir.join(format!("g{n}_{dim}_{seed}.txt"));
    let o = orbitri(&[
        "generate",
        &n.to_string(),
        "--dim",
        &dim.to_string(),
        "--seed",
        &seed.to_string(),
        "-o",
        p.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    p
}

/// `orbitri COMMAND INPUT --space NAME --box SIDES… EXTRA…`
fn in_space(command: &str, input: &Path, name: &str, sides: &[&str], extra: &[&str]) -> Output {
    let mut args = vec![command, input.to_str().unwrap(), "--space", name, "--box"];
    args.extend_from_slice(sides);
    args.extend_from_slice(extra);
    orbitri(&args)
}

type Isometry = (Vec<Vec<f64>>, Vec<f64>);

/// `[A, t]` from JSON.
fn isometry(v: &serde_json::Value) -> Isometry {
    let nums = |v: &serde_json::Value| -> Vec<f64> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    let a = v[0].as_array().unwrap().iter().map(nums).collect();
    (a, nums(&v[1]))
}

fn apply((a, t): &Isometry, p: &[f64]) -> Vec<f64> {
    (0..t.len())
        .map(|i| (0..p.len()).map(|j| a[i][j] * p[j]).sum::<f64>() + t[i])
        .collect()
}

fn det(m: &[Vec<f64>]) -> f64 {
    match m.len() {
        2 => m[0][0] * m[1][1] - m[0][1] * m[1][0],
        _ => {
            m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
                - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
                + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
        }
    }
}

/// The volume of a space's standard domain: its sides' product, times `√3/2` for the 60°
/// rhombus of the hexagonal screws.
fn domain_volume(name: &str, sides: &[&str]) -> f64 {
    let product: f64 = sides.iter().map(|s| s.parse::<f64>().unwrap()).product();
    if matches!(name, "tricosm" | "hexacosm") {
        product * 3f64.sqrt() / 2.0
    } else {
        product
    }
}

/// The JSON of `triangulate` in a manifold: the group is there; lifting every cell by its
/// elements gives positively oriented simplices that fill the domain's volume once (one
/// cell per orbit, also from a covering); and each facet, moved by its gluing, is the
/// neighbour's facet at its mirror index.
fn check_liftable_json(name: &str, sides: &[&str], json: &serde_json::Value) {
    let d = sides.len();
    assert_eq!(json["dimension"], d, "{name}");
    assert_eq!(json["space"], name);
    assert!(json.get("offsets").is_none() && json.get("lattice").is_none());
    let generators: Vec<Isometry> = json["group"]["generators"]
        .as_array()
        .unwrap()
        .iter()
        .map(isometry)
        .collect();
    assert!(generators.len() >= d, "{name}: translations and cosets");
    let rows: Vec<Vec<f64>> =
        serde_json::from_value(json["group"]["translations"].clone()).unwrap();
    assert_eq!(rows.len(), d);
    // the first D generators are the translations
    for (g, r) in generators.iter().zip(&rows) {
        assert_eq!(&g.1, r, "{name}");
    }
    let points: Vec<Vec<f64>> = serde_json::from_value(json["points"].clone()).unwrap();
    let cells: Vec<Vec<usize>> = serde_json::from_value(json["cells"].clone()).unwrap();
    let elements = json["elements"].as_array().unwrap();
    assert_eq!(cells.len(), elements.len());
    let mut total = 0.0;
    for (c, e) in cells.iter().zip(elements) {
        let lifted: Vec<Vec<f64>> = c
            .iter()
            .zip(e.as_array().unwrap())
            .map(|(&v, g)| apply(&isometry(g), &points[v]))
            .collect();
        let edges: Vec<Vec<f64>> = lifted[1..]
            .iter()
            .map(|x| (0..d).map(|i| x[i] - lifted[0][i]).collect())
            .collect();
        let signed = det(&edges);
        assert!(
            signed > 0.0,
            "{name}: cell {c:?} is not positively oriented"
        );
        total += signed / if d == 2 { 2.0 } else { 6.0 };
    }
    let volume = domain_volume(name, sides);
    assert!(
        (total - volume).abs() < 1e-9 * volume,
        "{name}: the cells fill {total}, not {volume}"
    );
    let rows =
        |key: &str| -> Vec<Vec<usize>> { serde_json::from_value(json[key].clone()).unwrap() };
    let (neighbors, mirrors) = (rows("neighbors"), rows("mirrors"));
    let gluings = json["gluings"].as_array().unwrap();
    assert!(neighbors.len() == cells.len() && mirrors.len() == cells.len());
    let lifted = |k: usize, skip: usize, by: Option<&Isometry>| -> Vec<Vec<f64>> {
        let mut out: Vec<Vec<f64>> = (0..=d)
            .filter(|&a| a != skip)
            .map(|a| {
                let x = apply(&isometry(&elements[k][a]), &points[cells[k][a]]);
                by.map_or(x.clone(), |g| apply(g, &x))
            })
            .collect();
        out.sort_by(|a, b| a.partial_cmp(b).unwrap());
        out
    };
    for k in 0..cells.len() {
        for i in 0..=d {
            let (m, j) = (neighbors[k][i], mirrors[k][i]);
            assert_eq!((neighbors[m][j], mirrors[m][j]), (k, i), "{name}");
            let g = isometry(&gluings[k][i]);
            let (here, there) = (lifted(k, i, None), lifted(m, j, Some(&g)));
            for (a, b) in here.iter().zip(&there) {
                assert!(
                    a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-9),
                    "{name}: cell {k} facet {i}: {here:?} is not {there:?}"
                );
            }
        }
    }
}

#[test]
fn manifold_cells_lift_to_positive_simplices_and_voronoi_volumes_fill_the_domain() {
    let dir = tempfile::tempdir().unwrap();
    for (name, sides) in manifolds() {
        let d = sides.len();
        // a few points stay in a covering space; a thousand reach the quotient (the dummy
        // point construction), checked where that is quick
        let quotient = matches!(name, "klein" | "dicosm");
        let sizes = [(3, 1), (12, 2), (1000, 3)];
        for (n, seed) in sizes.into_iter().filter(|&(n, _)| n < 1000 || quotient) {
            let input = generated(dir.path(), n, d, seed);
            let o = in_space("triangulate", &input, name, &sides, &["--format", "json"]);
            assert!(o.status.success(), "{name}: {}", stderr(&o));
            let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
            check_liftable_json(name, &sides, &json);
            assert_eq!(json["sheets"] == 1, n == 1000, "{name}, {n} points");
            if n == 3 {
                // the cells format: D + 1 ids, then D + 1 cosets and offsets
                let o = in_space("triangulate", &input, name, &sides, &[]);
                let text = String::from_utf8(o.stdout).unwrap();
                let mut lines = text.lines();
                let header: Vec<&str> = lines.next().unwrap().split(' ').collect();
                assert_eq!(header[0], json["sheets"].to_string(), "{name}");
                assert!(lines.all(|l| l.split(' ').count() == (d + 1) * (d + 2)));
            }
            // Voronoi volumes (CSV column 2) sum to the domain's
            let o = in_space("voronoi", &input, name, &sides, &[]);
            assert!(o.status.success(), "{name}: {}", stderr(&o));
            let table = String::from_utf8(o.stdout).unwrap();
            let sum: f64 = table
                .lines()
                .skip(1)
                .map(|l| l.split(',').nth(1).unwrap().parse::<f64>().unwrap())
                .sum();
            let volume = domain_volume(name, &sides);
            assert!(
                (sum - volume).abs() < 1e-12 * volume,
                "{name}, {n} points: {sum}"
            );
        }
    }
}

#[test]
fn manifold_voronoi_faces_and_tables_carry_elements() {
    let dir = tempfile::tempdir().unwrap();
    let input = generated(dir.path(), 100, 3, 5);
    let sides = ["1", "1", "1.25"];
    let nb = dir.path().join("nb.csv");
    let edges = dir.path().join("e.csv");
    let run = |command, extra: &[&str]| in_space(command, &input, "didicosm", &sides, extra);
    let o = run(
        "voronoi",
        &[
            "--format",
            "json",
            "--neighbours",
            nb.to_str().unwrap(),
            "--edges",
            edges.to_str().unwrap(),
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let json: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(json["space"], "didicosm");
    assert_eq!(json["group"]["generators"].as_array().unwrap().len(), 6);
    let cells = json["cells"].as_array().unwrap();
    assert_eq!(cells.len(), 100);
    let faces: usize = cells
        .iter()
        .map(|c| c["faces"].as_array().unwrap().len())
        .sum();
    for c in cells {
        for f in c["faces"].as_array().unwrap() {
            assert!(f.get("shift").is_none());
            let (a, _) = isometry(&f["element"]);
            assert!(det(&a).abs() == 1.0);
        }
    }
    let pairs = std::fs::read_to_string(&nb).unwrap();
    assert!(pairs.starts_with("i,j,coset,offset_x,offset_y,offset_z,area\n"));
    assert_eq!(2 * (pairs.lines().count() - 1), faces);
    let edges = std::fs::read_to_string(&edges).unwrap();
    assert!(edges.starts_with("i,j,coset,offset_x,offset_y,offset_z,length\n"));
    // VTK: the cells drawn whole
    let vtu = dir.path().join("t.vtu");
    let o = run(
        "triangulate",
        &["--format", "vtu", "-o", vtu.to_str().unwrap()],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&std::fs::read(&vtu).unwrap())
        .contains("<VTKFile type=\"UnstructuredGrid\""));
}

#[test]
fn the_torus_is_the_default_space() {
    let dir = tempfile::tempdir().unwrap();
    let input = generated(dir.path(), 50, 2, 3);
    let default = orbitri(&["triangulate", input.to_str().unwrap(), "--box", "1", "1"]);
    let torus = in_space("triangulate", &input, "torus", &["1", "1"], &[]);
    assert!(default.status.success() && torus.status.success());
    assert_eq!(default.stdout, torus.stdout);
}

#[test]
fn bad_spaces_and_boxes_get_a_clear_error_and_exit_code_2() {
    let dir = tempfile::tempdir().unwrap();
    let p2 = generated(dir.path(), 10, 2, 1);
    let p3 = generated(dir.path(), 10, 3, 1);
    // `NAME SIDES…: message`
    let cases = [
        "mobius 1 1 1: invalid value 'mobius' for '--space",
        "klein 1 1 1: --space klein takes --box L1 L2, not 3 lengths",
        "dicosm 1 1: --space dicosm takes --box L1 L2 L3, not 2 lengths",
        "tetracosm 1 2 1: invalid box: the tetracosm turns a square cross-section: L1 = L2 needed",
        "klein 1 -1: invalid box: the Klein bottle needs two positive finite sides",
        "didicosm 1 0 1: invalid box: the didicosm needs three positive finite sides",
    ];
    for case in cases {
        let (args, msg) = case.split_once(": ").unwrap();
        let mut args: Vec<&str> = args.split(' ').collect();
        let input = if args.len() == 3 { &p2 } else { &p3 };
        let name = args.remove(0);
        let o = in_space("triangulate", input, name, &args, &[]);
        assert_eq!(o.status.code(), Some(2), "{case}");
        assert!(stderr(&o).contains(msg), "{case}: {}", stderr(&o));
    }
    // the hexagonal screws and the amphidicosms take the same box as every other space
    for name in [
        "tricosm",
        "hexacosm",
        "first-amphidicosm",
        "second-amphidicosm",
    ] {
        let o = in_space("triangulate", &p3, name, &["1", "1", "1"], &[]);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
    }
    let o = in_space("triangulate", &p3, "hexacosm", &["1", "2", "1"], &[]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o)
            .contains("the hexacosm turns a hexagonal cross-section of side L1: L1 = L2 needed"),
        "{}",
        stderr(&o)
    );
    // --lattice is the torus's
    for command in ["triangulate", "voronoi", "draw"] {
        let o = orbitri(&[
            command,
            p2.to_str().unwrap(),
            "--space",
            "klein",
            "--lattice",
            "1",
            "0",
            "0",
            "1",
            "-o",
            dir.path().join("x.svg").to_str().unwrap(),
        ]);
        assert_eq!(o.status.code(), Some(2), "{command}");
        assert!(
            stderr(&o).contains("--lattice is for the torus only: --space klein takes --box L1 L2"),
            "{command}: {}",
            stderr(&o)
        );
    }
}

#[test]
fn draw_shows_the_klein_bottle_with_its_glide_images() {
    let dir = tempfile::tempdir().unwrap();
    let pts = generated(dir.path(), 30, 2, 4);
    let svg = dir.path().join("k.svg");
    let o = in_space(
        "draw",
        &pts,
        "klein",
        &["1", "0.75"],
        &["-o", svg.to_str().unwrap()],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.starts_with("<svg"));
    for id in [
        "voronoi", "delaunay", "points", "domains", "domain", "glides",
    ] {
        assert!(text.contains(&format!("id=\"{id}\"")), "{id}");
    }
    // 30 points in each of the 3×3 images of the domain (plus copies on the window's edge)
    assert!(text.matches("<circle").count() >= 270);
    assert_eq!(text.matches("fill=\"#111\"").count(), 30);
    // a flag per image: 9 images, 2 strokes each
    let glides = text.lines().find(|l| l.contains("id=\"glides\"")).unwrap();
    assert_eq!(glides.matches('M').count(), 18);
    // the 3D manifolds have no pictures: draw does not offer them
    let p3 = generated(dir.path(), 10, 3, 1);
    let o = in_space(
        "draw",
        &p3,
        "dicosm",
        &["1", "1", "1"],
        &["-o", svg.to_str().unwrap()],
    );
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("[possible values: torus, klein, sphere, projective-plane]"),
        "{}",
        stderr(&o)
    );
}

/// Runs the command with the blank-separated words of `line` (paths without blanks).
fn run_line(line: &str) -> std::process::Output {
    orbitri(&line.split_whitespace().collect::<Vec<_>>())
}

#[test]
fn output_formats_come_from_known_extensions_only() {
    let dir = tempfile::tempdir().unwrap();
    let input = generated(dir.path(), 40, 2, 3);
    let input = input.to_str().unwrap();
    let d = dir.path().to_str().unwrap();
    for (command, name, message) in [
        ("voronoi", "v.txt", "v.txt: cannot tell the output format from the extension .txt: use .csv, .npy, .npz, .json, .vtu or give --format"),
        ("voronoi", "v", "cannot tell the output format from a name without extension"),
        ("triangulate", "t.out", "use .cells, .json, .vtu, .txt or give --format"),
        ("draw", "d.jpg", "d.jpg: draw writes .svg or .png pictures, not .jpg"),
    ] {
        let o = run_line(&format!("{command} {input} --box 1 1 -o {d}/{name}"));
        assert_eq!(o.status.code(), Some(2), "{command} {name}");
        assert!(stderr(&o).contains(message), "{}", stderr(&o));
        assert!(!dir.path().join(name).exists(), "{name} was written");
    }
    // --format names it whatever the extension; .txt is the cells format
    for line in [
        format!("voronoi {input} --box 1 1 -o {d}/v.txt --format csv"),
        format!("triangulate {input} --box 1 1 -o {d}/t.txt"),
        format!("voronoi {input} --box 1 1 -o {d}/v.npz"),
    ] {
        let o = run_line(&line);
        assert!(o.status.success(), "{line}: {}", stderr(&o));
    }
    let cells = std::fs::read_to_string(dir.path().join("t.txt")).unwrap();
    assert!(cells.starts_with("1 40 80\n"), "{cells}");
    // .npz: named arrays in a zip archive
    let z = std::fs::read(dir.path().join("v.npz")).unwrap();
    assert_eq!(&z[..4], b"PK\x03\x04");
    let text = String::from_utf8_lossy(&z);
    for name in "id volume neighbours surface_area centroid duplicate_of".split(' ') {
        assert!(text.contains(&format!("{name}.npy")), "{name}");
    }
}

#[test]
fn cellpar_gives_lengths_and_angles() {
    let dir = tempfile::tempdir().unwrap();
    let input = generated(dir.path(), 300, 3, 4);
    let input = input.to_str().unwrap();
    // a hexagonal prism cell: a = b = 1, c = 2, γ = 120°; the volumes sum to its volume
    let o = run_line(&format!(
        "voronoi {input} --cellpar 1 1 2 90 90 120 --stats"
    ));
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    let domain = err.split("domain_volume=").nth(1).unwrap();
    let domain: f64 = domain.split(' ').next().unwrap().parse().unwrap();
    assert!((domain - 3f64.sqrt()).abs() < 1e-12, "{err}");
    // 2D: A B GAMMA, for draw too
    let input2 = generated(dir.path(), 30, 2, 5);
    let svg = dir.path().join("h.svg");
    let o = run_line(&format!(
        "draw {} --cellpar 1 1 60 -o {}",
        input2.display(),
        svg.display()
    ));
    assert!(o.status.success(), "{}", stderr(&o));
    for (domain, message) in [
        // six numbers after --box are lengths and angles given to the wrong flag
        ("--box 10 10 10 90 90 90", "--box takes the lengths LX LY [LZ], not 6 numbers: for lengths and angles (a b c α β γ) use --cellpar"),
        ("--cellpar 1 1 1 120 120 120", "make no cell"),
        ("--space dicosm --cellpar 1 1 1 90 90 90", "--cellpar is for the torus only: --space dicosm takes --box L1 L2 L3"),
    ] {
        let o = run_line(&format!("voronoi {input} {domain}"));
        assert_eq!(o.status.code(), Some(2), "{domain}");
        assert!(stderr(&o).contains(message), "{}", stderr(&o));
    }
}

#[test]
fn draw_help_is_two_dimensional_and_generate_is_documented() {
    let o = orbitri(&["draw", "--help"]);
    let help = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(
        help.contains("--box <LX> <LY>\n") || help.contains("--box <LX> <LY>|"),
        "{help}"
    );
    assert!(!help.contains("LZ") && !help.contains("AZ"), "{help}");
    assert!(!help.contains("dicosm"), "{help}");
    let o = orbitri(&["generate", "--help"]);
    let help = String::from_utf8_lossy(&o.stdout).into_owned();
    for doc in ["How many points", "Seed of the generator", "Output file"] {
        assert!(help.contains(doc), "{doc}: {help}");
    }
}

/// `--weights` and `--radii`: the hidden column, `hidden=` in the statistics, JSON weights
/// and hidden ids, and a negative radius named by its row.
#[test]
fn weighted_points_on_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("w.txt");
    // point 3 sits next to point 1, whose weight covers it
    std::fs::write(
        &input,
        "0.1 0.1 0.1 0\n0.6 0.2 0.3 0.04\n0.3 0.7 0.5 0\n0.62 0.21 0.3 0\n0.8 0.8 0.9 0\n",
    )
    .unwrap();
    // `orbitri CMD INPUT --box 1 1 1 EXTRA…`
    let run = |cmd: &str, extra: &[&str]| {
        let mut args = vec![cmd, input.to_str().unwrap(), "--box", "1", "1", "1"];
        args.extend_from_slice(extra);
        orbitri(&args)
    };
    let csv = dir.path().join("cells.csv");
    let out = run(
        "voronoi",
        &["--weights", "--stats", "-o", csv.to_str().unwrap()],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("hidden=1"));
    let table = std::fs::read_to_string(&csv).unwrap();
    let header: Vec<&str> = table.lines().next().unwrap().split(',').collect();
    let k = header.iter().position(|c| *c == "hidden").unwrap();
    let hidden: Vec<&str> = table
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(k).unwrap())
        .collect();
    assert_eq!(hidden, ["0", "0", "0", "1", "0"]);
    let vol: f64 = table
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap().parse::<f64>().unwrap())
        .sum();
    assert!((vol - 1.0).abs() < 1e-12);
    let json = dir.path().join("t.json");
    let out = run("triangulate", &["--radii", "-o", json.to_str().unwrap()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&json).unwrap();
    assert!(text.contains("\"weights\":[0.0,0.0016"), "{text}");
    std::fs::write(&input, "0.1 0.1 0.1 0\n0.6 0.2 0.3 -0.5\n").unwrap();
    let out = run("triangulate", &["--radii"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("point 1: radius -0.5"), "{err}");
    // draw: one circle of radius √w per weighted point (and copy), hidden ones dashed
    std::fs::write(
        &input,
        "0.2 0.2 0.1\n0.7 0.3 0.05\n0.72 0.31 0\n0.4 0.8 0.1\n",
    )
    .unwrap();
    let svg = dir.path().join("w.svg");
    let out = orbitri(&[
        "draw",
        input.to_str().unwrap(),
        "--box",
        "1",
        "1",
        "--radii",
        "--copies",
        "1",
        "-o",
        svg.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&svg).unwrap();
    let weights = &text[text.find("<g id=\"weights\"").unwrap()..];
    let weights = &weights[..weights.find("</g>").unwrap()];
    assert_eq!(weights.matches("<circle").count(), 3, "{weights}");
    assert_eq!(weights.matches("stroke-dasharray").count(), 0);
}

/// `orbitri COMMAND INPUT --space sphere EXTRA...`
fn on_sphere(command: &str, input: &Path, extra: &[&str]) -> Output {
    let mut args = vec![command, input.to_str().unwrap(), "--space", "sphere"];
    args.extend_from_slice(extra);
    orbitri(&args)
}

#[test]
fn the_sphere_from_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    // an octahedron with the north pole given twice (lon/lat), and a point off the sphere
    let ll = write(
        dir.path(),
        "ll.csv",
        "lon,lat\n0,0\n90,0\n180,0\n-90,0\n0,90\n45,90\n0,-90\n",
    );
    let o = on_sphere(
        "triangulate",
        &ll,
        &["--lonlat", "--stats", "-o", &path("t.cells")],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("vertices=6 faces=8 dimension=2 covers_sphere=true duplicates=1"));
    let (header, rows) = cells_file(&std::fs::read_to_string(path("t.cells")).unwrap());
    assert_eq!(header, vec![1, 6, 8]);
    // every face is three input ids, the pole as its first occurrence (4), never 5
    assert!(rows.iter().all(|r| r.len() == 3 && !r.contains(&5)));
    // the Voronoi table: areas sum to 4π, the duplicate points to its first occurrence
    let o = on_sphere("voronoi", &ll, &["--lonlat", "-o", &path("v.csv")]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(path("v.csv")).unwrap();
    let rows: Vec<Vec<&str>> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert_eq!(rows.len(), 7);
    let area: f64 = rows
        .iter()
        .filter(|r| r[8].is_empty())
        .map(|r| r[1].parse::<f64>().unwrap())
        .sum();
    assert!((area - 4.0 * std::f64::consts::PI).abs() < 1e-12);
    assert_eq!(rows[5][8], "4");
    // JSON, VTU and a picture
    for (command, name) in [
        ("voronoi", "v.json"),
        ("voronoi", "v.vtu"),
        ("draw", "d.svg"),
    ] {
        let o = on_sphere(command, &ll, &["--lonlat", "-o", &path(name)]);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    assert!(std::fs::read_to_string(path("d.svg"))
        .unwrap()
        .contains("id=\"voronoi\""));
    // points off the sphere: an error, or normalized on request (three points: one plane)
    let off = write(dir.path(), "off.txt", "1 0 0\n0 1 0\n0 0 1.5\n");
    let o = on_sphere("triangulate", &off, &[]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("point 2: its norm is 1.5"),
        "{}",
        stderr(&o)
    );
    let o = on_sphere(
        "triangulate",
        &off,
        &["--normalize", "--stats", "-o", &path("n.cells")],
    );
    assert!(stderr(&o).contains("dimension=1"), "{}", stderr(&o));
    // three points on one plane have no faces, so no Voronoi cells: a typed error
    let o = on_sphere("voronoi", &off, &["--normalize"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("no faces"), "{}", stderr(&o));
    // a hemisphere: ghost faces in the JSON, and cells through their poles
    let hemi = write(dir.path(), "hemi.txt", "1 0 0\n0 1 0\n0 0 1\n0.6 0.8 0\n");
    let o = on_sphere("triangulate", &hemi, &["-o", &path("h.json")]);
    assert!(o.status.success(), "{}", stderr(&o));
    let json = std::fs::read_to_string(path("h.json")).unwrap();
    assert!(json.contains("\"covers_sphere\":false"), "{json}");
    assert!(json.contains("\"ghost_faces\":[["), "{json}");
    let o = on_sphere("voronoi", &hemi, &["-o", &path("h.csv")]);
    assert!(o.status.success(), "{}", stderr(&o));
    let areas: f64 = std::fs::read_to_string(path("h.csv"))
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap().parse::<f64>().unwrap())
        .sum();
    assert!(
        (areas - 4.0 * std::f64::consts::PI).abs() < 1e-12,
        "{areas}"
    );
    // a box given to the sphere, --lonlat given to a torus, a torus without its box
    let o = on_sphere("triangulate", &off, &["--box", "1", "1", "1"]);
    assert!(stderr(&o).contains("has no box"), "{}", stderr(&o));
    let o = triangulate_cube(&off, &["--lonlat"]);
    assert!(stderr(&o).contains("for --space sphere"), "{}", stderr(&o));
    let o = orbitri(&["triangulate", off.to_str().unwrap()]);
    assert!(stderr(&o).contains("needs its domain"), "{}", stderr(&o));
}

#[test]
fn the_projective_plane_from_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    // an octahedron given with both poles and all four equator points: three points of RP²
    let pts = write(
        dir.path(),
        "oct.txt",
        "1 0 0\n-1 0 0\n0 1 0\n0 -1 0\n0 0 1\n0 0 -1\n",
    );
    let rp = |command: &str, extra: &[&str]| {
        let mut args = vec![
            command,
            pts.to_str().unwrap(),
            "--space",
            "projective-plane",
        ];
        args.extend_from_slice(extra);
        orbitri(&args)
    };
    let o = rp("triangulate", &["--stats", "-o", &path("t.cells")]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("vertices=3 faces=4 dimension=2 covers_sphere=true duplicates=3"));
    let (header, rows) = cells_file(&std::fs::read_to_string(path("t.cells")).unwrap());
    assert_eq!(header, vec![1, 3, 4]);
    // ids of the first occurrences and one sign per vertex, at most one antipode per face
    for r in &rows {
        assert_eq!(r.len(), 6);
        assert!(r[..3].iter().all(|&i| [0, 2, 4].contains(&i)));
        assert!(r[3..].iter().all(|&s| s == 1 || s == -1));
        assert!(r[3..].iter().filter(|&&s| s == -1).count() <= 1);
    }
    let o = rp("voronoi", &["--stats", "-o", &path("v.csv")]);
    assert!(o.status.success(), "{}", stderr(&o));
    let line = stderr(&o);
    let sum: f64 = line
        .split_whitespace()
        .find_map(|kv| kv.strip_prefix("area_sum="))
        .unwrap()
        .parse()
        .unwrap();
    assert!((sum - 2.0 * std::f64::consts::PI).abs() < 1e-12, "{line}");
    let o = rp("draw", &["-o", &path("d.svg")]);
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn every_thread_count_writes_the_same_files() {
    let dir = tempfile::tempdir().unwrap();
    let cube = write(dir.path(), "cube.txt", &random_text(6000));
    // directions in a cube's corner, projected onto the sphere (`--normalize`)
    let sphere = write(
        dir.path(),
        "sphere.txt",
        &random_text(6000).replace(", ", " "),
    );
    let run = |threads: &str| -> Vec<Vec<u8>> {
        let runs: [(&str, &Path, &[&str], &str); 4] = [
            ("triangulate", &cube, &["--box", "1", "1", "1"], "cells"),
            ("voronoi", &cube, &["--box", "1", "1", "1"], "csv"),
            (
                "triangulate",
                &sphere,
                &["--space", "sphere", "--normalize"],
                "json",
            ),
            (
                "voronoi",
                &sphere,
                &["--space", "sphere", "--normalize"],
                "csv",
            ),
        ];
        runs.iter()
            .enumerate()
            .map(|(k, (command, input, extra, format))| {
                let o = dir.path().join(format!("{k}.{threads}.{format}"));
                let mut args = vec![*command, input.to_str().unwrap()];
                args.extend_from_slice(extra);
                args.extend_from_slice(&["--threads", threads, "-o", o.to_str().unwrap()]);
                let r = orbitri(&args);
                assert!(r.status.success(), "{args:?}: {}", stderr(&r));
                std::fs::read(o).unwrap()
            })
            .collect()
    };
    let one = run("1");
    assert!(one.iter().all(|f| f.len() > 1000));
    for threads in ["2", "3"] {
        assert!(run(threads) == one, "--threads {threads} wrote other files");
    }
    for bad in ["0", "5000"] {
        let o = triangulate_cube(&cube, &["--threads", bad]);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert!(stderr(&o).contains("--threads"), "{}", stderr(&o));
    }
}
