//! Fuzzing the readers with proptest, on fixed seeds so that CI runs the same cases every
//! time: random bytes, text-like noise, and valid text and `.npy` files with random rows,
//! mutated (commas, byte-order marks, NUL and other control bytes, huge numbers, cut
//! anywhere). Whatever the input, a reader must not panic, and either return points where
//! every row held exactly `D` finite numbers, or a parse error that names the file.
//!
//! `ORBITRI_FUZZ_CASES` sets the number of cases of each property (default: a CI run of
//! about a second) and `ORBITRI_FUZZ_SEED` the seed, for long runs:
//! `ORBITRI_FUZZ_CASES=200000 cargo test -p orbitri --test readers`. The `cargo fuzz`
//! targets in `fuzz/` feed the same readers coverage-guided input.

use std::path::Path;

use orbitri::io::{encode_npy, parse_npy, parse_text};
use orbitri::Error;
use proptest::prelude::*;
use proptest::test_runner::{RngSeed, TestCaseError};

fn env(name: &str) -> Option<u64> {
    std::env::var(name).ok().and_then(|v| v.parse().ok())
}

fn config(default_cases: u32, seed: u64) -> ProptestConfig {
    ProptestConfig {
        cases: env("ORBITRI_FUZZ_CASES").map_or(default_cases, |n| n as u32),
        rng_seed: RngSeed::Fixed(env("ORBITRI_FUZZ_SEED").unwrap_or(seed)),
        ..ProptestConfig::default()
    }
}

const TXT: &str = "fuzz.txt";
const NPY: &str = "fuzz.npy";

/// The header of `body`, if the line is one (no field a number, none empty but the first):
/// its number of fields and the fields of the `d` coordinates, `None` inside for a header
/// the reader must reject.
fn header(body: &str, d: usize) -> Option<Option<(usize, Vec<usize>)>> {
    let fields: Vec<&str> = if body.contains(',') {
        body.split(',').map(str::trim).collect()
    } else {
        body.split_whitespace().collect()
    };
    let numbers = fields.iter().any(|f| f.parse::<f64>().is_ok());
    if numbers || fields[1..].iter().any(|f| f.is_empty()) {
        return None;
    }
    let n = fields.len();
    let named: Option<Vec<usize>> = ["x", "y", "z"][..d]
        .iter()
        .map(|a| fields.iter().position(|f| f.eq_ignore_ascii_case(a)))
        .collect();
    Some(match named {
        Some(at) => Some((n, at)),
        None if n == d + 1 && fields[0].is_empty() => Some((n, (1..=d).collect())),
        None if n == d => Some((n, (0..d).collect())),
        None => None,
    })
}

/// What the text format says, read independently of the reader: the rows of numbers of the
/// data lines (not blank, not comment), `None` for a line the reader must reject. The first
/// line with values may be a header (skipped, see [`header`]); after one, a row has its
/// number of fields and the named ones are the coordinates.
fn text_rows(bytes: &[u8], d: usize) -> Vec<Option<Vec<f64>>> {
    let mut rows = Vec::new();
    let mut columns: Option<(usize, Vec<usize>)> = None;
    let mut first = true;
    for (k, line) in bytes.split(|&b| b == b'\n').enumerate() {
        let Ok(mut line) = std::str::from_utf8(line) else {
            rows.push(None);
            continue;
        };
        if k == 0 {
            line = line.strip_prefix('\u{feff}').unwrap_or(line);
        }
        if line
            .chars()
            .any(|c| (c.is_control() && c != '\t' && c != '\r') || c == '\u{feff}')
        {
            rows.push(None);
            continue;
        }
        let body = line.split('#').next().unwrap();
        if first && !body.trim().is_empty() {
            first = false;
            match header(body, d) {
                Some(Some(h)) => {
                    columns = Some(h);
                    continue;
                }
                Some(None) => {
                    rows.push(None);
                    continue;
                }
                None => {}
            }
        }
        if body.contains(',') && body.split(',').any(|f| f.trim().is_empty()) {
            rows.push(None);
            continue;
        }
        let values: Vec<&str> = body
            .split(|c: char| c == ',' || c.is_whitespace())
            .filter(|s| !s.is_empty())
            .collect();
        if values.is_empty() {
            continue;
        }
        rows.push(match &columns {
            None => {
                let numbers: Vec<f64> = values.iter().filter_map(|v| v.parse().ok()).collect();
                (numbers.len() == values.len()).then_some(numbers)
            }
            Some((n, at)) if values.len() == *n => {
                at.iter().map(|&c| values[c].parse().ok()).collect()
            }
            Some(_) => None,
        });
    }
    rows
}

