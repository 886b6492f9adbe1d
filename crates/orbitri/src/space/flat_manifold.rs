//! Closed flat manifolds `E^D/G`, `G` a Bieberbach group (thesis §4.2, Caroli–Teillaud): the
//! translations `T` of a lattice `M` and `k` cosets of them, represented by isometries
//! `r_c: x ↦ A_c·x + s_c·M/q` whose linear parts `A_c` are signed permutation matrices and
//! whose translations are multiples of `M/q` for a power of two `q`. Every element is
//! `g = (c, o): x ↦ A_c·x + (s_c/q + o)·M`, `o` an integer vector.
//!
//! The predicates are exact because a lifted point `g·p = A_c·p + (s_c + q·o)·M/q` is a
//! signed permutation of the stored coordinates (exact) plus an integer combination of the
//! rows of `M/q`: a lifted point of the flat torus of `M/q`, whose filters and exact
//! fallbacks are reused as they are. The symbolic perturbation orders lifted points by
//! their stored coordinates (one orbit, one stored point: invariant under `G`), and copies
//! `g·p`, `h·p` of one point, which meet in one test in the coverings, by `g⁻¹∘h` in a
//! left-invariant order of `G` (`left_order.rs`; the didicosm has none and is ordered by
//! coset, then translation: see `FlatManifold::copy_order`).
//!
//! The covering ladder is the torus of `T`'s ladder (`k` sheets per torus sheet) followed by
//! the manifold itself: Caroli–Teillaud's Theorem 10 with the translational subgroup.

use super::flat_torus::{UnperturbedInSphere, L};
use super::lattice::{Ladder, Level};
use super::left_order::LeftOrder;
use super::metric::Gram;
use super::{least_frame, FlatSpace, FlatTorus, Lattice, OrbitSpace};
use crate::error::{Error, Result};
use crate::predicates::perturbed_by;
use crate::predicates::Sign;

/// A group element `x ↦ A_c·x + (s_c/q + o)·M`: coset `coset` of the translations, lattice
/// offset `offset`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Motion<const D: usize> {
    pub coset: u8,
    pub offset: [i8; D],
}

impl<const D: usize> Default for Motion<D> {
    /// The identity.
    fn default() -> Self {
        Motion {
            coset: 0,
            offset: [0; D],
        }
    }
}

crate::tds::unpacked!(impl [const D: usize] Motion<D>);

/// A coset representative `x ↦ A·x + s·M/q` as given to [`FlatManifold::new`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Coset<const D: usize> {
    /// `A`, a signed permutation matrix: `linear[i][j]` is the coefficient of `x_j` in
    /// output coordinate `i`.
    pub linear: [[i8; D]; D],
    /// `s`: the translation in units of the rows of `M/q`.
    pub shift: [i32; D],
}

/// How a coset's linear part acts on stored coordinates, exactly.
#[derive(Clone, Debug)]
enum Action<const D: usize> {
    /// Cartesian coordinates: output coordinate `i` is `sign·x_j`, as `(j, sign)`.
    Permute([(usize, f64); D]),
    /// Lattice coordinates: output coordinate `i` is `Σ_j a_ij·x_j` with integers `a_ij`,
    /// exact on the grid the stored coordinates are rounded to.
    Integer([[f64; D]; D]),
}

impl<const D: usize> Action<D> {
    #[inline(always)]
    fn apply(&self, p: &[f64; D]) -> [f64; D] {
        match self {
            Action::Permute(perm) => std::array::from_fn(|i| {
                let (j, sign) = perm[i];
                sign * p[j]
            }),
            Action::Integer(a) => std::array::from_fn(|i| {
                let mut s = 0.0;
                for j in 0..D {
                    if a[i][j] != 0.0 {
                        s += a[i][j] * p[j];
                    }
                }
                s
            }),
        }
    }
}

/// A coset of a lattice frame: `(R, s, A)`, see [`FlatManifold::in_lattice_frame`].
pub(super) type LatticeCoset<const D: usize> = ([[i32; D]; D], [i32; D], [[f64; D]; D]);

/// A coset with what the group law needs.
#[derive(Clone, Debug)]
struct CosetData<const D: usize> {
    action: Action<D>,
    /// `A` in Cartesian coordinates (rounded when irrational).
    linear: [[f64; D]; D],
    /// The action of `A` on lattice coordinates: `A·(o·M) = (o·R)·M`.
    r: [[i32; D]; D],
    shift: [i32; D],
    reverses: bool,
}

/// The frame of a manifold whose linear parts are not signed permutations (a hexagonal
/// cross-section turned by a third or a sixth): points are stored in the coordinates of the
/// lattice `M/q`, rounded to a grid on which the cosets' integer actions are exact, and
/// the predicates use the lattice's exact Gram matrix.
#[derive(Clone, Debug)]
struct LatticeFrame<const D: usize> {
    /// The torus of the identity lattice: exact orientation, coincidence and order of
    /// lifted points in lattice coordinates.
    unit: FlatTorus<D>,
    gram: Gram<D>,
    /// The grid spacing per coordinate (a power of two).
    quantum: [f64; D],
}

/// A closed flat manifold: the orbit space of a Bieberbach group.
#[derive(Clone, Debug)]
pub struct FlatManifold<const D: usize> {
    name: &'static str,
    translations: Lattice<D>,
    /// The torus of `M/q`: its lattice gives the internal frame, its predicates the exact
    /// tests on lifted points.
    fine: FlatTorus<D>,
    q: i32,
    cosets: Vec<CosetData<D>>,
    /// `r_a∘r_b = (c, κ)`: the coset of the product and its lattice offset, at `a·k + b`.
    product: Vec<(u8, [i32; D])>,
    inverse: Vec<u8>,
    /// The coverings by sublattices of `T`, systoles in the internal frame.
    ladder: Vec<Level<D>>,
    /// `δ(G)`: the least displacement of a non-identity element, internal frame.
    systole: f64,
    /// The order of the copies of one point in the perturbation (none for a group that is
    /// not left-orderable).
    order: Option<LeftOrder<D>>,
    /// The domain is the part of `T`'s domain whose fractional coordinate along this axis
    /// is below `1/k`.
    slab_axis: usize,
    /// `T`'s internal length unit over the fine lattice's (`q` when `q` is a power of two).
    scale: f64,
    /// A bound on the diameter `Δ` of the largest empty ball of one point's orbit, internal
    /// frame.
    orbit_gap: f64,
    /// `None`: stored points are Cartesian (the fine torus's internal frame).
    lattice_frame: Option<Box<LatticeFrame<D>>>,
}

pub(super) fn mat_mul<const D: usize>(a: &[[i32; D]; D], b: &[[i32; D]; D]) -> [[i32; D]; D] {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..D).map(|k| a[i][k] * b[k][j]).sum()))
}

/// `o·R` for a row vector `o`.
fn row_times<const D: usize>(o: [i32; D], r: &[[i32; D]; D]) -> [i32; D] {
    std::array::from_fn(|j| (0..D).map(|k| o[k] * r[k][j]).sum())
}

