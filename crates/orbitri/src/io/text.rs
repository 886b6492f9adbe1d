//! Text points: one point per line, coordinates separated by blanks or commas, `#` starts a
//! comment, blank lines are skipped.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};

/// Reads a text point file, streaming it line by line.
pub fn read_text<const D: usize>(path: &Path) -> Result<Vec<[f64; D]>> {
    let file = std::fs::File::open(path).map_err(|source| Error::Io {
        file: path.to_path_buf(),
        source,
    })?;
    parse_lines(BufReader::new(file), path)
}

/// Parses text points; `file` is only used in error messages.
pub fn parse_text<const D: usize>(text: &str, file: &Path) -> Result<Vec<[f64; D]>> {
    parse_lines(text.as_bytes(), file)
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
        let raw = std::str::from_utf8(&buf).map_err(|_| {
            err(
                line,
                "not UTF-8 text (for binary input use a .npy file)".into(),
            )
        })?;
        let body = raw.split('#').next().unwrap_or("");
        let mut p = [0.0; D];
        let mut count = 0;
        for f in body
            .split(|c: char| c == ',' || c.is_whitespace())
            .filter(|s| !s.is_empty())
        {
            if count < D {
                let v: f64 = f
                    .parse()
                    .map_err(|_| err(line, format!("coordinate {count} '{f}' is not a number")))?;
                if !v.is_finite() {
                    return Err(err(
                        line,
                        format!("coordinate {count} is {v}, not a finite number"),
                    ));
                }
                p[count] = v;
            }
            count += 1;
        }
        if count == 0 {
            continue;
        }
        if count != D {
            return Err(err(
                line,
                format!(
                    "expected {D} coordinates, found {count} ({:?})",
                    body.trim()
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
}
