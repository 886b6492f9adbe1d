//! How a space appears in the output formats: its description in JSON and its group elements
//! as JSON values and as integer columns. A torus writes its lattice and its offsets, a
//! closed flat manifold its name, its group and each element as an isometry `[A, t]`.

use super::write::json_point;
use crate::space::{FlatManifold, FlatSpace, FlatTorus, Motion};

/// A flat space as the writers see it.
pub trait SpaceFormat<const D: usize, const N: usize>: FlatSpace<D, N> {
    /// The JSON key of the cells' elements: `"offsets"` for a torus, `"elements"` otherwise.
    const CELL_ELEMENTS: &'static str;
    /// The JSON key of a Voronoi face's element: `"shift"` for a torus, `"element"` otherwise.
    const FACE_ELEMENT: &'static str;

    /// The JSON members that describe the space, without braces: a torus's `"lattice"`, a
    /// manifold's `"space"` and `"group"`.
    fn json_space(&self) -> String;
    /// An element as a JSON value: a torus's offset `[1,0,-1]`, a manifold's isometry
    /// `[A, t]` (`x ↦ A·x + t`, `A` as rows).
    fn json_element(&self, g: Self::Elem) -> String;
    /// The names of an element's integer columns in tables: `shift_x, shift_y[, shift_z]`
    /// for a torus, `coset, offset_x, offset_y[, offset_z]` otherwise.
    fn element_columns() -> Vec<String>;
    /// An element's integers, in the order of [`Self::element_columns`].
    fn element_integers(g: Self::Elem) -> impl Iterator<Item = i32>;
}

const AXES: [&str; 3] = ["x", "y", "z"];

/// `PREFIX_x, PREFIX_y[, PREFIX_z]`.
fn axis_columns<const D: usize>(prefix: &str) -> Vec<String> {
    AXES[..D].iter().map(|a| format!("{prefix}_{a}")).collect()
}

/// Vectors as a JSON array of arrays of numbers.
pub(super) fn json_rows<const D: usize>(rows: &[[f64; D]]) -> String {
    let all: Vec<String> = rows.iter().map(|r| json_point(r)).collect();
    format!("[{}]", all.join(","))
}

impl<const D: usize, const N: usize> SpaceFormat<D, N> for FlatTorus<D>
where
    FlatTorus<D>: FlatSpace<D, N, Elem = [i8; D]>,
{
    const CELL_ELEMENTS: &'static str = "offsets";
    const FACE_ELEMENT: &'static str = "shift";

    fn json_space(&self) -> String {
        format!("\"lattice\":{}", json_rows(&self.lattice().vectors()))
    }

    fn json_element(&self, g: [i8; D]) -> String {
        format!("{g:?}").replace(' ', "")
    }

    fn element_columns() -> Vec<String> {
        axis_columns::<D>("shift")
    }

    fn element_integers(g: [i8; D]) -> impl Iterator<Item = i32> {
        g.into_iter().map(i32::from)
    }
}

/// An isometry `x ↦ A·x + t` as `[A, t]`; `A`'s integer entries (all of a signed
/// permutation's) are written as integers, the others (`±√3/2` in a hexagonal turn) as
/// doubles.
fn json_isometry<const D: usize>((a, t): ([[f64; D]; D], [f64; D])) -> String {
    let entry = |x: f64| {
        if x == x.trunc() {
            format!("{}", x as i64)
        } else {
            format!("{x:?}")
        }
    };
    let rows: Vec<String> = a
        .iter()
        .map(|r| format!("[{}]", r.map(entry).join(",")))
        .collect();
    format!("[[{}],{}]", rows.join(","), json_point(&t))
}

impl<const D: usize, const N: usize> SpaceFormat<D, N> for FlatManifold<D>
where
    FlatManifold<D>: FlatSpace<D, N, Elem = Motion<D>>,
{
    const CELL_ELEMENTS: &'static str = "elements";
    const FACE_ELEMENT: &'static str = "element";

    /// `"space":NAME,"group":{"generators":[[A,t],…],"translations":[rows]}`: the `D`
    /// lattice translations, then the representatives of cosets `1…k−1`.
    fn json_space(&self) -> String {
        let generators: Vec<String> = self.generators().into_iter().map(json_isometry).collect();
        format!(
            "\"space\":\"{}\",\"group\":{{\"generators\":[{}],\"translations\":{}}}",
            self.name(),
            generators.join(","),
            json_rows(&self.translations().vectors())
        )
    }

    fn json_element(&self, g: Motion<D>) -> String {
        json_isometry(self.isometry(g))
    }

    fn element_columns() -> Vec<String> {
        let mut c = vec!["coset".to_string()];
        c.extend(axis_columns::<D>("offset"));
        c
    }

    fn element_integers(g: Motion<D>) -> impl Iterator<Item = i32> {
        std::iter::once(i32::from(g.coset)).chain(g.offset.into_iter().map(i32::from))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn elements_as_json_and_integers() {
        let klein = FlatManifold::klein_bottle(0.5, 1.0).unwrap();
        let glide = Motion {
            coset: 1,
            offset: [1, -1],
        };
        assert_eq!(
            SpaceFormat::<2, 3>::json_element(&klein, glide),
            "[[[1,0],[0,-1]],[1.5,-1.0]]"
        );
        let ints: Vec<i32> =
            <FlatManifold<2> as SpaceFormat<2, 3>>::element_integers(glide).collect();
        assert_eq!(ints, [1, 1, -1]);
        assert_eq!(
            <FlatManifold<2> as SpaceFormat<2, 3>>::element_columns(),
            ["coset", "offset_x", "offset_y"]
        );
        assert_eq!(
            SpaceFormat::<2, 3>::json_space(&klein),
            "\"space\":\"klein\",\"group\":{\"generators\":[[[[1,0],[0,1]],[1.0,0.0]],\
             [[[1,0],[0,1]],[0.0,1.0]],[[[1,0],[0,-1]],[0.5,0.0]]],\
             \"translations\":[[1.0,0.0],[0.0,1.0]]}"
        );
        let torus = FlatTorus::<3>::cuboid([1.0, 2.0, 3.0]).unwrap();
        assert_eq!(
            SpaceFormat::<3, 4>::json_element(&torus, [1, 0, -2]),
            "[1,0,-2]"
        );
        assert_eq!(
            <FlatTorus<3> as SpaceFormat<3, 4>>::element_columns(),
            ["shift_x", "shift_y", "shift_z"]
        );
    }
}