fn det<const D: usize>(a: &[[i32; D]; D]) -> i32 {
    match D {
        2 => a[0][0] * a[1][1] - a[0][1] * a[1][0],
        3 => {
            a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
                - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
                + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])
        }
        _ => unreachable!("dimension 2 or 3"),
    }
}

/// `Aᵀ·v`: the inverse of an orthogonal linear part applied to a vector.
fn transpose_times<const D: usize>(a: &[[f64; D]; D], v: &[f64; D]) -> [f64; D] {
    std::array::from_fn(|j| (0..D).map(|i| a[i][j] * v[i]).sum())
}

/// Offsets are bounded by construction; overflowing them is a bug, and it must stop the
/// program rather than silently wrap, also in release builds.
#[inline(always)]
fn narrow<const D: usize>(o: [i32; D]) -> [i8; D] {
    let mut out = [0i8; D];
    for c in 0..D {
        if o[c] != o[c] as i8 as i32 {
            overflow(o[c]);
        }
        out[c] = o[c] as i8;
    }
    out
}

#[cold]
fn overflow(x: i32) -> ! {
    panic!("lattice offset {x} out of the 8-bit range")
}

/// Twice the largest empty-ball diameter `Δ` one point's orbit can leave, internal frame of
/// `T`, with a relative margin: a covering by translations whose systole exceeds it
/// triangulates every non-empty point set (Theorem 10 of Caroli–Teillaud). `Δ` is twice the
/// covering radius `ρ` of the orbit, bounded two ways: by `T`'s alone, `½√(Σ|b_i|²)`; and
/// by layers: the cosets map the slab domain onto the `k` layers of `T`'s domain along the
/// slab axis, each holding a translate of the lattice of the other vectors on a plane, so a
/// point is within the layer width `w` of that plane and within `½√(Σ_{i≠axis}|b_i|²)` of
/// a lattice point on it.
fn one_point_need<const D: usize>(t: &Lattice<D>, k: usize, axis: usize) -> f64 {
    let m = &t.rows.m;
    let sq = |r: &[f64; D]| r.iter().map(|x| x * x).sum::<f64>();
    let others: Vec<&[f64; D]> = (0..D).filter(|&i| i != axis).map(|i| &m[i]).collect();
    // the measure of the other vectors' cell: a length in 2D, an area in 3D
    let base = if D == 2 {
        sq(others[0]).sqrt()
    } else {
        let (a, b) = (others[0], others[1]);
        let c = [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ];
        (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt()
    };
    let w = t.volume_in() / base / k as f64;
    let rho_layer = (w * w + 0.25 * others.iter().map(|r| sq(r)).sum::<f64>()).sqrt();
    // T's own bound, 4·½√(Σ|b_i|²) with the same margin
    t.one_point_need().min(4.0 * rho_layer * (1.0 + 1e-9))
}

fn not_a_group(why: String) -> Error {
    Error::InvalidBox(format!("not a Bieberbach group presentation: {why}"))
}

impl<const D: usize> FlatManifold<D> {
    /// The manifold of the translations by the rows of `rows` (user units) and the coset
    /// representatives `cosets` (the first one the identity), their translations in units of
    /// `rows/q`. The cosets must shift along `slab_axis` by distinct multiples of `1/k` of
    /// that lattice vector, so that the slab of `T`'s domain below `1/k` along it is a
    /// fundamental domain.
    pub fn new(
        name: &'static str,
        rows: [[f64; D]; D],
        q: i32,
        cosets: &[Coset<D>],
        slab_axis: usize,
    ) -> Result<Self> {
        let translations = Lattice::new(rows)?;
        let identity: [[i8; D]; D] =
            std::array::from_fn(|i| std::array::from_fn(|j| (i == j) as i8));
        if cosets
            .first()
            .is_none_or(|c| c.linear != identity || c.shift != [0; D])
        {
            return Err(not_a_group("the first coset must be the identity".into()));
        }
        let mut data = Vec::with_capacity(cosets.len());
        for (c, co) in cosets.iter().enumerate() {
            let linear = co.linear.map(|r| r.map(|x| x as f64));
            let mut perm = [(0usize, 0.0f64); D];
            for i in 0..D {
                let nz: Vec<usize> = (0..D).filter(|&j| linear[i][j] != 0.0).collect();
                if nz.len() != 1 || linear[i][nz[0]].abs() != 1.0 {
                    return Err(not_a_group(format!(
                        "coset {c} is not a signed permutation"
                    )));
                }
                perm[i] = (nz[0], linear[i][nz[0]]);
            }
            // R = M·Aᵀ·M⁻¹, rounded and confirmed: A maps the lattice onto itself
            let image: [[f64; D]; D] = std::array::from_fn(|kk| {
                std::array::from_fn(|i| (0..D).map(|j| linear[i][j] * rows[kk][j]).sum())
            });
            let r_f: [[f64; D]; D] = image.map(|v| translations.fractional(&v));
            let r = r_f.map(|row| row.map(|x| x.round() as i32));
            if r_f
                .iter()
                .flatten()
                .zip(r.iter().flatten())
                .any(|(a, b)| (a - *b as f64).abs() > 1e-6)
            {
                return Err(not_a_group(format!(
                    "coset {c} does not map the lattice onto itself"
                )));
            }
            data.push(CosetData {
                action: Action::Permute(perm),
                linear,
                r,
                shift: co.shift,
                reverses: det(&r) < 0,
            });
        }
        Self::assemble(name, translations, q, data, slab_axis, None)
    }

    /// The manifold of the translations by `rows` (user units, only used approximately)
    /// whose metric in the coordinates of `rows` is exactly `gram`, and whose cosets are
    /// `(R, s, A)`: `R` the action on lattice coordinates (`A·(o·M) = (o·R)·M`), `s` the
    /// translation in units of `rows/q`, `A` the Cartesian linear part (for output). Points
    /// are stored in lattice coordinates, so nothing irrational is ever computed exactly.
    pub(super) fn in_lattice_frame(
        name: &'static str,
        rows: [[f64; D]; D],
        gram: Gram<D>,
        q: i32,
        cosets: &[LatticeCoset<D>],
        slab_axis: usize,
    ) -> Result<Self> {
        let translations = Lattice::new(rows)?;
        let identity: [[i32; D]; D] =
            std::array::from_fn(|i| std::array::from_fn(|j| (i == j) as i32));
        if cosets
            .first()
            .is_none_or(|c| c.0 != identity || c.1 != [0; D])
        {
            return Err(not_a_group("the first coset must be the identity".into()));
        }
        let data: Vec<CosetData<D>> = cosets
            .iter()
            .map(|&(r, shift, linear)| CosetData {
                // output coordinate j of x·R is Σ_i x_i·R_ij
                action: Action::Integer(std::array::from_fn(|j| {
                    std::array::from_fn(|i| r[i][j] as f64)
                })),
                linear,
                r,
                shift,
                reverses: det(&r) < 0,
            })
            .collect();
        // the grid: every sum an action or a shift forms stays below 2^53 quanta
        let quantum: [f64; D] = std::array::from_fn(|j| {
            let reach = data
                .iter()
                .map(|c| (0..D).map(|i| c.r[i][j].abs()).sum::<i32>() * q + c.shift[j].abs() + q)
                .max()
                .unwrap_or(q);
            2f64.powi((reach as f64).log2().ceil() as i32 - 52)
        });
        let frame = LatticeFrame {
            unit: FlatTorus::with_ladder(
                Lattice::new(identity.map(|r| r.map(|x| x as f64)))?,
                Ladder::Grid,
            ),
            gram,
            quantum,
        };
        Self::assemble(
            name,
            translations,
            q,
            data,
            slab_axis,
            Some(Box::new(frame)),
        )
    }

    /// The group law's tables, the ladder and the systole, shared by both frames.
    fn assemble(
        name: &'static str,
        translations: Lattice<D>,
        q: i32,
        data: Vec<CosetData<D>>,
        slab_axis: usize,
        lattice_frame: Option<Box<LatticeFrame<D>>>,
    ) -> Result<Self> {
        let fine_rows = translations.vectors().map(|r| r.map(|x| x / q as f64));
        let fine = FlatTorus::with_ladder(Lattice::new(fine_rows)?, Ladder::Grid);
        let scale = translations.unit() / fine.lattice().unit();
        if lattice_frame.is_none() && scale != q as f64 {
            return Err(Error::InvalidBox(format!(
                "{name}: the box is too close to the limits of the doubles"
            )));
        }
        let k = data.len();
        let mut product = Vec::with_capacity(k * k);
        for a in 0..k {
            for b in 0..k {
                // r_a∘r_b acts on lattice coordinates by R_b·R_a
                let lin = mat_mul(&data[b].r, &data[a].r);
                let Some(c) = (0..k).find(|&c| data[c].r == lin) else {
                    return Err(not_a_group(format!(
                        "the product of cosets {a} and {b} is no coset"
                    )));
                };
                // A_a·(s_b/q·M) + s_a/q·M − s_c/q·M = κ·M
                let num: [i32; D] = std::array::from_fn(|j| {
                    row_times(data[b].shift, &data[a].r)[j] + data[a].shift[j] - data[c].shift[j]
                });
                if num.iter().any(|x| x % q != 0) {
                    return Err(not_a_group(format!(
                        "cosets {a}·{b} and {c} differ by no lattice vector"
                    )));
                }
                product.push((c as u8, num.map(|x| x / q)));
            }
        }
        let inverse = (0..k)
            .map(|a| (0..k).find(|&b| product[a * k + b].0 == 0).map(|b| b as u8))
            .collect::<Option<Vec<u8>>>()
            .ok_or_else(|| not_a_group("a coset has no inverse".into()))?;
        let need = one_point_need(&translations, k, slab_axis);
        let ladder = translations
            .grid_ladder_for(need)
            .into_iter()
            .map(|l| Level {
                sub: l.sub,
                systole: l.systole * scale,
            })
            .collect::<Vec<_>>();
        let widest = (0..D).map(|c| ladder[0].sub.span(c)).max().unwrap_or(1);
        if 3 * widest * q + q > 127 {
            return Err(Error::InvalidBox(format!(
                "{name}: the box is too elongated (its first covering needs {widest} copies along an axis)"
            )));
        }
        let mut m = FlatManifold {
            name,
            translations,
            fine,
            q,
            cosets: data,
            product,
            inverse,
            ladder,
            systole: 0.0,
            order: None,
            slab_axis,
            scale,
            orbit_gap: need / 2.0 * scale,
            lattice_frame,
        };
        m.systole = m.least_displacement();
        let actions: Vec<_> = m.cosets.iter().map(|c| (c.r, c.shift)).collect();
        m.order = LeftOrder::new(&actions, q);
        if m.systole.is_nan() || m.systole <= 0.0 {
            return Err(not_a_group(
                "an element other than the identity fixes a point".into(),
            ));
        }
        Ok(m)
    }

    /// The manifold's name.
    pub fn name(&self) -> &'static str {
        self.name
    }

    /// The lattice of the translational subgroup `T`.
    pub fn translations(&self) -> &Lattice<D> {
        &self.translations
    }

    /// The index `k` of the translations in the group: the number of cosets.
    pub fn index(&self) -> usize {
        self.cosets.len()
    }

    /// Volume (area in 2D) of the manifold: the torus of `T`'s, over the index.
    pub fn volume(&self) -> f64 {
        self.translations.volume() / self.index() as f64
    }

    /// `δ(G)`, the least distance between a point and one of its other images, in user units.
    pub fn systole(&self) -> f64 {
        self.fine.lattice().measure_to_user(self.systole, 1)
    }

    /// Whether the manifold is orientable (no coset reverses orientation).
    pub fn is_orientable(&self) -> bool {
        self.cosets.iter().all(|c| !c.reverses)
    }

    /// The isometry `x ↦ A·x + t` of an element, in user units.
    pub fn isometry(&self, g: Motion<D>) -> ([[f64; D]; D], [f64; D]) {
        let c = &self.cosets[g.coset as usize];
        let frac: [f64; D] =
            std::array::from_fn(|i| (c.shift[i] + self.q * g.offset[i] as i32) as f64);
        (c.linear, self.fine.lattice().cartesian(&frac))
    }

    /// Generators of the group as isometries: the lattice translations and the coset
    /// representatives.
    pub fn generators(&self) -> Vec<([[f64; D]; D], [f64; D])> {
        let mut out: Vec<_> = (0..D)
            .map(|i| {
                self.isometry(Motion {
                    coset: 0,
                    offset: std::array::from_fn(|j| (i == j) as i8),
                })
            })
            .collect();
        out.extend((1..self.index()).map(|c| {
            self.isometry(Motion {
                coset: c as u8,
                offset: [0; D],
            })
        }));
        out
    }

    /// A user point in the fundamental domain, in the internal frame, and whether it moved
    /// (`None` if it is too far away to be wrapped exactly). The point is wrapped into the
    /// domain of `T` and, of its `k` images there, the one with the least fractional
    /// coordinates (the slab axis first) is kept; moving it may round, as wrapping into a
    /// torus does.
    pub(crate) fn canonical(&self, x: [f64; D]) -> Option<([f64; D], bool)> {
        if let Some(frame) = &self.lattice_frame {
            return self.canonical_in_lattice(frame, x);
        }
        let (y, mut moved) = self.translations.wrap(x)?;
        // the slab axis first, then the others: images tied along the axis (on a boundary
        // of the slab) are told apart by the rest
        let key_of = |z: &[f64; D]| self.slab_first(self.translations.fractional(z));
        let mut best = y;
        let mut key = key_of(&y);
        for c in self.cosets.iter().skip(1) {
            // r_c⁻¹(y) = Aᵀ·(y − s/q·M)
            let t = self.fine.lattice().cartesian(&c.shift.map(|s| s as f64));
            let d: [f64; D] = std::array::from_fn(|i| y[i] - t[i]);
            let (z, _) = self.translations.wrap(transpose_times(&c.linear, &d))?;
            let kz = key_of(&z);
            if kz < key {
                (best, key, moved) = (z, kz, true);
            }
        }
        Some((self.fine.lattice().to_internal(best), moved))
    }

    /// Fractional coordinates reordered with the slab axis first: the order in which the
    /// images of a point compete for the domain (images tied along the axis, on a boundary of
    /// the slab, are told apart by the rest).
    fn slab_first(&self, f: [f64; D]) -> [f64; D] {
        let mut k = [f[self.slab_axis]; D];
        let others = (0..D).filter(|&i| i != self.slab_axis);
        for (slot, i) in others.enumerate() {
            k[slot + 1] = f[i];
        }
        k
    }

    /// [`Self::canonical`] in a lattice frame: the user's point in coordinates of `M/q`,
    /// wrapped into `T`'s domain and rounded to the frame's grid; of its `k` images there
    /// (exact on the grid), the one with the least coordinates, the slab axis first.
    fn canonical_in_lattice(
        &self,
        frame: &LatticeFrame<D>,
        x: [f64; D],
    ) -> Option<([f64; D], bool)> {
        let q = self.q as f64;
        let f = self.translations.fractional(&x);
        if f.iter().any(|v| v.is_nan() || v.abs() >= 2f64.powi(40)) {
            return None;
        }
        let wrap = |v: f64| {
            if v >= q {
                v - q
            } else if v < 0.0 {
                v + q
            } else {
                v
            }
        };
        let u: [f64; D] = std::array::from_fn(|j| {
            let grid = frame.quantum[j];
            wrap(((f[j] - f[j].floor()) * q / grid).round() * grid)
        });
        let mut best = u;
        let mut key = self.slab_first(u);
        for c in self.cosets.iter().skip(1) {
            let y = c.action.apply(&u);
            let z: [f64; D] = std::array::from_fn(|j| {
                let v = y[j] + c.shift[j] as f64;
                v - q * (v / q).floor()
            });
            let kz = self.slab_first(z);
            if kz < key {
                (best, key) = (z, kz);
            }
        }
        let back = self
            .fine
            .lattice()
            .to_user(self.position(&best, self.identity_motion()));
        Some((best, back != x))
    }

    fn identity_motion(&self) -> Motion<D> {
        Motion {
            coset: 0,
            offset: [0; D],
        }
    }

    /// The lifted point `g·p` as a lifted point of the torus of `M/q` in the stored frame:
    /// Cartesian, or lattice coordinates (then see [`Self::cartesian`]).
    #[inline(always)]
    fn lift(&self, (p, g): (&[f64; D], Motion<D>)) -> L<D> {
        let c = &self.cosets[g.coset as usize];
        let x = c.action.apply(p);
        let t: [i32; D] = std::array::from_fn(|i| c.shift[i] + self.q * g.offset[i] as i32);
        (x, narrow(t))
    }

    fn lift_all<const N: usize>(&self, s: &[(P<D>, Motion<D>); N]) -> [L<D>; N] {
        std::array::from_fn(|i| self.lift((&s[i].0, s[i].1)))
    }

    /// A lifted point of the stored frame as a lifted point of the Cartesian torus of
    /// `M/q` (rounded in a lattice frame): what constructions and distances use.
    #[inline(always)]
    fn cartesian(&self, l: L<D>) -> L<D> {
        match &self.lattice_frame {
            None => l,
            Some(_) => (self.fine.lattice().cartesian_in(&l.0), l.1),
        }
    }

    fn cartesian_all<const N: usize>(&self, s: &[(P<D>, Motion<D>); N]) -> [L<D>; N] {
        std::array::from_fn(|i| self.cartesian(self.lift((&s[i].0, s[i].1))))
    }

    #[inline]
    fn compose_elems(&self, a: Motion<D>, b: Motion<D>) -> Motion<D> {
        if a.coset == 0 {
            // a translation first: the offsets add
            return Motion {
                coset: b.coset,
                offset: narrow(std::array::from_fn(|j| {
                    a.offset[j] as i32 + b.offset[j] as i32
                })),
            };
        }
        let k = self.cosets.len();
        let (c, kappa) = self.product[a.coset as usize * k + b.coset as usize];
        let rb = row_times(b.offset.map(|x| x as i32), &self.cosets[a.coset as usize].r);
        Motion {
            coset: c,
            offset: narrow(std::array::from_fn(|j| {
                a.offset[j] as i32 + rb[j] + kappa[j]
            })),
        }
    }

    #[inline]
    fn inverse_elem(&self, a: Motion<D>) -> Motion<D> {
        if a.coset == 0 {
            return Motion {
                coset: 0,
                offset: narrow(a.offset.map(|x| -(x as i32))),
            };
        }
        let k = self.cosets.len();
        let ci = self.inverse[a.coset as usize];
        let (_, kappa) = self.product[a.coset as usize * k + ci as usize];
        let o: [i32; D] = std::array::from_fn(|j| -(a.offset[j] as i32 + kappa[j]));
        Motion {
            coset: ci,
            offset: narrow(row_times(o, &self.cosets[ci as usize].r)),
        }
    }

    /// `δ(G)` in the internal frame: an element `x ↦ A·x + t` moves points by at least the
    /// length of `t`'s projection on the fixed space of `A` (the average of `A`'s powers),
    /// attained there; small offsets suffice because the lattice is reduced.
    fn least_displacement(&self) -> f64 {
        let mut best = f64::INFINITY;
        let span = 3i32;
        let side = (2 * span + 1) as usize;
        for (c, co) in self.cosets.iter().enumerate() {
            // the projection onto the fixed space of A
            let mut power = co.r;
            let mut sum = co.r;
            let mut order = 1;
            while power != std::array::from_fn(|i| std::array::from_fn(|j| (i == j) as i32)) {
                power = mat_mul(&power, &co.r);
                for i in 0..D {
                    for j in 0..D {
                        sum[i][j] += power[i][j];
                    }
                }
                order += 1;
            }
            for idx in 0..side.pow(D as u32) {
                let mut rem = idx;
                let o: [i32; D] = std::array::from_fn(|_| {
                    let v = (rem % side) as i32 - span;
                    rem /= side;
                    v
                });
                if c == 0 && o == [0; D] {
                    continue;
                }
                // the projection t·(Σ R^i)/order in lattice coordinates, then Cartesian
                let t: [i32; D] = std::array::from_fn(|i| co.shift[i] + self.q * o[i]);
                let frac = row_times(t, &sum).map(|x| x as f64 / order as f64);
                let proj = self.fine.lattice().cartesian_in(&frac);
                best = best.min(proj.iter().map(|x| x * x).sum::<f64>().sqrt());
            }
        }
        best
    }

    /// The last level: the manifold itself.
    fn quotient_level(&self) -> usize {
        self.ladder.len()
    }

    /// The squared radius `(δ/4)²` with the torus's safety margin.
    fn radius2_for(systole: f64) -> f64 {
        let r = systole / 4.0 * (1.0 - 1e-7);
        r * r
    }

    /// The position of a lifted point in the internal frame, rounded.
    fn position(&self, p: &[f64; D], g: Motion<D>) -> [f64; D] {
        self.fine.position(self.cartesian(self.lift((p, g))))
    }
}

