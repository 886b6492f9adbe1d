//! NumPy `.npy` arrays, shape `(N, dim)`, C order: read as float64 from float32, float64 and
//! integer arrays (little- or big-endian); written as float64 or int64, and several named
//! ones together as an `.npz` archive.

use std::path::Path;

use crate::error::{Error, Result};

/// Reads an `(N, D)` array of float64, float32 or integers (as float64).
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
    let dtype = Dtype::parse(descr.trim_matches(|c| c == '\'' || c == '"')).ok_or_else(|| {
        err(format!(
            "dtype {descr} is not a number type this reader takes (float64, float32 or an integer; convert with .astype(np.float64))"
        ))
    })?;
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
    if n.checked_mul(dim * dtype.size)
        .is_none_or(|len| data.len() < len)
    {
        return Err(err(format!(
            "truncated data: {} bytes for {n}×{dim} {}",
            data.len(),
            dtype.name()
        )));
    }
    if n == 0 {
        return Err(err(format!("the file holds no points (shape {shape})")));
    }
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let mut p = [0.0; D];
        for axis in 0..dim {
            let k = (i * dim + axis) * dtype.size;
            let v = dtype.value(&data[k..k + dtype.size]);
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

/// The element type of a `.npy` array this reader takes.
#[derive(Clone, Copy)]
struct Dtype {
    kind: u8,
    size: usize,
    little: bool,
}

impl Dtype {
    /// `<f8`, `>f4`, `|i1`, `<u2`, … (floats of 4 or 8 bytes, integers of 1 to 8).
    fn parse(descr: &str) -> Option<Dtype> {
        let (order, rest) = descr.split_at_checked(1)?;
        let little = match order {
            "<" | "=" | "|" => true,
            ">" => false,
            _ => return None,
        };
        let (kind, size) = rest.split_at_checked(1)?;
        let size: usize = size.parse().ok()?;
        let ok = match kind {
            "f" => matches!(size, 4 | 8),
            "i" | "u" => matches!(size, 1 | 2 | 4 | 8),
            _ => false,
        };
        ok.then(|| Dtype {
            kind: kind.as_bytes()[0],
            size,
            little,
        })
    }

    fn name(self) -> String {
        let kind = match self.kind {
            b'f' => "float",
            b'i' => "int",
            _ => "uint",
        };
        format!("{kind}{}", self.size * 8)
    }

    /// The value of one element's bytes (`size` of them).
    fn value(self, b: &[u8]) -> f64 {
        let mut x = [0u8; 8];
        if self.little {
            x[..self.size].copy_from_slice(b);
        } else {
            for (k, &byte) in b.iter().rev().enumerate() {
                x[k] = byte;
            }
        }
        let bits = u64::from_le_bytes(x);
        let shift = 64 - 8 * self.size as u32;
        match self.kind {
            b'f' if self.size == 4 => f64::from(f32::from_bits(bits as u32)),
            b'f' => f64::from_bits(bits),
            // sign-extend from the element's width
            b'i' => ((bits << shift) as i64 >> shift) as f64,
            _ => bits as f64,
        }
    }
}

/// Encodes an `(N, D)` float64 array as `.npy` (used by tests and tools).
pub fn encode_npy<const D: usize>(rows: &[[f64; D]]) -> Vec<u8> {
    encode_npy_matrix(rows.as_flattened(), D)
}

/// A float64 `.npy` file of shape `(data.len() / cols, cols)`, row-major.
pub fn encode_npy_matrix(data: &[f64], cols: usize) -> Vec<u8> {
    let shape = format!("({}, {cols})", data.len() / cols);
    encode_npy_raw("<f8", &shape, data.iter().flat_map(|v| v.to_le_bytes()))
}

/// A `.npy` array of what [`NpyArray`] holds.
pub fn encode_npy_array(a: &NpyArray) -> Vec<u8> {
    let shape = match a.cols {
        None => format!("({},)", a.len()),
        Some(c) => format!("({}, {c})", a.len() / c),
    };
    match &a.data {
        NpyData::F64(v) => encode_npy_raw("<f8", &shape, v.iter().flat_map(|x| x.to_le_bytes())),
        NpyData::I64(v) => encode_npy_raw("<i8", &shape, v.iter().flat_map(|x| x.to_le_bytes())),
    }
}

/// The values of a named array of an `.npz` archive.
pub enum NpyData {
    F64(Vec<f64>),
    I64(Vec<i64>),
}

/// A named array: one-dimensional (`cols` is `None`) or `(len / cols, cols)`.
pub struct NpyArray {
    pub name: String,
    pub data: NpyData,
    pub cols: Option<usize>,
}

impl NpyArray {
    fn len(&self) -> usize {
        match &self.data {
            NpyData::F64(v) => v.len(),
            NpyData::I64(v) => v.len(),
        }
    }
}

/// An `.npz` archive (what `numpy.savez` writes and `numpy.load` reads): a zip of one
/// `NAME.npy` per array, stored uncompressed. An archive past 4 GiB is an error (it would
/// need Zip64): write `.npy` then.
pub fn encode_npz(arrays: &[NpyArray]) -> std::io::Result<Vec<u8>> {
    let mut out = Vec::new();
    let mut central = Vec::new();
    let too_large = || {
        std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            "the arrays are too large for an .npz archive without Zip64 (4 GiB): write .npy",
        )
    };
    for a in arrays {
        let bytes = encode_npy_array(a);
        let name = format!("{}.npy", a.name);
        let mut crc = flate2::Crc::new();
        crc.update(&bytes);
        let size = u32::try_from(bytes.len()).map_err(|_| too_large())?;
        let offset = u32::try_from(out.len()).map_err(|_| too_large())?;
        // what local and central headers share: version 2.0, no flags, stored, 1980-01-01
        let mut common = Vec::new();
        for v in [20u16, 0, 0, 0, 0x21] {
            common.extend_from_slice(&v.to_le_bytes());
        }
        for v in [crc.sum(), size, size] {
            common.extend_from_slice(&v.to_le_bytes());
        }
        common.extend_from_slice(&(name.len() as u16).to_le_bytes());
        common.extend_from_slice(&0u16.to_le_bytes()); // extra field
        out.extend_from_slice(&0x0403_4b50u32.to_le_bytes());
        out.extend_from_slice(&common);
        out.extend_from_slice(name.as_bytes());
        out.extend_from_slice(&bytes);
        central.extend_from_slice(&0x0201_4b50u32.to_le_bytes());
        central.extend_from_slice(&20u16.to_le_bytes()); // made by
        central.extend_from_slice(&common);
        // comment length, disk, internal (2 bytes) and external (4) attributes
        central.extend_from_slice(&[0; 10]);
        central.extend_from_slice(&offset.to_le_bytes());
        central.extend_from_slice(name.as_bytes());
    }
    let at = u32::try_from(out.len()).map_err(|_| too_large())?;
    let count = arrays.len() as u16;
    out.extend_from_slice(&central);
    out.extend_from_slice(&0x0605_4b50u32.to_le_bytes());
    out.extend_from_slice(&[0; 4]); // this disk, the central directory's disk
    out.extend_from_slice(&count.to_le_bytes());
    out.extend_from_slice(&count.to_le_bytes());
    out.extend_from_slice(&(central.len() as u32).to_le_bytes());
    out.extend_from_slice(&at.to_le_bytes());
    out.extend_from_slice(&0u16.to_le_bytes()); // comment
    Ok(out)
}