/// A parse error must name the file, and quote at most a short piece of the input.
fn check_error(e: &Error, name: &str, lines: usize) -> Result<(), TestCaseError> {
    match e {
        Error::Parse {
            file,
            line,
            message,
        } => {
            prop_assert_eq!(file, Path::new(name));
            prop_assert!(
                (1..=lines.max(1)).contains(line),
                "line {} of {}",
                line,
                lines
            );
            let prefix = format!("{name}:{line}: ");
            prop_assert!(e.to_string().starts_with(&prefix));
            prop_assert!(!message.is_empty());
            // 80 characters quoted, each escaped in at most 10
            prop_assert!(message.len() < 1000, "{} bytes: {}", message.len(), message);
        }
        Error::Io { file, .. } => prop_assert_eq!(file, Path::new(name)),
        other => prop_assert!(false, "{:?} does not name the file", other),
    }
    Ok(())
}

/// The text reader's contract on any bytes, for points of dimension `D`.
fn check_text<const D: usize>(bytes: &[u8]) -> Result<(), TestCaseError> {
    let lines = bytes.split(|&b| b == b'\n').count();
    match parse_text::<D>(bytes, Path::new(TXT)) {
        Ok(points) => {
            let rows = text_rows(bytes, D);
            prop_assert_eq!(rows.len(), points.len());
            for (row, p) in rows.iter().zip(&points) {
                let row = row.as_ref().expect("a line the reader must reject");
                prop_assert_eq!(row.len(), D);
                for (a, b) in row.iter().zip(p) {
                    prop_assert!(b.is_finite());
                    prop_assert_eq!(a.to_bits(), b.to_bits());
                }
            }
        }
        Err(e) => check_error(&e, TXT, lines)?,
    }
    Ok(())
}

/// The `.npy` reader's contract on any bytes: finite points, or an error naming the file.
fn check_npy<const D: usize>(bytes: &[u8]) -> Result<Option<Vec<[f64; D]>>, TestCaseError> {
    match parse_npy::<D>(bytes, Path::new(NPY)) {
        Ok(points) => {
            prop_assert!(!points.is_empty());
            prop_assert!(points.as_flattened().iter().all(|x| x.is_finite()));
            Ok(Some(points))
        }
        Err(e) => {
            check_error(&e, NPY, 1)?;
            Ok(None)
        }
    }
}

/// Any finite double, and often a short decimal one.
fn finite() -> impl Strategy<Value = f64> {
    prop_oneof![
        any::<f64>().prop_filter("finite", |x| x.is_finite()),
        (-1000i32..1000).prop_map(|k| f64::from(k) / 64.0),
        prop::num::f64::NORMAL | prop::num::f64::SUBNORMAL | prop::num::f64::ZERO,
    ]
}

/// How a number is written: each form reads back to the same double.
fn write_number(x: f64, form: u8) -> String {
    match form % 4 {
        0 => format!("{x:?}"),
        1 => format!("{x:e}"),
        2 => format!("{x:E}"),
        _ => format!("{x}"),
    }
}

