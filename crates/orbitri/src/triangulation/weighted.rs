//! Weighted points: the regular (weighted Delaunay) triangulation, whose dual is the power
//! (Laguerre) diagram. A weight is a squared length (a radius `r` gives `r²`); the power
//! test replaces the in-sphere test, and a point whose power cell is empty is *hidden*: it
//! has no vertex, is kept, and comes back when a removal uncovers it. Every input is a
//! vertex, a duplicate (same position and weight), or hidden.

use std::ops::ControlFlow;

use super::{internal_points, BuildOptions, Triangulation, HIDDEN};
use crate::delaunay::{Engine, Inserted};
use crate::error::{Error, Result};
use crate::ids::{InputId, PointId};
use crate::space::FlatSpace;

impl<const D: usize, const N: usize, S: FlatSpace<D, N>> Triangulation<D, N, S> {
    /// An empty weighted triangulation of the space (its weights all equal until points
    /// come; see [`Self::insert_weighted`]).
    pub fn new_weighted(space: S) -> Self {
        let mut tri = Self::new(space.clone());
        tri.engine = Engine::new_weighted(space);
        tri
    }

    /// The regular triangulation of `points` with `weights` (squared lengths, one per
    /// point, user units). Bad weights (not finite, or out of the box's range), a weight
    /// count other than the point count, or weights spread too widely for any covering of
    /// the box (see [`crate::FlatTorus::for_spread`]) are errors naming the point.
    ///
    /// ```
    /// use orbitri::{FlatTorus2, InputId, PeriodicDelaunay2};
    /// let pts = [[0.1, 0.1], [0.6, 0.2], [0.3, 0.7], [0.62, 0.21], [0.8, 0.8]];
    /// // the fourth point lies inside the second's large circle: hidden
    /// let weights = [0.0, 0.04, 0.0, 0.0, 0.0];
    /// let torus = FlatTorus2::cuboid([1.0, 1.0]).unwrap();
    /// let tri = PeriodicDelaunay2::build_weighted(torus, &pts, &weights).unwrap();
    /// assert_eq!(tri.hidden(), vec![InputId(3)]);
    /// assert_eq!(tri.number_of_vertices(), 4);
    /// assert!(tri.is_valid().is_ok());
    /// ```
    pub fn build_weighted(space: S, points: &[[f64; D]], weights: &[f64]) -> Result<Self> {
        Self::build_weighted_with(space, points, weights, BuildOptions::default(), |_| {
            ControlFlow::Continue(())
        })
    }

    /// [`Self::build_weighted`] with options and a progress callback (as
    /// [`Self::build_with`]).
    pub fn build_weighted_with(
        space: S,
        points: &[[f64; D]],
        weights: &[f64],
        opts: BuildOptions,
        progress: impl FnMut(usize) -> ControlFlow<()>,
    ) -> Result<Self> {
        if weights.len() != points.len() {
            return Err(Error::WeightCount {
                points: points.len(),
                weights: weights.len(),
            });
        }
        let internal = internal_weights(&space, weights, 0)?;
        let mut tri = Self::new_weighted(space);
        tri.input_weight = weights.to_vec();
        tri.widen(&internal, 0)?;
        Self::build_inner(tri, points, &internal, opts, progress)
    }

    /// This triangulation's kind (weighted or not, space and spread) without points.
    pub(super) fn emptied(&self) -> Self {
        let mut tri = Self::new(self.space().clone());
        tri.engine.set_threads(self.engine.threads());
        if self.engine.is_weighted() {
            tri.engine = Engine::new_weighted(self.space().clone());
            tri.engine.weight_max = self.engine.weight_max;
            tri.input_weight = self.input_weight.clone();
            tri.weight_range = self.weight_range;
        }
        tri
    }

    /// The spread of the weights given (largest − least, internal frame; 0 for none): the
    /// space's coverings are for it, since the range only grows and the space follows.
    fn spread(&self) -> f64 {
        let (lo, hi) = self.weight_range;
        (hi - lo).max(0.0)
    }

