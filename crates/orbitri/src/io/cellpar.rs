//! Boxes as crystallographers and simulation codes write them: lengths and angles
//! (`a b c α β γ`, ASE's `cellpar`, MDAnalysis's `dimensions`, a CIF's cell) to the lattice
//! vectors the spaces take.

use crate::error::{Error, Result};

/// `cos` of an angle in degrees, exactly 0 at 90° (so that a right angle gives an
/// orthogonal box, as ASE and MDAnalysis make it).
fn cos_deg(angle: f64) -> f64 {
    if angle == 90.0 {
        0.0
    } else {
        angle.to_radians().cos()
    }
}

fn check(lengths: &[f64], angles: &[f64]) -> Result<()> {
    for (k, &l) in lengths.iter().enumerate() {
        if !(l.is_finite() && l > 0.0) {
            return Err(Error::InvalidBox(format!(
                "cell length {} is {l}; lengths must be positive and finite",
                ["a", "b", "c"][k]
            )));
        }
    }
    for (k, &t) in angles.iter().enumerate() {
        if !(t.is_finite() && t > 0.0 && t < 180.0) {
            let name = if angles.len() == 1 {
                "γ"
            } else {
                ["α", "β", "γ"][k]
            };
            return Err(Error::InvalidBox(format!(
                "cell angle {name} is {t}; angles are in degrees, strictly between 0 and 180"
            )));
        }
    }
    Ok(())
}

/// The lattice vectors (rows) of the 3D cell of lengths `a, b, c` and angles `α` (between
/// `b` and `c`), `β` (`a`, `c`) and `γ` (`a`, `b`) in degrees, in the standard orientation:
/// `a` along x, `b` in the xy-plane, `c` with a positive z. Angles that make no cell (one
/// larger than the sum of the two others, say) are an error.
///
/// ```
/// let m = orbitri::io::lattice_from_cellpar([2.0, 3.0, 4.0, 90.0, 90.0, 90.0]).unwrap();
/// assert_eq!(m, [[2.0, 0.0, 0.0], [0.0, 3.0, 0.0], [0.0, 0.0, 4.0]]);
/// let e = orbitri::io::lattice_from_cellpar([1.0, 1.0, 1.0, 10.0, 10.0, 90.0]).unwrap_err();
/// assert!(e.to_string().contains("make no cell"));
/// ```
pub fn lattice_from_cellpar([a, b, c, alpha, beta, gamma]: [f64; 6]) -> Result<[[f64; 3]; 3]> {
    check(&[a, b, c], &[alpha, beta, gamma])?;
    let (ca, cb, cg) = (cos_deg(alpha), cos_deg(beta), cos_deg(gamma));
    let sg = gamma.to_radians().sin();
    let cx = cb;
    let cy = (ca - cb * cg) / sg;
    let cz2 = 1.0 - cx * cx - cy * cy;
    // within rounding of 0 (120°, 120°, 120°): a flat cell
    if cz2 <= 1e-12 {
        return Err(Error::InvalidBox(format!(
            "the angles α = {alpha}, β = {beta}, γ = {gamma} make no cell (each must be less than the sum of the two others, and their sum less than 360)"
        )));
    }
    Ok([
        [a, 0.0, 0.0],
        [b * cg, b * sg, 0.0],
        [c * cx, c * cy, c * cz2.sqrt()],
    ])
}

/// The lattice vectors (rows) of the 2D cell of lengths `a, b` and angle `γ` in degrees: `a`
/// along x, `b` at `γ` from it, counter-clockwise.
///
/// ```
/// let m = orbitri::io::lattice_from_cellpar2([1.0, 2.0, 90.0]).unwrap();
/// assert_eq!(m, [[1.0, 0.0], [0.0, 2.0]]);
/// ```
pub fn lattice_from_cellpar2([a, b, gamma]: [f64; 3]) -> Result<[[f64; 2]; 2]> {
    check(&[a, b], &[gamma])?;
    Ok([[a, 0.0], [b * cos_deg(gamma), b * gamma.to_radians().sin()]])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cells_from_lengths_and_angles() {
        // hexagonal: a = b, γ = 120°
        let m = lattice_from_cellpar([2.0, 2.0, 3.0, 90.0, 90.0, 120.0]).unwrap();
        assert!((m[1][0] + 1.0).abs() < 1e-15 && (m[1][1] - 3f64.sqrt()).abs() < 1e-15);
        assert_eq!(m[2], [0.0, 0.0, 3.0]);
        // every angle is the one asked for
        let m = lattice_from_cellpar([1.0, 2.0, 3.0, 70.0, 80.0, 100.0]).unwrap();
        let angle = |u: [f64; 3], v: [f64; 3]| {
            let dot = |p: [f64; 3], q: [f64; 3]| p[0] * q[0] + p[1] * q[1] + p[2] * q[2];
            (dot(u, v) / (dot(u, u) * dot(v, v)).sqrt())
                .acos()
                .to_degrees()
        };
        assert!((angle(m[1], m[2]) - 70.0).abs() < 1e-12);
        assert!((angle(m[0], m[2]) - 80.0).abs() < 1e-12);
        assert!((angle(m[0], m[1]) - 100.0).abs() < 1e-12);
        let e = |p| lattice_from_cellpar(p).unwrap_err().to_string();
        assert_eq!(
            e([1.0, 0.0, 1.0, 90.0, 90.0, 90.0]),
            "invalid box: cell length b is 0; lengths must be positive and finite"
        );
        assert!(
            e([1.0, 1.0, 1.0, 90.0, 180.0, 90.0]).starts_with("invalid box: cell angle β is 180")
        );
        assert!(e([1.0, 1.0, 1.0, 120.0, 120.0, 120.0]).contains("make no cell"));
        assert!(e([1.0, 1.0, 1.0, 130.0, 130.0, 130.0]).contains("make no cell"));
        assert!(e([1.0, 1.0, 1.0, 20.0, 30.0, 60.0]).contains("make no cell"));
        let e2 = lattice_from_cellpar2([1.0, 1.0, f64::NAN])
            .unwrap_err()
            .to_string();
        assert!(e2.starts_with("invalid box: cell angle γ is NaN"), "{e2}");
    }
}