type P<const D: usize> = [f64; D];

impl<const D: usize> FlatManifold<D> {
    /// The torus whose exact orientation, coincidence and order the stored frame uses.
    #[inline(always)]
    fn kernel(&self) -> &FlatTorus<D> {
        match &self.lattice_frame {
            None => &self.fine,
            Some(f) => &f.unit,
        }
    }

    /// The exact in-sphere sign of lifted points of the stored frame, `Zero` when
    /// cospherical.
    #[inline]
    fn in_sphere_unperturbed<const N: usize>(&self, s: &[L<D>; N], q: L<D>) -> Sign
    where
        FlatTorus<D>: UnperturbedInSphere<D, N>,
    {
        match &self.lattice_frame {
            None => self.fine.in_sphere_unperturbed(s, q),
            Some(f) => f.gram.in_sphere(&f.unit, s, q),
        }
    }
}

impl<const D: usize> FlatManifold<D> {
    /// The exact power test of lifted points of the stored frame, `Zero` when orthogonal.
    /// (In a lattice frame it is evaluated exactly, without a filter.)
    fn power_unperturbed<const N: usize>(
        &self,
        s: &[L<D>; N],
        ws: &[f64; N],
        q: L<D>,
        wq: f64,
    ) -> Sign {
        match &self.lattice_frame {
            None => self.fine.power_raw(s, ws, q, wq),
            Some(f) => f.gram.power_exact(&f.unit, s, ws, q, wq),
        }
    }