    /// Takes the internal weights `w` (of inputs `first..`) into the weight range: when the
    /// spread grows, the space is replaced by one for the new spread (the triangulation, if
    /// any, moves to its coverings). An error names the input that spreads the weights too
    /// far, and changes nothing.
    fn widen(&mut self, w: &[f64], first: usize) -> Result<()> {
        let (mut lo, mut hi) = self.weight_range;
        for &x in w {
            lo = lo.min(x);
            hi = hi.max(x);
        }
        if w.is_empty() || hi - lo <= self.spread() {
            (self.weight_range, self.engine.weight_max) =
                ((lo, hi), hi.max(self.engine.weight_max));
            return Ok(());
        }
        let spread = hi - lo;
        let Some(space) = self.space().for_spread(spread) else {
            // the weight farthest from the others' mean
            let mean = w.iter().sum::<f64>() / w.len() as f64;
            let (k, &x) = w
                .iter()
                .enumerate()
                .max_by(|a, b| (a.1 - mean).abs().total_cmp(&(b.1 - mean).abs()))
                .expect("a weight");
            let user = |x: f64| self.space().weight_to_user(x);
            if self.space().max_spread() == 0.0 {
                return Err(Error::BadWeight {
                    index: first + k,
                    what: "weight",
                    value: user(x),
                    why: "differs from the others: weights in this space must be equal (a spread of weights is for the flat tori)".into(),
                });
            }
            return Err(Error::WeightSpread {
                index: first + k,
                value: user(x),
                spread: user(spread),
                limit: user(self.space().max_spread()),
            });
        };
        self.weight_range = (lo, hi);
        self.engine.weight_max = hi.max(self.engine.weight_max);
        self.engine.replace_space(space);
        Ok(())
    }

    /// Inserts one more point of weight `w` (a squared length, user units; ignored when
    /// the triangulation is unweighted): a new point, a duplicate of a point of the same
    /// position and weight, or hidden ([`Inserted::Hidden`]); the points it hides are
    /// listed by [`Self::hidden`] from then on. An error (a bad coordinate or weight, a
    /// spread too wide) changes nothing.
    pub fn insert_weighted(&mut self, p: [f64; D], w: f64) -> Result<Inserted> {
        let i = self.input_point.len();
        let (x, moved) = super::internal_point(self.space(), i, &p)?;
        let mut wi = 0.0;
        if self.engine.is_weighted() {
            wi = internal_weights(self.space(), &[w], i)?[0];
            self.widen(&[wi], i)?;
            self.input_weight.push(w);
        }
        self.wrapped += moved as usize;
        self.input_point.push(PointId::NONE);
        Ok(self.insert_wrapped(InputId::new(i), x, wi))
    }

    /// [`Self::insert_all`] with weights (one per point, user units; ignored when the
    /// triangulation is unweighted, and may be empty then). All or nothing: an error names
    /// the first bad point or weight.
    pub fn insert_all_weighted(
        &mut self,
        points: &[[f64; D]],
        weights: &[f64],
    ) -> Result<Vec<Inserted>> {
        let first = self.input_point.len();
        let (internal, moved) = internal_points(self.space(), points)?;
        let mut wi = Vec::new();
        if self.engine.is_weighted() {
            if weights.len() != points.len() {
                return Err(Error::WeightCount {
                    points: points.len(),
                    weights: weights.len(),
                });
            }
            wi = internal_weights(self.space(), weights, first)?;
            self.widen(&wi, first)?;
            self.input_weight.extend_from_slice(weights);
        }
        self.wrapped += moved;
        Ok(self.insert_all_internal(&internal, &wi))
    }

    /// True for a regular (weighted) triangulation.
    pub fn is_weighted(&self) -> bool {
        self.engine.is_weighted()
    }

    /// Each input's weight in user units (empty when unweighted; a removed input keeps
    /// its entry).
    pub fn weights(&self) -> &[f64] {
        &self.input_weight
    }

    /// The hidden inputs, sorted: their power cells are empty, they have no vertex.
    pub fn hidden(&self) -> Vec<InputId> {
        self.hidden.keys().copied().collect()
    }

    /// True when input `i` is hidden.
    pub fn is_hidden(&self, i: InputId) -> bool {
        self.hidden.contains_key(&i)
    }