/// A valid text file of `rows`, written with the given separators, number forms, comments
/// and line ends; also returns the byte range of each row's line (without its line end).
fn text_file<const D: usize>(
    rows: &[[f64; D]],
    style: &[(u8, u8, bool)],
    bom: bool,
    crlf: bool,
) -> (String, Vec<std::ops::Range<usize>>) {
    const SEPARATORS: [&str; 6] = [" ", ",", ", ", "\t", " , ", "  "];
    let mut s = String::new();
    if bom {
        s.push('\u{feff}');
    }
    let mut lines = Vec::new();
    for (k, row) in rows.iter().enumerate() {
        let (sep, form, comment) = style[k % style.len()];
        if comment {
            s.push_str("# a comment, with commas\n\n");
        }
        let start = s.len();
        let numbers: Vec<String> = row.iter().map(|&x| write_number(x, form)).collect();
        s.push_str(&numbers.join(SEPARATORS[sep as usize % SEPARATORS.len()]));
        lines.push(start..s.len());
        s.push_str(if crlf { "\r\n" } else { "\n" });
    }
    (s, lines)
}

/// Insertions that break or bend a text file.
const INSERTS: [&[u8]; 18] = [
    b",",
    b",,",
    b" ",
    b"\xef\xbb\xbf",
    b"\0",
    b"\x07",
    b"\xc2\x85",
    b"\xff",
    b"#",
    b"\n",
    b"\r",
    b"-",
    b".",
    b"e",
    b"1e999",
    b"nan",
    b"-inf",
    b"123456789012345678901234567890123456789012345678901234567890",
];

#[derive(Clone, Debug)]
enum Mutation {
    Insert(usize, u8),
    InsertByte(usize, u8),
    Delete(usize),
    Truncate(usize),
    HugeNumber(usize, usize),
    Repeat(usize, usize),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let at = any::<usize>();
    prop_oneof![
        3 => (at, 0..INSERTS.len() as u8).prop_map(|(a, k)| Mutation::Insert(a, k)),
        1 => (at, any::<u8>()).prop_map(|(a, b)| Mutation::InsertByte(a, b)),
        1 => at.prop_map(Mutation::Delete),
        1 => at.prop_map(Mutation::Truncate),
        1 => (at, 300usize..2000).prop_map(|(a, n)| Mutation::HugeNumber(a, n)),
        1 => (at, 1usize..50).prop_map(|(a, n)| Mutation::Repeat(a, n)),
    ]
}

fn mutate(bytes: &mut Vec<u8>, m: &Mutation) {
    let at = |a: usize| a % (bytes.len() + 1);
    match *m {
        Mutation::Insert(a, k) => {
            let a = at(a);
            bytes.splice(a..a, INSERTS[k as usize].iter().copied());
        }
        Mutation::InsertByte(a, b) => {
            let a = at(a);
            bytes.insert(a, b);
        }
        Mutation::Delete(a) if !bytes.is_empty() => {
            bytes.remove(a % bytes.len());
        }
        Mutation::Delete(_) => {}
        Mutation::Truncate(a) => {
            let a = at(a);
            bytes.truncate(a);
        }
        Mutation::HugeNumber(a, n) => {
            // hundreds of digits: finite, or beyond f64 when an exponent follows
            let a = at(a);
            let digits: Vec<u8> = (0..n).map(|k| b"0123456789"[k % 10]).collect();
            bytes.splice(a..a, digits);
        }
        Mutation::Repeat(a, n) => {
            // a run of the same piece: long lines, many fields
            let a = at(a);
            let piece = bytes[a..bytes.len().min(a + 8)].to_vec();
            let run: Vec<u8> = piece
                .iter()
                .copied()
                .cycle()
                .take(piece.len() * n)
                .collect();
            bytes.splice(a..a, run);
        }
    }
}

fn text_like() -> impl Strategy<Value = Vec<u8>> {
    // numbers and separators mostly, so that some lines hold D numbers
    const PIECES: [&str; 24] = [
        "0", "0.25", "-1.5", "7e-3", "-2e-301", "1e308", ".5", "5.", "1e999", "nan", "-inf", " ",
        " ", ", ", ",", "\t", "\n", "\n", "\r\n", "# c\n", "\u{feff}", "\0", "x", "-",
    ];
    prop::collection::vec(prop::sample::select(PIECES.as_slice()), 0..80)
        .prop_map(|pieces| pieces.concat().into_bytes())
}

