//! Text points: one point per line, coordinates separated by blanks or commas, `#` starts a
//! comment, blank lines are skipped. A UTF-8 byte-order mark at the start of the file is
//! skipped; an empty field between commas and a control character (other than tab, CR and
//! LF) are errors.
//!
//! The first line with values may be a header, a line none of whose fields is a number (as
//! pandas' `to_csv` writes): it is skipped. If it names columns `x`, `y` (and `z`), those
//! are read, in that order, from rows of as many fields as the header has (the other fields
//! may hold anything but an empty field or a comma); if its first
//! field is empty (pandas' unnamed index) and it has `D + 1` fields, the first column is
//! left out; otherwise it must have `D` fields.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};

/// The most characters of a line or value that an error message quotes.
const QUOTE_CHARS: usize = 80;

/// `s`, cut after [`QUOTE_CHARS`] characters (marked with `…`), for an error message.
fn clip(s: &str) -> String {
    match s.char_indices().nth(QUOTE_CHARS) {
        Some((end, _)) => format!("{}…", &s[..end]),
        None => s.to_string(),
    }
}

/// Reads a text point file, streaming it line by line.
pub fn read_text<const D: usize>(path: &Path) -> Result<Vec<[f64; D]>> {
    let file = std::fs::File::open(path).map_err(|source| Error::Io {
        file: path.to_path_buf(),
        source,
    })?;
    parse_lines(BufReader::new(file), path)
}

/// Parses text points from a string or raw bytes (which must be UTF-8); `file` is only used
/// in error messages.
pub fn parse_text<const D: usize>(text: impl AsRef<[u8]>, file: &Path) -> Result<Vec<[f64; D]>> {
    parse_lines(text.as_ref(), file)
}

fn parse_lines<const D: usize>(mut input: impl BufRead, file: &Path) -> Result<Vec<[f64; D]>> {
    let err = |line: usize, message: String| Error::Parse {
        file: PathBuf::from(file),
        line,
        message,
    };
    let mut out = Vec::new();
    let mut buf = Vec::new();
    let mut line = 0;
    // after a header: the header's number of fields, and the field read as each coordinate
    let mut columns: Option<(usize, [usize; D])> = None;
    let mut first_values = true;
    loop {
        buf.clear();
        let n = input
            .read_until(b'\n', &mut buf)
            .map_err(|source| Error::Io {
                file: PathBuf::from(file),
                source,
            })?;
        if n == 0 {
            break;
        }
        line += 1;
        let raw = std::str::from_utf8(&buf).map_err(|e| {
            let ok = &buf[..e.valid_up_to()];
            let column = std::str::from_utf8(ok).map_or(0, |s| s.chars().count()) + 1;
            err(
                line,
                format!(
                    "not UTF-8 text (byte 0x{:02X} at column {column}; for binary input use a .npy file)",
                    buf[ok.len()]
                ),
            )
        })?;
        let raw = match line {
            1 => raw.strip_prefix('\u{feff}').unwrap_or(raw),
            _ => raw,
        };
        // a fast test first: most lines are printable ASCII with tabs and line ends
        let plain = |b: &u8| (0x20..0x7f).contains(b) || matches!(b, b'\t' | b'\r' | b'\n');
        if !raw.as_bytes().iter().all(plain) {
            for (k, c) in raw.chars().enumerate() {
                let column = k + 1;
                if c.is_control() && !matches!(c, '\t' | '\r' | '\n') {
                    let code = c as u32;
                    return Err(err(
                        line,
                        format!("control character U+{code:04X} at column {column}"),
                    ));
                }
                if c == '\u{feff}' {
                    return Err(err(
                        line,
                        format!(
                            "byte-order mark U+FEFF at column {column} (allowed only at the start of the file)"
                        ),
                    ));
                }
            }
        }
        let body = raw.split('#').next().unwrap_or("");
        let commas = body.contains(',');
        if first_values && !body.trim().is_empty() {
            first_values = false;
            if let Some(header) = header_columns::<D>(body).map_err(|m| err(line, m))? {
                columns = Some(header);
                continue;
            }
        }
        let mut p = [0.0; D];
        let mut count = 0;
        for (field, text) in body.split(',').enumerate() {
            let mut values = text.split(char::is_whitespace).filter(|s| !s.is_empty());
            let first = values.next();
            if first.is_none() && commas {
                return Err(err(
                    line,
                    format!("field {} is empty ({:?})", field + 1, clip(body.trim())),
                ));
            }
            for f in first.into_iter().chain(values) {
                let axis = match &columns {
                    None => (count < D).then_some(count),
                    Some((_, at)) => at.iter().position(|&c| c == count),
                };
                if let Some(axis) = axis {
                    let v: f64 = f.parse().map_err(|_| {
                        err(
                            line,
                            format!("coordinate {axis} '{}' is not a number", clip(f)),
                        )
                    })?;
                    if !v.is_finite() {
                        return Err(err(
                            line,
                            format!("coordinate {axis} is {v}, not a finite number"),
                        ));
                    }
                    p[axis] = v;
                }
                count += 1;
            }
        }
        if count == 0 {
            continue;
        }
        let fields = columns.map_or(D, |(n, _)| n);
        if count != fields {
            let what = match columns {
                None => "coordinates",
                Some(_) => "fields (as the header has)",
            };
            return Err(err(
                line,
                format!(
                    "expected {fields} {what}, found {count} ({:?})",
                    clip(body.trim())
                ),
            ));
        }
        out.push(p);
    }
    if out.is_empty() {
        return Err(err(line.max(1), "the file holds no points".into()));
    }
    Ok(out)
}

