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

fn parse_npy<const D: usize>(bytes: &[u8], path: &Path) -> Result<Vec<[f64; D]>> {
    let dim = D;
    let err = |message: String| Error::Parse {
        file: path.to_path_buf(),
        line: 1,
        message,
    };
    if bytes.len() < 10 || &bytes[..6] != b"\x93NUMPY" {
        return Err(err("not a .npy file (bad magic)".into()));
    }
    let (hlen, start) = match bytes[6] {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10),
        2 | 3 if bytes.len() >= 12 => (
            u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize,
            12,
        ),
        v => return Err(err(format!("unsupported .npy version {v}"))),
    };
    let header = bytes
        .get(start..start + hlen)
        .ok_or_else(|| err("truncated .npy header".into()))?;
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
    if data.len() < n * dim * 8 {
        return Err(err(format!(
            "truncated data: {} bytes for {n}×{dim} float64",
            data.len()
        )));
    }
    if n == 0 {
        return Err(Error::EmptyInput);
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
}