    /// The internal weight of input `i` (0 when unweighted).
    pub(super) fn internal_weight(&self, i: InputId) -> f64 {
        match self.input_weight.get(i.index()) {
            Some(&w) => self.space().weight_to_internal(w),
            None => 0.0,
        }
    }

    /// Input `i` (internal point `p`, weight `w`) is hidden.
    pub(super) fn record_hidden(&mut self, i: InputId, p: [f64; D], w: f64) {
        self.input_point[i.index()] = HIDDEN;
        self.hidden.insert(i, (p, w));
    }

    /// The points the engine's last insertions hid: their inputs become hidden, and the
    /// point ids follow the engine's renumbering (the last point takes each one's id).
    pub(super) fn absorb_hidden(&mut self) {
        for h in std::mem::take(&mut self.engine.hidden_log) {
            let inputs: Vec<usize> = if self.duplicates == 0 {
                vec![self.point_input[h.id.index()].index()]
            } else {
                (0..self.input_point.len())
                    .filter(|&j| self.input_point[j] == h.id)
                    .collect()
            };
            self.duplicates -= inputs.len() - 1;
            for j in inputs {
                self.record_hidden(InputId::new(j), h.point, h.weight);
            }
            self.forget_point(h.id);
        }
    }

    /// The hidden inputs that removing point `p` may uncover: a point whose power cell
    /// becomes non-empty lies in one of the new cells, which fill `p`'s star, and the star
    /// lies within the ball around `p` reaching its farthest neighbour (each of its cells is
    /// the hull of `p` and neighbours). Sorted.
    pub(super) fn hidden_near(&self, p: PointId) -> Vec<InputId> {
        if self.hidden.is_empty() {
            return Vec::new();
        }
        let e = &self.engine;
        let space = self.space();
        let at = (e.points()[p.index()], space.identity());
        let reach = e
            .neighbours(e.vertex_of_point(p))
            .into_iter()
            .map(|(w, g)| {
                let d = space.lifted_difference((e.points()[e.point_of(w).index()], g), at);
                d.iter().map(|x| x * x).sum::<f64>().sqrt()
            })
            .fold(0.0, f64::max);
        let (ids, pts): (Vec<InputId>, Vec<[f64; D]>) =
            self.hidden.iter().map(|(&i, &(x, _))| (i, x)).unzip();
        let mut near = Vec::new();
        space.near(at, &pts, reach, &mut near);
        let mut out: Vec<InputId> = near.into_iter().map(|(k, _)| ids[k as usize]).collect();
        out.dedup();
        out
    }

    /// After removals: inserts again every hidden point whose power cell is no longer
    /// empty (each insertion can only hide more, so one pass in input order suffices).
    pub(super) fn uncover(&mut self) {
        let ids: Vec<InputId> = self.hidden.keys().copied().collect();
        self.uncover_among(ids);
    }

    /// [`Self::uncover`] for the hidden inputs `ids` only (sorted).
    pub(super) fn uncover_among(&mut self, ids: Vec<InputId>) {
        for i in ids {
            let Some(&(x, w)) = self.hidden.get(&i) else {
                continue;
            };
            if self.engine.would_appear(x, w) {
                self.hidden.remove(&i);
                self.insert_wrapped(i, x, w);
            }
        }
    }
}

/// The weights in the internal frame; an error names the first that is not finite or
/// that the frame cannot hold (input ids from `first`).
fn internal_weights<const D: usize, const N: usize, S: FlatSpace<D, N>>(
    space: &S,
    weights: &[f64],
    first: usize,
) -> Result<Vec<f64>> {
    weights
        .iter()
        .enumerate()
        .map(|(k, &w)| {
            let bad = |why: &str| Error::BadWeight {
                index: first + k,
                what: "weight",
                value: w,
                why: why.into(),
            };
            if !w.is_finite() {
                return Err(bad("is not a finite number"));
            }
            let x = space.weight_to_internal(w);
            if !x.is_finite() {
                return Err(bad(
                    "is too large for the box (weights are squared lengths)",
                ));
            }
            Ok(x)
        })
        .collect()
}