/// If `body` is a header (no field is a number), the number of its fields and the field of
/// each coordinate; an error if it is a header this reader cannot use.
fn header_columns<const D: usize>(
    body: &str,
) -> std::result::Result<Option<(usize, [usize; D])>, String> {
    let fields: Vec<&str> = if body.contains(',') {
        body.split(',').map(str::trim).collect()
    } else {
        body.split_whitespace().collect()
    };
    // names: none a number, only the first (pandas' index) may be empty
    if fields.iter().any(|f| f.parse::<f64>().is_ok()) || fields[1..].iter().any(|f| f.is_empty()) {
        return Ok(None);
    }
    let n = fields.len();
    let named: Option<Vec<usize>> = ["x", "y", "z"][..D]
        .iter()
        .map(|a| fields.iter().position(|f| f.eq_ignore_ascii_case(a)))
        .collect();
    let at: Vec<usize> = match named {
        Some(at) => at,
        None if n == D + 1 && fields[0].is_empty() => (1..=D).collect(),
        None if n == D => (0..D).collect(),
        None => {
            return Err(format!(
                "a header of {n} columns ({:?}) that names no columns x, y{}: expected {D} columns, or one more with an empty first name (pandas' index)",
                clip(body.trim()),
                if D == 3 { ", z" } else { "" }
            ))
        }
    };
    Ok(Some((n, std::array::from_fn(|k| at[k]))))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(s: &str) -> Result<Vec<[f64; 3]>> {
        parse_text(s, Path::new("in.txt"))
    }

    #[test]
    fn comments_commas_blanks() {
        let p = parse("# header\n0.1 0.2 0.3\n\n0.4,0.5, 0.6  # trailing\n1e-3\t2 3\n").unwrap();
        assert_eq!(p, vec![[0.1, 0.2, 0.3], [0.4, 0.5, 0.6], [1e-3, 2.0, 3.0]]);
    }

    #[test]
    fn errors_name_file_line_and_value() {
        let e = parse("0 0 0\n0.1 nan 0.3\n").unwrap_err().to_string();
        assert_eq!(e, "in.txt:2: coordinate 1 is NaN, not a finite number");
        let e = parse("0 0 0\n1 2\n").unwrap_err().to_string();
        assert!(
            e.starts_with("in.txt:2: expected 3 coordinates, found 2"),
            "{e}"
        );
        let e = parse("0 0 x1\n").unwrap_err().to_string();
        assert_eq!(e, "in.txt:1: coordinate 2 'x1' is not a number");
        let e = parse("1 2 inf\n").unwrap_err().to_string();
        assert_eq!(e, "in.txt:1: coordinate 2 is inf, not a finite number");
        let e = parse_lines::<3>(&b"0 0 0\n\xff\n"[..], Path::new("in.txt"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("in.txt:2: not UTF-8"), "{e}");
        let e = parse("# only a comment\n").unwrap_err().to_string();
        assert_eq!(e, "in.txt:1: the file holds no points");
    }

    fn error(s: &str) -> String {
        parse(s).unwrap_err().to_string()
    }

    #[test]
    fn an_empty_field_is_an_error() {
        // it used to be dropped, turning a 3D row into a 2D one
        assert_eq!(
            error("0 0 0\n\n0.1,,0.3\n"),
            "in.txt:3: field 2 is empty (\"0.1,,0.3\")"
        );
        assert!(error("0.1,0.2,0.3,\n").starts_with("in.txt:1: field 4 is empty"));
        assert!(error(",0.1,0.2,0.3\n").starts_with("in.txt:1: field 1 is empty"));
        assert!(error("0.1, ,0.3\n").starts_with("in.txt:1: field 2 is empty"));
        assert!(error("0.1,0.2,0.3, # a comment\n").starts_with("in.txt:1: field 4 is empty"));
        // a 2D row with a missing value is not taken for a complete 2D point
        let e = parse_text::<2>("0.1,0.2,\n", Path::new("in.txt"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("in.txt:1: field 3 is empty"), "{e}");
        // blanks around commas, blanks only, and commas mixed with blanks stay fine
        let p = parse("0.1 , 0.2 ,\t0.3\n0.4 0.5 0.6\n0.7, 0.8 0.9\n").unwrap();
        assert_eq!(p, vec![[0.1, 0.2, 0.3], [0.4, 0.5, 0.6], [0.7, 0.8, 0.9]]);
    }

    #[test]
    fn a_header_line_is_skipped() {
        // pandas' to_csv(index=False), and blank-separated names
        let p = parse("x,y,z\n0.1,0.2,0.3\n0.4,0.5,0.6\n").unwrap();
        assert_eq!(p, vec![[0.1, 0.2, 0.3], [0.4, 0.5, 0.6]]);
        assert_eq!(
            parse("# c\n\na b c\n0.1 0.2 0.3\n").unwrap(),
            vec![[0.1, 0.2, 0.3]]
        );
        // pandas' to_csv() with its unnamed index: the first column is left out
        let p = parse(",x,y,z\n0,0.1,0.2,0.3\n1,0.4,0.5,0.6\n").unwrap();
        assert_eq!(p, vec![[0.1, 0.2, 0.3], [0.4, 0.5, 0.6]]);
        // named columns anywhere, in any order
        let p = parse("id,z,type,x,y\n7,0.3,1,0.1,0.2\n").unwrap();
        assert_eq!(p, vec![[0.1, 0.2, 0.3]]);
        // the other columns may hold names (an element), not only numbers
        let p = parse("id,type,x,y,z\n1,Cu,0.1,0.2,0.3\n").unwrap();
        assert_eq!(p, vec![[0.1, 0.2, 0.3]]);
        // empty names are no header (but pandas' unnamed index)
        assert!(error(",,\n0.1,0.2,0.3\n").starts_with("in.txt:1: field 1 is empty"));
        let p = parse_text::<2>("X Y\n0.1 0.2\n", Path::new("in.txt")).unwrap();
        assert_eq!(p, vec![[0.1, 0.2]]);
        // rows must have the header's fields; only the first line may be a header
        assert!(error("id,x,y,z\n0.1,0.2,0.3\n")
            .starts_with("in.txt:2: expected 4 fields (as the header has), found 3"));
        assert_eq!(
            error("0.1,0.2,0.3\nx,y,z\n"),
            "in.txt:2: coordinate 0 'x' is not a number"
        );
        let e = error("a,b\n0.1,0.2,0.3\n");
        assert!(
            e.starts_with(
                "in.txt:1: a header of 2 columns (\"a,b\") that names no columns x, y, z"
            ),
            "{e}"
        );
    }

    #[test]
    fn a_byte_order_mark_at_the_start_is_skipped() {
        let p = parse("\u{feff}0.1 0.2 0.3\n0.4 0.5 0.6\n").unwrap();
        assert_eq!(p, vec![[0.1, 0.2, 0.3], [0.4, 0.5, 0.6]]);
        let p = parse("\u{feff}# x y z\n0.1,0.2,0.3\n").unwrap();
        assert_eq!(p, vec![[0.1, 0.2, 0.3]]);
        // anywhere else (two files concatenated) it is named
        assert_eq!(
            error("0.1 0.2 0.3\n\u{feff}0.4 0.5 0.6\n"),
            "in.txt:2: byte-order mark U+FEFF at column 1 (allowed only at the start of the file)"
        );
    }

    #[test]
    fn control_characters_are_named() {
        assert_eq!(
            error("0 0 0\n0.1 0\u{0}2 0.3\n"),
            "in.txt:2: control character U+0000 at column 6"
        );
        assert_eq!(
            error("0.1\u{b}0.2 0.3\n"),
            "in.txt:1: control character U+000B at column 4"
        );
        // the column counts characters, not bytes; C1 controls and DEL too
        assert_eq!(
            error("# é\n0.1 0.2 0.3 \u{85}\n"),
            "in.txt:2: control character U+0085 at column 13"
        );
        assert_eq!(
            error("0.1 0.2 0.3\u{7f}\n"),
            "in.txt:1: control character U+007F at column 12"
        );
        // tabs and CRLF line ends are fine
        assert_eq!(parse("0.1\t0.2\t0.3\r\n").unwrap(), vec![[0.1, 0.2, 0.3]]);
        let e = parse_lines::<3>(&b"0.1 \xc3\xa9\xff 0.3\n"[..], Path::new("in.txt"))
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("in.txt:1: not UTF-8 text (byte 0xFF at column 6;"),
            "{e}"
        );
    }

    #[test]
    fn long_lines_are_quoted_shortly() {
        let row = "0.125 ".repeat(10_000);
        let e = error(&row);
        assert!(
            e.starts_with("in.txt:1: expected 3 coordinates, found 10000"),
            "{e}"
        );
        assert!(e.ends_with("…\")"), "{e}");
        assert!(e.chars().count() < 160, "{e}");
        let e = error(&format!("0.5 0.5 {}\n", "x".repeat(100_000)));
        assert!(e.starts_with("in.txt:1: coordinate 2 'xxx"), "{e}");
        assert!(e.ends_with("…' is not a number"), "{e}");
        assert!(e.chars().count() < 160, "{e}");
        let e = error(&format!("{},,1\n", "1 ".repeat(1000)));
        assert!(
            e.contains("field 2 is empty") && e.chars().count() < 160,
            "{e}"
        );
        // a short line is quoted whole
        assert_eq!(clip("0.1 0.2"), "0.1 0.2");
        assert_eq!(clip(&"é".repeat(81)), format!("{}…", "é".repeat(80)));
    }

    #[test]
    fn bytes_and_strings_parse_alike() {
        let text = "0.1 0.2 0.3\n";
        assert_eq!(
            parse_text::<3>(text.as_bytes(), Path::new("in.txt")).unwrap(),
            parse(text).unwrap()
        );
        let e = parse_text::<3>(b"", Path::new("in.txt")).unwrap_err();
        assert_eq!(e.to_string(), "in.txt:1: the file holds no points");
    }
}