    /// The perturbation of a tie of the in-sphere or power test of `q` against `s` (lifted
    /// to `ls` and `lq`): one global order of lifted points, distinct points by their
    /// stored coordinates, copies of one point by [`Self::copy_order`].
    fn perturbed<const N: usize>(
        &self,
        s: &[(P<D>, Motion<D>); N],
        ls: &[L<D>; N],
        q: (P<D>, Motion<D>),
        lq: L<D>,
    ) -> Sign
    where
        FlatTorus<D>: OrbitSpace<N, Point = [f64; D], Elem = [i8; D]>,
    {
        let kernel = self.kernel();
        let at = |k: usize| if k == N { q } else { s[k] };
        perturbed_by(
            ls,
            lq,
            |t| kernel.orient(t),
            |a, b| {
                let ((pa, ga), (pb, gb)) = (at(a), at(b));
                match pa.partial_cmp(&pb) {
                    Some(std::cmp::Ordering::Equal) | None => self.copy_order(ga, gb),
                    Some(o) => Sign::from(o),
                }
            },
        )
    }

    /// The order of the copies `g·p` and `h·p` of one point (`Positive`: `g·p` comes
    /// after), which must not change when both are moved by an element `k`, so that every
    /// copy of a tie is broken alike. It depends on `x = g⁻¹∘h` alone (`k` cancels): `g·p`
    /// comes first when `x` is positive in the group's left order ([`LeftOrder`]). A group
    /// with none (the didicosm) orders copies by the coset of their element first, then by
    /// `x`, a translation, lexicographically: a total order all the same, invariant for
    /// ties among the translates of a copy (the ties of points in general position), and
    /// not for a tie among copies in different cosets (points at special positions of the
    /// screw axes), which [`crate::Triangulation::complex`] detects.
    fn copy_order(&self, g: Motion<D>, h: Motion<D>) -> Sign {
        let x = self.compose_elems(self.inverse_elem(g), h);
        match &self.order {
            Some(order) => {
                let c = &self.cosets[x.coset as usize];
                order
                    .sign(std::array::from_fn(|i| {
                        c.shift[i] + self.q * x.offset[i] as i32
                    }))
                    .flip()
            }
            None if g.coset != h.coset => Sign::from(g.coset.cmp(&h.coset)),
            None => Sign::from(x.offset.cmp(&self.inverse_elem(x).offset)).flip(),
        }
    }
}