/// A `.npy` file of type `descr` and shape `shape` (Python's tuple syntax) around `data`.
fn encode_npy_raw(descr: &str, shape: &str, data: impl Iterator<Item = u8>) -> Vec<u8> {
    let mut header = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}");
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut out = b"\x93NUMPY\x01\x00".to_vec();
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    out.extend(data);
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

    /// A `.npy` file of `descr` and shape `(rows, cols)` around raw bytes.
    fn raw(descr: &str, rows: usize, cols: usize, data: &[u8]) -> Vec<u8> {
        encode_npy_raw(descr, &format!("({rows}, {cols})"), data.iter().copied())
    }

    #[test]
    fn float32_and_integer_arrays_are_read() {
        let p = Path::new("a.npy");
        let f4: Vec<u8> = [0.5f32, -1.25]
            .iter()
            .flat_map(|x| x.to_le_bytes())
            .collect();
        assert_eq!(
            parse_npy::<2>(&raw("<f4", 1, 2, &f4), p).unwrap(),
            [[0.5, -1.25]]
        );
        let f4be: Vec<u8> = [0.5f32, 3.0].iter().flat_map(|x| x.to_be_bytes()).collect();
        assert_eq!(
            parse_npy::<2>(&raw(">f4", 1, 2, &f4be), p).unwrap(),
            [[0.5, 3.0]]
        );
        let i8s: Vec<u8> = [-3i64, 7].iter().flat_map(|x| x.to_le_bytes()).collect();
        assert_eq!(
            parse_npy::<2>(&raw("<i8", 1, 2, &i8s), p).unwrap(),
            [[-3.0, 7.0]]
        );
        let i2: Vec<u8> = [-2i16, 300].iter().flat_map(|x| x.to_be_bytes()).collect();
        assert_eq!(
            parse_npy::<2>(&raw(">i2", 1, 2, &i2), p).unwrap(),
            [[-2.0, 300.0]]
        );
        assert_eq!(
            parse_npy::<2>(&raw("|u1", 1, 2, &[255, 1]), p).unwrap(),
            [[255.0, 1.0]]
        );
        assert_eq!(
            parse_npy::<2>(&raw("|i1", 1, 2, &[255, 1]), p).unwrap(),
            [[-1.0, 1.0]]
        );
        let e = parse_npy::<2>(&raw("<c16", 1, 2, &[0; 32]), p)
            .unwrap_err()
            .to_string();
        assert!(e.contains("dtype '<c16' is not a number type"), "{e}");
        let e = parse_npy::<2>(&raw("<f4", 2, 2, &f4), p)
            .unwrap_err()
            .to_string();
        assert_eq!(e, "a.npy:1: truncated data: 8 bytes for 2×2 float32");
    }

    #[test]
    fn npz_archives_hold_named_arrays() {
        let a = NpyArray {
            name: "volume".into(),
            data: NpyData::F64(vec![0.25, 0.75]),
            cols: None,
        };
        let b = NpyArray {
            name: "centroid".into(),
            data: NpyData::I64(vec![1, 2, 3, 4]),
            cols: Some(2),
        };
        let z = encode_npz(&[a, b]).unwrap();
        // local headers, then the central directory, then its end record
        assert_eq!(&z[..4], b"PK\x03\x04");
        assert_eq!(&z[z.len() - 22..z.len() - 18], b"PK\x05\x06");
        assert_eq!(u16::from_le_bytes([z[z.len() - 12], z[z.len() - 11]]), 2);
        let npy = encode_npy_array(&NpyArray {
            name: "x".into(),
            data: NpyData::F64(vec![0.25, 0.75]),
            cols: None,
        });
        assert!(String::from_utf8_lossy(&npy).contains("'shape': (2,)"));
        let at = z.windows(npy.len()).position(|w| w == npy);
        assert_eq!(at, Some(30 + "volume.npy".len()));
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