fn npy_like() -> impl Strategy<Value = Vec<u8>> {
    // past the magic most of the time, to reach the header parser
    (
        any::<bool>(),
        0u8..4,
        prop::collection::vec(any::<u8>(), 0..200),
        prop::collection::vec(
            prop::sample::select(b"{}'(), :0123456789<>f8descrshapeTrueFals".as_slice()),
            0..120,
        ),
    )
        .prop_map(|(magic, version, tail, header)| {
            let mut b = Vec::new();
            if magic {
                b.extend_from_slice(b"\x93NUMPY");
                b.push(version);
                b.push(0);
                b.extend_from_slice(&(header.len() as u16).to_le_bytes());
                b.extend_from_slice(&header);
            }
            b.extend_from_slice(&tail);
            b
        })
}

/// A `.npy` whose header declares `n` rows (whatever `rows` holds), of 3 columns.
fn npy_declaring(rows: &[[f64; 3]], n: u64) -> Vec<u8> {
    let header = format!("{{'descr': '<f8', 'fortran_order': False, 'shape': ({n}, 3), }}\n");
    let mut b = b"\x93NUMPY\x01\x00".to_vec();
    b.extend_from_slice(&(header.len() as u16).to_le_bytes());
    b.extend_from_slice(header.as_bytes());
    for x in rows.as_flattened() {
        b.extend_from_slice(&x.to_le_bytes());
    }
    b
}

/// A valid `.npy` of `rows`, little- or big-endian.
fn npy_file<const D: usize>(rows: &[[f64; D]], big: bool) -> Vec<u8> {
    let mut b = encode_npy(rows);
    if big {
        let data = b.len() - rows.len() * D * 8;
        let at = b.windows(5).position(|w| w == b"'<f8'").unwrap();
        b[at + 1] = b'>';
        for x in b[data..].chunks_mut(8) {
            x.reverse();
        }
    }
    b
}

proptest! {
    #![proptest_config(config(2000, 20261201))]

    #[test]
    fn random_bytes(bytes in prop::collection::vec(any::<u8>(), 0..600)) {
        check_text::<2>(&bytes)?;
        check_text::<3>(&bytes)?;
        check_npy::<2>(&bytes)?;
        check_npy::<3>(&bytes)?;
    }

    #[test]
    fn text_like_noise(bytes in text_like()) {
        check_text::<2>(&bytes)?;
        check_text::<3>(&bytes)?;
    }

    #[test]
    fn npy_like_noise(bytes in npy_like()) {
        check_npy::<2>(&bytes)?;
        check_npy::<3>(&bytes)?;
    }
}