impl<const D: usize, const N: usize> OrbitSpace<N> for FlatManifold<D>
where
    FlatTorus<D>: OrbitSpace<N, Point = [f64; D], Elem = [i8; D]> + UnperturbedInSphere<D, N>,
{
    type Point = [f64; D];
    type Elem = Motion<D>;

    #[inline]
    fn identity(&self) -> Motion<D> {
        Motion {
            coset: 0,
            offset: [0; D],
        }
    }

    #[inline]
    fn compose(&self, a: Motion<D>, b: Motion<D>) -> Motion<D> {
        self.compose_elems(a, b)
    }

    #[inline]
    fn inverse(&self, a: Motion<D>) -> Motion<D> {
        self.inverse_elem(a)
    }

    #[inline]
    fn relative(&self, a: Motion<D>, b: Motion<D>) -> Motion<D> {
        if b.coset == 0 {
            // b⁻¹ is a translation: the offsets subtract
            return Motion {
                coset: a.coset,
                offset: narrow(std::array::from_fn(|j| {
                    a.offset[j] as i32 - b.offset[j] as i32
                })),
            };
        }
        self.compose_elems(self.inverse_elem(b), a)
    }

    #[inline]
    fn carry(&self, from: Motion<D>, to: Motion<D>) -> Motion<D> {
        if from.coset == 0 && to.coset == 0 {
            return Motion {
                coset: 0,
                offset: narrow(std::array::from_fn(|j| {
                    to.offset[j] as i32 - from.offset[j] as i32
                })),
            };
        }
        self.compose_elems(to, self.inverse_elem(from))
    }

    fn translations_only(&self) -> bool {
        self.cosets.len() == 1
    }

    fn reverses_orientation(&self, g: Motion<D>) -> bool {
        self.cosets[g.coset as usize].reverses
    }

    fn euler_characteristic(&self) -> i64 {
        0
    }

    #[inline]
    fn orient(&self, s: &[(P<D>, Motion<D>); N]) -> Sign {
        let ls = self.lift_all(s);
        match &self.lattice_frame {
            None => self.fine.orient(&ls),
            Some(f) => f.unit.orient(&ls),
        }
    }

    fn in_sphere(&self, s: &[(P<D>, Motion<D>); N], q: (P<D>, Motion<D>)) -> Sign {
        let ls = self.lift_all(s);
        let lq = self.lift((&q.0, q.1));
        match self.in_sphere_unperturbed(&ls, lq) {
            Sign::Zero => self.perturbed(s, &ls, q, lq),
            sign => sign,
        }
    }

    fn cospherical(&self, s: &[(P<D>, Motion<D>); N], q: (P<D>, Motion<D>)) -> bool {
        self.in_sphere_unperturbed(&self.lift_all(s), self.lift((&q.0, q.1))) == Sign::Zero
    }

    fn coincide(&self, a: (P<D>, Motion<D>), b: (P<D>, Motion<D>)) -> bool {
        self.kernel()
            .coincide(self.lift((&a.0, a.1)), self.lift((&b.0, b.1)))
    }

    fn power_test(
        &self,
        s: &[(P<D>, Motion<D>); N],
        ws: &[f64; N],
        q: (P<D>, Motion<D>),
        wq: f64,
    ) -> Sign {
        let ls = self.lift_all(s);
        let lq = self.lift((&q.0, q.1));
        match self.power_unperturbed(&ls, ws, lq, wq) {
            Sign::Zero => self.perturbed(s, &ls, q, lq),
            sign => sign,
        }
    }

    fn orthogonal(
        &self,
        s: &[(P<D>, Motion<D>); N],
        ws: &[f64; N],
        q: (P<D>, Motion<D>),
        wq: f64,
    ) -> bool {
        self.power_unperturbed(&self.lift_all(s), ws, self.lift((&q.0, q.1)), wq) == Sign::Zero
    }

    fn ortho_distance2(&self, s: &[(P<D>, Motion<D>); N], ws: &[f64; N]) -> f64 {
        self.fine.ortho_distance2(&self.cartesian_all(s), ws)
    }

    fn orthocenter(&self, s: &[(P<D>, Motion<D>); N], ws: &[f64; N]) -> P<D> {
        self.fine.orthocenter(&self.cartesian_all(s), ws)
    }

    fn levels(&self) -> usize {
        self.ladder.len() + 1
    }

    fn criterion_radius2(&self, level: usize) -> f64 {
        if level == 0 {
            f64::INFINITY
        } else if level == self.quotient_level() {
            Self::radius2_for(self.systole)
        } else {
            Self::radius2_for(self.ladder[level].systole)
        }
    }

    fn single_lift_radius2(&self) -> f64 {
        4.0 * Self::radius2_for(self.systole)
    }

    fn covering_copies(&self, level: usize) -> Vec<Motion<D>> {
        if level == self.quotient_level() {
            return vec![OrbitSpace::<N>::identity(self)];
        }
        let offsets = self.ladder[level].sub.copies();
        (0..self.cosets.len() as u8)
            .flat_map(|coset| {
                offsets.iter().map(move |o| Motion {
                    coset,
                    offset: narrow(*o),
                })
            })
            .collect()
    }

    fn normalize(&self, off: &mut [Motion<D>; N], level: usize) -> bool {
        if level < self.quotient_level() {
            // a covering: translate by the sublattice, cosets stay
            let mut o = off.map(|g| g.offset);
            self.ladder[level].sub.normalize(&mut o);
            for (g, oi) in off.iter_mut().zip(o) {
                g.offset = oi;
            }
            return false;
        }
        let one = OrbitSpace::<N>::identity(self);
        if off.iter().all(|&g| g == one) {
            return false;
        }
        // the quotient: the canonical frame of the cell's elements
        let h = least_frame::<Self, N, ()>(self, &off.map(|g| ((), g)));
        if h == one {
            return false;
        }
        for g in off.iter_mut() {
            *g = self.compose_elems(h, *g);
        }
        self.cosets[h.coset as usize].reverses
    }

    fn dummy_points(&self) -> Vec<P<D>> {
        // a grid over T's domain fine enough for δ(G), of which the slab is kept (its images
        // fill the rest); T's internal frame is the manifold's divided by `scale` (exactly)
        let grid = self
            .translations
            .dummy_grid_for(self.systole / self.scale, self.slab_axis, self.cosets.len())
            .into_iter()
            .map(|p| p.map(|x| x * self.scale));
        match &self.lattice_frame {
            None => grid.collect(),
            Some(f) => grid
                .map(|p| {
                    let u = self.fine.lattice().fractional_in(&p);
                    std::array::from_fn(|j| (u[j] / f.quantum[j]).round() * f.quantum[j])
                })
                .collect(),
        }
    }

    fn sheets(&self, level: usize) -> usize {
        if level == self.quotient_level() {
            1
        } else {
            self.cosets.len() * self.ladder[level].sub.index()
        }
    }

    fn sheet_of(&self, g: Motion<D>, level: usize) -> usize {
        if level == self.quotient_level() {
            0
        } else {
            let sub = &self.ladder[level].sub;
            g.coset as usize * sub.index() + sub.sheet(g.offset.map(|x| x as i32))
        }
    }

    fn near(
        &self,
        z: (P<D>, Motion<D>),
        pts: &[P<D>],
        radius: f64,
        out: &mut Vec<(u32, Motion<D>)>,
    ) {
        let zc = self.position(&z.0, z.1);
        let lat = self.fine.lattice();
        let r = radius * (1.0 + 1e-9) + 1e-12 * self.systole;
        let q = self.q as f64;
        // how far a move of length r reaches in T's fractional coordinates (T's vectors are
        // q times the fine lattice's)
        let span = lat.fractional_reach(r).map(|x| x / q);
        for (i, p) in pts.iter().enumerate() {
            for coset in 0..self.cosets.len() as u8 {
                let base = self.position(
                    p,
                    Motion {
                        coset,
                        offset: [0; D],
                    },
                );
                let d: [f64; D] = std::array::from_fn(|c| zc[c] - base[c]);
                let f = lat.fractional_in(&d).map(|x| x / q);
                // offsets o with |f − o| ≤ span per axis; the slack covers the rounding of f
                let slack = 1e-6;
                let lo: [i32; D] = std::array::from_fn(|c| (f[c] - span[c] - slack).ceil() as i32);
                let side: [i32; D] =
                    std::array::from_fn(|c| (f[c] + span[c] + slack).floor() as i32 - lo[c] + 1);
                if side.iter().any(|&s| s <= 0) {
                    continue;
                }
                let total: usize = side.iter().map(|&s| s as usize).product();
                for idx in 0..total {
                    let mut rem = idx;
                    let mut o = [0i32; D];
                    for c in (0..D).rev() {
                        o[c] = lo[c] + (rem % side[c] as usize) as i32;
                        rem /= side[c] as usize;
                    }
                    let g = Motion {
                        coset,
                        offset: narrow(o),
                    };
                    let x = self.position(p, g);
                    let d2: f64 = (0..D).map(|c| (x[c] - zc[c]).powi(2)).sum();
                    if d2 <= r * r {
                        out.push((i as u32, g));
                    }
                }
            }
        }
    }

    fn edge_bound(&self, level: usize) -> f64 {
        if level == self.quotient_level() {
            self.systole / 2.0
        } else if level > 0 {
            self.ladder[level].systole / 2.0
        } else {
            // the largest empty ball one point's orbit leaves bounds every edge
            self.orbit_gap
        }
    }

    const KEY_BITS: u32 = if D == 3 { 63 } else { 32 };

    fn spatial_key(&self, p: &P<D>) -> u64 {
        let bits = if D == 3 { 21 } else { 16 };
        let f = match &self.lattice_frame {
            None => self.fine.lattice().fractional_in(p),
            Some(_) => *p,
        };
        let scale = (1u64 << bits) as f64;
        let cell: [u32; D] =
            f.map(|v| ((v / self.q as f64).clamp(0.0, 1.0) * scale).min(scale - 1.0) as u32);
        crate::sort::hilbert(cell, bits)
    }
}

