//! NumPy `.npy` arrays of float64 (little- or big-endian, C order), shape `(N, dim)`.

use std::path::Path;

use crate::error::{Error, Result};

/// Reads an `(N, D)` float64 array.
pub fn read_npy<const D: usize>(path: &Path) -> Result<Vec<[f64; D]>> {
    let bytes = std::fs::read(path).map_err(|source| Error::Io {
        file: path.to_path_buf(),
        source,
    })?;
    parse_npy(&bytes, path)
}

fn header_value<'a>(header: &'a str, key: &str) -> Option<&'a str> {
    let at = header.find(&format!("'{key}'"))? + key.len() + 2;
    let rest = header[at..].trim_start().strip_prefix(':')?.trim_start();
    let end = if rest.starts_with('(') {
        rest.find(')')? + 1
    } else {
        rest.find(',').unwrap_or(rest.len())
    };
    Some(rest[..end].trim())
}

/// Parses the bytes of an `(N, D)` float64 `.npy` file (what [`read_npy`] reads); `path` is
/// only used in error messages, which all name it.
pub fn parse_npy<const D: usize>(bytes: &[u8], path: &Path) -> Result<Vec<[f64; D]>> {
    let dim = D;
    let err = |message: String| Error::Parse {
        file: path.to_path_buf(),
        line: 1,
        message,
    };
    const MAGIC: &[u8] = b"\x93NUMPY";
    if bytes.is_empty() {
        return Err(err("empty file (0 bytes), not a .npy array".into()));
    }
    if !bytes.starts_with(&MAGIC[..bytes.len().min(MAGIC.len())]) {
        return Err(err("not a .npy file (bad magic)".into()));
    }
    let truncated = || err(format!("truncated .npy header ({} bytes)", bytes.len()));
    if bytes.len() < 10 {
        return Err(truncated());
    }
    let (hlen, start) = match bytes[6] {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10),
        2 | 3 if bytes.len() >= 12 => (
            u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize,
            12,
        ),
        2 | 3 => return Err(truncated()),
        v => return Err(err(format!("unsupported .npy version {v}"))),
    };
    let header = bytes.get(start..start + hlen).ok_or_else(truncated)?;
    let header = std::str::from_utf8(header).map_err(|_| err("bad .npy header".into()))?;
    let descr =
        header_value(header, "descr").ok_or_else(|| err("no dtype in .npy header".into()))?;
    let little = match descr.trim_matches(|c| c == '\'' || c == '"') {
        "<f8" | "=f8" => true,
        ">f8" => false,
        other => {
            return Err(err(format!(
                "dtype {other} is not float64 (convert with .astype(np.float64))"
            )))
        }
    };
    if header_value(header, "fortran_order") == Some("True") {
        return Err(err(
            "Fortran-ordered array (save with np.ascontiguousarray)".into(),
        ));
    }
    let shape =
        header_value(header, "shape").ok_or_else(|| err("no shape in .npy header".into()))?;
    let dims: Vec<usize> = shape
        .trim_matches(|c| c == '(' || c == ')')
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| s.parse().map_err(|_| err(format!("bad shape {shape}"))))
        .collect::<Result<_>>()?;
    if dims.len() != 2 || dims[1] != dim {
        return Err(err(format!("array shape {shape}, expected (N, {dim})")));
    }
    let data = &bytes[start + hlen..];
    let n = dims[0];
    // a shape from a corrupt header can overflow the byte count
    if n.checked_mul(dim * 8).is_none_or(|len| data.len() < len) {
        return Err(err(format!(
            "truncated data: {} bytes for {n}×{dim} float64",
            data.len()
        )));
    }
    if n == 0 {
        return Err(err(format!("the file holds no points (shape {shape})")));
    }
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let mut p = [0.0; D];
        for axis in 0..dim {
            let k = (i * dim + axis) * 8;
            let b: [u8; 8] = data[k..k + 8].try_into().unwrap();
            let v = if little {
                f64::from_le_bytes(b)
            } else {
                f64::from_be_bytes(b)
            };
            if !v.is_finite() {
                return Err(err(format!(
                    "row {i}, coordinate {axis} is {v}, not a finite number"
                )));
            }
            p[axis] = v;
        }
        out.push(p);
    }
    Ok(out)
}