proptest! {
    #![proptest_config(config(1000, 20261202))]

    /// Valid files read back exactly, in every style; mutated, they keep the contract.
    #[test]
    fn mutated_text_files(
        rows in prop::collection::vec(prop::array::uniform3(finite()), 1..12),
        style in prop::collection::vec((0u8..6, 0u8..4, prop::bool::weighted(0.2)), 1..4),
        bom in any::<bool>(),
        crlf in any::<bool>(),
        mutations in prop::collection::vec(mutation(), 1..5),
    ) {
        let (text, _) = text_file(&rows, &style, bom, crlf);
        prop_assert_eq!(&parse_text::<3>(&text, Path::new(TXT)).unwrap(), &rows);
        check_text::<3>(text.as_bytes())?;
        let mut bytes = text.into_bytes();
        for m in &mutations {
            mutate(&mut bytes, m);
            check_text::<2>(&bytes)?;
            check_text::<3>(&bytes)?;
        }
    }

    /// An empty field anywhere is an error naming its line and field, never a dropped
    /// coordinate (in 2D too, where the row's other numbers would make a point).
    #[test]
    fn an_empty_field_is_named(
        rows in prop::collection::vec(prop::array::uniform3(finite()), 1..10),
        form in 0u8..4,
        row in any::<prop::sample::Index>(),
        field in 0usize..4,
        blank in prop::sample::select(vec!["", " ", "\t", "  "]),
    ) {
        let (text, lines) = text_file(&rows, &[(1, form, false)], false, false);
        let r = row.index(rows.len());
        let line = &text[lines[r].clone()];
        let mut fields: Vec<&str> = line.split(',').collect();
        fields.insert(field, blank);
        let broken = format!("{}{}{}", &text[..lines[r].start], fields.join(","), &text[lines[r].end..]);
        let want = format!("{TXT}:{}: field {} is empty", r + 1, field + 1);
        for e in [
            parse_text::<3>(&broken, Path::new(TXT)).unwrap_err(),
            parse_text::<2>(&broken, Path::new(TXT)).unwrap_err(),
        ] {
            // in 2D an earlier row of 3 numbers is the first error
            if r == 0 || e.to_string().contains("is empty") {
                prop_assert!(e.to_string().starts_with(&want), "{} instead of {}", e, want);
            }
        }
    }

    /// A control byte in a data line is named with its line and column; a byte-order mark
    /// at the start is skipped.
    #[test]
    fn a_control_byte_is_named(
        rows in prop::collection::vec(prop::array::uniform3(finite()), 1..10),
        style in (0u8..6, 0u8..4),
        bom in any::<bool>(),
        row in any::<prop::sample::Index>(),
        at in any::<prop::sample::Index>(),
        byte in prop::sample::select(vec![0u8, 1, 7, 8, 11, 12, 27, 31, 127]),
    ) {
        let (text, lines) = text_file(&rows, &[(style.0, style.1, false)], bom, false);
        let r = row.index(rows.len());
        let column = at.index(lines[r].len() + 1);
        let mut bytes = text.into_bytes();
        bytes.insert(lines[r].start + column, byte);
        let e = parse_text::<3>(&bytes, Path::new(TXT)).unwrap_err().to_string();
        let want = format!("{TXT}:{}: control character U+{byte:04X} at column {}", r + 1, column + 1);
        prop_assert_eq!(e, want);
    }

    /// `.npy` files read back exactly (either byte order); cut anywhere, they are an error
    /// naming the file; with changed bytes, they keep the contract.
    #[test]
    fn mutated_npy_files(
        rows in prop::collection::vec(prop::array::uniform3(finite()), 0..12),
        big in any::<bool>(),
        cut in any::<prop::sample::Index>(),
        changes in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..6),
    ) {
        let b = npy_file(&rows, big);
        match rows.len() {
            0 => prop_assert!(check_npy::<3>(&b)?.is_none()),
            _ => prop_assert_eq!(check_npy::<3>(&b)?, Some(rows.clone())),
        }
        prop_assert!(check_npy::<2>(&b)?.is_none());
        let cut = cut.index(b.len());
        prop_assert!(check_npy::<3>(&b[..cut])?.is_none(), "cut at {}", cut);
        let mut changed = b.clone();
        for (at, byte) in &changes {
            let at = at.index(changed.len());
            changed[at] = *byte;
            check_npy::<3>(&changed)?;
            check_npy::<2>(&changed)?;
        }
    }

    /// A header may declare any number of rows: more than the data holds is truncated data
    /// (a huge count must not overflow the byte count), fewer reads that many.
    #[test]
    fn npy_shapes_of_any_size(
        rows in prop::collection::vec(prop::array::uniform3(finite()), 0..6),
        n in prop_oneof![0u64..8, any::<u64>(), Just(u64::MAX), Just(u64::MAX / 24 + 1)],
    ) {
        let b = npy_declaring(&rows, n);
        let read = check_npy::<3>(&b)?;
        if n == 0 || n > rows.len() as u64 {
            prop_assert!(read.is_none());
            let e = parse_npy::<3>(&b, Path::new(NPY)).unwrap_err().to_string();
            let want = if n == 0 { "the file holds no points" } else { "truncated data" };
            prop_assert!(e.contains(want), "{}", e);
        } else {
            prop_assert_eq!(read, Some(rows[..n as usize].to_vec()));
        }
    }
}