impl<const D: usize, const N: usize> FlatSpace<D, N> for FlatManifold<D>
where
    FlatTorus<D>: OrbitSpace<N, Point = [f64; D], Elem = [i8; D]> + UnperturbedInSphere<D, N>,
{
    fn canonical_point(&self, x: &[f64; D]) -> Option<([f64; D], bool)> {
        self.canonical(*x)
    }

    fn to_user(&self, x: [f64; D]) -> [f64; D] {
        self.fine.lattice().to_user(x)
    }

    fn measure_to_user(&self, x: f64, power: i32) -> f64 {
        self.fine.lattice().measure_to_user(x, power)
    }

    fn lifted_position(&self, (p, g): (P<D>, Motion<D>)) -> [f64; D] {
        self.position(&p, g)
    }

    fn lifted_difference(&self, a: (P<D>, Motion<D>), b: (P<D>, Motion<D>)) -> [f64; D] {
        self.fine.lifted_difference(
            self.cartesian(self.lift((&a.0, a.1))),
            self.cartesian(self.lift((&b.0, b.1))),
        )
    }

    fn untwist(&self, g: Motion<D>, v: [f64; D]) -> [f64; D] {
        transpose_times(&self.cosets[g.coset as usize].linear, &v)
    }

    fn relating(&self, from: [f64; D], to: [f64; D]) -> Option<Motion<D>> {
        let lat = self.fine.lattice();
        let target = self.position(&to, self.identity_motion());
        (0..self.cosets.len() as u8).find_map(|coset| {
            let base = self.position(
                &from,
                Motion {
                    coset,
                    offset: [0; D],
                },
            );
            let d: [f64; D] = std::array::from_fn(|c| target[c] - base[c]);
            let o = lat.fractional_in(&d).map(|x| (x / self.q as f64).round());
            if o.iter().any(|x| x.abs() > 30.0) {
                return None;
            }
            let g = Motion {
                coset,
                offset: o.map(|x| x as i8),
            };
            self.kernel()
                .coincide(self.lift((&from, g)), (to, [0; D]))
                .then_some(g)
        })
    }

    fn face_frame(&self, pairs: &[(u32, Motion<D>)]) -> Motion<D> {
        least_frame::<Self, N, u32>(self, pairs)
    }

    fn weight_to_internal(&self, w: f64) -> f64 {
        self.fine.lattice().measure_to_internal(w, 2)
    }

    /// Equal weights only: a manifold's covering and criterion for a spread of weights
    /// are not derived (weighted points with a spread are for the flat tori).
    fn for_spread(&self, spread: f64) -> Option<Self> {
        (spread == 0.0).then(|| self.clone())
    }

    fn max_spread(&self) -> f64 {
        0.0
    }

    fn volume(&self) -> f64 {
        FlatManifold::volume(self)
    }

    fn check_volume_representable(&self) -> Result<()> {
        self.translations.check_volume_representable()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn klein() -> FlatManifold<2> {
        FlatManifold::klein_bottle(1.0, 1.0).unwrap()
    }

    #[test]
    fn the_group_law_of_the_klein_bottle() {
        let k = klein();
        let s = |g| OrbitSpace::<3>::identity(&k) == g;
        let glide = Motion {
            coset: 1,
            offset: [0, 0],
        };
        let g2 = k.compose_elems(glide, glide);
        assert_eq!(
            g2,
            Motion {
                coset: 0,
                offset: [1, 0]
            },
            "γ² is the translation (2, 0)"
        );
        let elems: Vec<Motion<2>> = (0..2u8)
            .flat_map(|c| {
                (-2..=2).flat_map(move |x| {
                    (-2..=2).map(move |y| Motion {
                        coset: c,
                        offset: [x, y],
                    })
                })
            })
            .collect();
        for &a in &elems {
            assert!(s(k.compose_elems(a, k.inverse_elem(a))));
            assert!(s(k.compose_elems(k.inverse_elem(a), a)));
            for &b in &elems {
                // the composition agrees with the isometries
                let (aa, ta) = k.isometry(a);
                let (ab, tb) = k.isometry(b);
                let (ac, tc) = k.isometry(k.compose_elems(a, b));
                for i in 0..2 {
                    for j in 0..2 {
                        assert_eq!(ac[i][j], (0..2).map(|m| aa[i][m] * ab[m][j]).sum::<f64>());
                    }
                    let t = (0..2).map(|m| aa[i][m] * tb[m]).sum::<f64>() + ta[i];
                    assert_eq!(tc[i], t);
                }
            }
        }
        assert!(!k.is_orientable());
        assert_eq!(k.systole(), 1.0);
        assert_eq!(k.volume(), 1.0);
        assert!(OrbitSpace::<3>::reverses_orientation(&k, glide));
    }

    #[test]
    fn canonical_points_lie_in_the_domain() {
        let k = klein();
        let (p, moved) = k.canonical([1.25, 0.25]).unwrap();
        assert!(moved);
        assert_eq!(k.fine.lattice().to_user(p), [0.25, 0.75]);
        let (p, moved) = k.canonical([0.5, 0.5]).unwrap();
        assert!(!moved);
        assert_eq!(k.fine.lattice().to_user(p), [0.5, 0.5]);
    }

    #[test]
    fn random_points_triangulate_the_klein_bottle() {
        let k = klein();
        let mut e = crate::Engine::<FlatManifold<2>, 3>::new(k.clone());
        let mut r = crate::sort::SplitMix::new(7);
        for n in 0..300 {
            let (p, _) = k.canonical([r.unit() * 3.0, r.unit() * 2.0 - 0.5]).unwrap();
            e.insert(p);
            if n < 40 || n % 50 == 0 {
                e.is_valid()
                    .unwrap_or_else(|x| panic!("after {} points: {x}", n + 1));
            }
        }
        assert!(e.is_one_sheeted());
        e.is_valid().unwrap();
        assert_eq!(e.number_of_cells(), 2 * 300);
    }

    /// The first homology group `G/[G, G]` of a presentation: free rank and torsion
    /// coefficients. Generators: the `D` lattice translations, then the cosets `1..k`;
    /// relations: conjugating a translation by a coset (`r_c t_i r_c⁻¹ = t^{R_c,i}`) and
    /// the product table (`r_a r_b = t^{κ(a,b)} r_{ab}`). Smith normal form by hand.
    fn homology<const D: usize>(m: &FlatManifold<D>) -> (usize, Vec<i64>) {
        let k = m.cosets.len();
        let n = D + k - 1;
        let col = |c: usize| D + c - 1;
        let mut rows: Vec<Vec<i64>> = Vec::new();
        for co in &m.cosets {
            for i in 0..D {
                let mut r = vec![0i64; n];
                for j in 0..D {
                    r[j] += co.r[i][j] as i64;
                }
                r[i] -= 1;
                rows.push(r);
            }
        }
        for a in 0..k {
            for b in 0..k {
                let (c, kappa) = m.product[a * k + b];
                let mut r = vec![0i64; n];
                for (slot, coset) in [(a, 1i64), (b, 1), (c as usize, -1)] {
                    if slot > 0 {
                        r[col(slot)] += coset;
                    }
                }
                for j in 0..D {
                    r[j] -= kappa[j] as i64;
                }
                rows.push(r);
            }
        }
        // Smith normal form: diagonalize by unimodular row and column operations
        let mut a = rows;
        let mut diag = Vec::new();
        let (mut top, mut left) = (0, 0);
        while top < a.len() && left < n {
            let pivot = (top..a.len())
                .flat_map(|i| (left..n).map(move |j| (i, j)))
                .filter(|&(i, j)| a[i][j] != 0)
                .min_by_key(|&(i, j)| a[i][j].abs());
            let Some((pi, pj)) = pivot else { break };
            a.swap(top, pi);
            for row in a.iter_mut() {
                row.swap(left, pj);
            }
            let p = a[top][left];
            let mut clean = true;
            for i in top + 1..a.len() {
                let q = a[i][left] / p;
                for j in left..n {
                    a[i][j] -= q * a[top][j];
                }
                clean &= a[i][left] == 0;
            }
            for j in left + 1..n {
                let q = a[top][j] / p;
                for i in top..a.len() {
                    a[i][j] -= q * a[i][left];
                }
                clean &= a[top][j] == 0;
            }
            if !clean {
                continue;
            }
            // the pivot must divide the rest, else fold a row into the pivot's and go on
            if let Some(i) = (top + 1..a.len()).find(|&i| (left + 1..n).any(|j| a[i][j] % p != 0)) {
                for j in left..n {
                    a[top][j] += a[i][j];
                }
                continue;
            }
            diag.push(p.abs());
            top += 1;
            left += 1;
        }
        let torsion: Vec<i64> = diag.iter().copied().filter(|&d| d > 1).collect();
        (n - diag.len(), torsion)
    }

    #[test]
    fn first_homology_names_each_space() {
        let b = [1.0, 1.0, 1.25];
        let expect: [(&str, usize, &[i64]); 10] = [
            ("torocosm", 3, &[]),
            ("dicosm", 1, &[2, 2]),
            ("tricosm", 1, &[3]),
            ("tetracosm", 1, &[2]),
            ("hexacosm", 1, &[]),
            ("didicosm", 0, &[4, 4]),
            ("first-amphicosm", 2, &[2]),
            ("second-amphicosm", 2, &[]),
            ("first-amphidicosm", 1, &[2, 2]),
            ("second-amphidicosm", 1, &[4]),
        ];
        for (name, rank, torsion) in expect {
            let m = FlatManifold::platycosm(name, b).unwrap();
            assert_eq!(homology(&m), (rank, torsion.to_vec()), "{name}");
        }
        assert_eq!(homology(&klein()), (1, vec![2]), "klein");
    }

    /// The sign of an element under the space's left order.
    fn sign_of<const D: usize>(m: &FlatManifold<D>, g: Motion<D>) -> Sign {
        let c = &m.cosets[g.coset as usize];
        let tau = std::array::from_fn(|i| c.shift[i] + m.q * g.offset[i] as i32);
        m.order.as_ref().expect("a left order").sign(tau)
    }

    /// Random elements of `m` with small offsets.
    fn elements<const D: usize>(m: &FlatManifold<D>, n: usize) -> Vec<Motion<D>> {
        let mut r = crate::sort::SplitMix::new(5);
        (0..n)
            .map(|_| Motion {
                coset: (r.unit() * m.cosets.len() as f64) as u8,
                offset: std::array::from_fn(|_| (r.unit() * 7.0) as i8 - 3),
            })
            .collect()
    }

    /// A left order: total (only the identity has sign zero), `x` and `x⁻¹` of opposite
    /// signs, positives closed under products; and `copy_order` keeps the order of two
    /// copies under every element.
    fn check_left_order<const D: usize, const N: usize>(m: &FlatManifold<D>, what: &str)
    where
        FlatManifold<D>: OrbitSpace<N, Elem = Motion<D>>,
    {
        let els = elements(m, 40);
        let one = OrbitSpace::<N>::identity(m);
        assert_eq!(sign_of(m, one), Sign::Zero, "{what}");
        for &x in &els {
            let sx = sign_of(m, x);
            assert_eq!(sx == Sign::Zero, x == one, "{what}: {x:?}");
            assert_eq!(
                sign_of(m, OrbitSpace::<N>::inverse(m, x)),
                sx.flip(),
                "{what}: {x:?}"
            );
            for &y in &els {
                let xy = OrbitSpace::<N>::compose(m, x, y);
                if sx == Sign::Positive && sign_of(m, y) == Sign::Positive {
                    assert_eq!(sign_of(m, xy), Sign::Positive, "{what}: {x:?}·{y:?}");
                }
                let order = m.copy_order(x, y);
                assert_eq!(order == Sign::Zero, x == y, "{what}");
                assert_eq!(m.copy_order(y, x), order.flip(), "{what}");
                for &k in &els[..8] {
                    let (kx, ky) = (m.compose_elems(k, x), m.compose_elems(k, y));
                    assert_eq!(m.copy_order(kx, ky), order, "{what}: moved by {k:?}");
                }
            }
        }
    }

    #[test]
    fn every_group_but_the_didicosm_has_a_left_order() {
        check_left_order::<2, 3>(&klein(), "klein");
        for name in FlatManifold::PLATYCOSMS {
            let m = FlatManifold::platycosm(name, [1.0, 1.0, 1.25]).unwrap();
            if name == "didicosm" {
                assert!(
                    m.order.is_none(),
                    "the Hantzsche–Wendt group is not left-orderable"
                );
            } else {
                check_left_order::<3, 4>(&m, name);
            }
        }
    }

    #[test]
    fn presentations_that_are_no_group_are_refused() {
        let bad = FlatManifold::new(
            "bad",
            [[2.0, 0.0], [0.0, 1.0]],
            2,
            &[
                Coset {
                    linear: [[1, 0], [0, 1]],
                    shift: [0, 0],
                },
                // a reflection without glide fixes the line y = 0
                Coset {
                    linear: [[1, 0], [0, -1]],
                    shift: [0, 0],
                },
            ],
            0,
        );
        assert!(bad.is_err());
    }
}