/// Encodes an `(N, D)` float64 array as `.npy` (used by tests and tools).
pub fn encode_npy<const D: usize>(rows: &[[f64; D]]) -> Vec<u8> {
    encode_npy_matrix(rows.as_flattened(), D)
}

/// A float64 `.npy` file of shape `(data.len() / cols, cols)`, row-major.
pub fn encode_npy_matrix(data: &[f64], cols: usize) -> Vec<u8> {
    let mut header = format!(
        "{{'descr': '<f8', 'fortran_order': False, 'shape': ({}, {cols}), }}",
        data.len() / cols
    );
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    for v in data {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_errors() {
        let rows = vec![[0.1, 0.2, 0.3], [1.0, 2.0, 3.0]];
        let b = encode_npy(&rows);
        assert_eq!(parse_npy::<3>(&b, Path::new("a.npy")).unwrap(), rows);
        let e = parse_npy::<2>(&b, Path::new("a.npy"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("expected (N, 2)"), "{e}");
        let e = parse_npy::<3>(b"hello world", Path::new("a.npy"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("bad magic"), "{e}");
        let nan = encode_npy(&[[0.0, f64::NAN, 0.0]]);
        let e = parse_npy::<3>(&nan, Path::new("a.npy"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("row 0, coordinate 1 is NaN"), "{e}");
        let truncated = &b[..b.len() - 4];
        let e = parse_npy::<3>(truncated, Path::new("a.npy"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("truncated"), "{e}");
    }

    fn error(bytes: &[u8]) -> String {
        parse_npy::<3>(bytes, Path::new("a.npy"))
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn empty_and_truncated_files_name_the_file() {
        // 0 rows: was the untyped-to-the-file "the input holds no points"
        let empty = encode_npy::<3>(&[]);
        assert_eq!(
            error(&empty),
            "a.npy:1: the file holds no points (shape (0, 3))"
        );
        assert_eq!(
            error(b""),
            "a.npy:1: empty file (0 bytes), not a .npy array"
        );
        // a header cut anywhere, also before the version bytes or within the magic
        let b = encode_npy(&[[0.1, 0.2, 0.3]]);
        let header_end = b.len() - 24;
        for cut in 1..header_end {
            let e = error(&b[..cut]);
            assert!(
                e.starts_with("a.npy:1: truncated .npy header"),
                "{cut}: {e}"
            );
        }
        let mut v2 = b"\x93NUMPY\x02\x00\x10\x00".to_vec();
        assert_eq!(error(&v2), "a.npy:1: truncated .npy header (10 bytes)");
        v2.extend_from_slice(&[0, 0]);
        assert!(error(&v2).starts_with("a.npy:1: truncated .npy header"));
        assert!(error(b"\x93NUMPX\x01\x00").contains("bad magic"));
    }

    #[test]
    fn a_huge_shape_is_truncated_data_not_an_overflow() {
        let mut b = encode_npy(&[[0.1, 0.2, 0.3]]);
        let header_end = 10 + u16::from_le_bytes([b[8], b[9]]) as usize;
        let header = String::from_utf8(b[10..header_end].to_vec()).unwrap();
        // the same header length: the shape's extra digits replace padding blanks
        let huge = format!("({}, 3)", usize::MAX);
        let mut header = header.replace("(1, 3)", &huge);
        let newline = header.len() - 1;
        header.replace_range(newline - (huge.len() - "(1, 3)".len())..newline, "");
        b.splice(10..header_end, header.bytes());
        let e = error(&b);
        assert!(
            e.starts_with("a.npy:1: truncated data: 24 bytes for"),
            "{e}"
        );
    }
}
