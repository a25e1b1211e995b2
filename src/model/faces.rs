//! The six faces of a die: which end of which body axis points up when it has come to rest,
//! and the numbers the faces carry. The three outcomes of the paper (which side stands
//! vertical) are the faces taken in opposite pairs; a face tells which of the pair is up.

use crate::error::Field;
use crate::model::block::Side;
use crate::model::state::up_in_body;
use nalgebra::UnitQuaternion;
use serde::{Deserialize, Serialize};

/// The body directions whose faces can be up, in the order every count of faces keeps:
/// +x, −x (the breadth axis), +y, −y (width), +z, −z (length).
pub const DIRECTIONS: [&str; 6] = ["+x", "-x", "+y", "-y", "+z", "-z"];

/// How the numbers 1 to 6 sit on the faces.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, strum::EnumString)]
#[serde(rename_all = "kebab-case")]
#[strum(serialize_all = "kebab-case")]
pub enum Layout {
    /// Western dice: 1 on +z, 6 on −z, 2 on +x, 5 on −x, 3 on +y, 4 on −y. Opposite faces sum
    /// to seven, and 1, 2, 3 run counter-clockwise about their shared corner (+x, +y, +z) seen
    /// from outside it (the body axes are right-handed: seen down the diagonal, x, y and z
    /// follow each other counter-clockwise).
    #[default]
    Right,
    /// Its mirror image (2 and 3 swapped, so 5 and 4): 1, 2, 3 clockwise, as on some dice.
    Left,
    /// Any other map (a die file's `faces`): the number on each direction's face, in
    /// [`DIRECTIONS`]' order, a permutation of 1 to 6.
    #[strum(disabled)]
    Map([u8; 6]),
}

/// The layouts a name gives (a map is a die file's, never a name: reliability round 5,
/// class G, "unknown layout 'map' (known: right, left, map)").
impl strum::VariantNames for Layout {
    const VARIANTS: &'static [&'static str] = &["right", "left"];
}

impl std::fmt::Display for Layout {
    /// "right", "left", or the map as "+x=2 -x=5 +y=3 -y=4 +z=1 -z=6".
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Layout::Right => f.write_str("right"),
            Layout::Left => f.write_str("left"),
            Layout::Map(n) => {
                let parts: Vec<String> = DIRECTIONS
                    .iter()
                    .zip(n)
                    .map(|(d, k)| format!("{d}={k}"))
                    .collect();
                f.write_str(&parts.join(" "))
            }
        }
    }
}

impl Layout {
    /// The layout whose numbers are these (each direction's, in [`DIRECTIONS`]' order): the
    /// named one where it is one; `None` unless they are 1 to 6, each once.
    pub fn from_numbers(numbers: [u8; 6]) -> Option<Layout> {
        let mut sorted = numbers;
        sorted.sort_unstable();
        if sorted != [1, 2, 3, 4, 5, 6] {
            return None;
        }
        Some(
            [Layout::Right, Layout::Left]
                .into_iter()
                .find(|l| l.numbers() == numbers)
                .unwrap_or(Layout::Map(numbers)),
        )
    }

    /// The number on each direction's face, in [`DIRECTIONS`]' order.
    pub fn numbers(self) -> [u8; 6] {
        match self {
            Layout::Right => [2, 5, 3, 4, 1, 6],
            Layout::Left => [3, 4, 2, 5, 1, 6],
            Layout::Map(n) => n,
        }
    }

    /// The layout a face map gives: each of the six directions ("+x" … "-z") a number, the
    /// numbers a permutation of 1 to 6; the named layout when it is one.
    pub fn from_map(map: &std::collections::BTreeMap<String, u8>) -> crate::Result<Layout> {
        let bad = |why: String| Err(crate::Error::field(Field::Faces, "", why));
        let mut numbers = [0u8; 6];
        for (d, n) in map {
            let Some(i) = DIRECTIONS.iter().position(|x| x == d) else {
                return bad(format!(
                    "'{d}' is not a face: name each of +x, -x, +y, -y, +z, -z"
                ));
            };
            numbers[i] = *n;
        }
        let mut sorted = numbers;
        sorted.sort_unstable();
        if map.len() != 6 || sorted != [1, 2, 3, 4, 5, 6] {
            return bad(format!(
                "{}: must give each of +x, -x, +y, -y, +z, -z one of the numbers 1 to 6, each \
                 number once",
                Layout::Map(numbers)
            ));
        }
        Ok([Layout::Right, Layout::Left]
            .into_iter()
            .find(|l| l.numbers() == numbers)
            .unwrap_or(Layout::Map(numbers)))
    }

    /// The direction (index into [`DIRECTIONS`]) whose face carries `number`.
    pub fn direction_of(self, number: u8) -> Option<usize> {
        self.numbers().iter().position(|&n| n == number)
    }
}

/// How a roll came to rest, for every die: on one of its faces, or on none. The face is its
/// index among the die's outcomes: a cuboid's by the direction of its face up
/// ([`DIRECTIONS`]; four in 2D), a die of any shape's in the order of its faces
/// (`Shape::faces`, a box-shaped one's too). What it shows is the die's to say (its layout's
/// number, its label); the paper's view of a cuboid's outcome, the side standing vertical, is
/// [`Outcome::side`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Outcome {
    /// At rest on one of its faces: the face's index among the die's outcomes.
    Face(u8),
    /// At rest on none: no face down within the tolerance (on an edge, or leaning).
    Unknown,
}

impl Outcome {
    /// The face's index, if it came to rest on one.
    pub fn face(self) -> Option<u8> {
        match self {
            Outcome::Face(k) => Some(k),
            Outcome::Unknown => None,
        }
    }

    /// A cuboid's outcome as the paper sees it: the side standing vertical when the face of
    /// direction `d` is up. Only a cuboid's faces are directions; a die of any shape has no
    /// sides.
    pub fn side(self) -> Side {
        match self {
            Outcome::Face(d) => side_of(usize::from(d)),
            Outcome::Unknown => Side::Unknown,
        }
    }
}

/// The direction (index into [`DIRECTIONS`]) whose face is up on a die at `rotation` whose
/// `side` axis stands vertical: that axis's positive end if it points up, else its negative
/// end. `None` when no side is vertical.
pub fn up_direction(rotation: &UnitQuaternion<f64>, side: Side) -> Option<u8> {
    let axis = match side {
        Side::Breadth => 0,
        Side::Width => 1,
        Side::Length => 2,
        Side::Unknown => return None,
    };
    let up = up_in_body(rotation);
    Some(2 * axis + u8::from(up[axis as usize] < 0.0))
}

/// The side standing vertical when the face of direction `d` is up.
pub fn side_of(d: usize) -> Side {
    match d / 2 {
        0 => Side::Breadth,
        1 => Side::Width,
        _ => Side::Length,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    #[test]
    fn opposite_faces_sum_to_seven_and_one_two_three_turn_as_the_layout_says() {
        for layout in [Layout::Right, Layout::Left] {
            let n = layout.numbers();
            let mut sorted = n;
            sorted.sort();
            assert_eq!(sorted, [1, 2, 3, 4, 5, 6]);
            for k in 0..3 {
                assert_eq!(n[2 * k] + n[2 * k + 1], 7, "{layout}");
            }
            // The outward normals of 1, 2 and 3: their triple product is positive when they
            // run counter-clockwise seen from outside their shared corner.
            let normal = |number: u8| {
                let d = layout.direction_of(number).unwrap();
                let mut v = Vector3::zeros();
                v[d / 2] = if d % 2 == 0 { 1.0 } else { -1.0 };
                v
            };
            let turn = normal(1).dot(&normal(2).cross(&normal(3)));
            assert_eq!(turn > 0.0, layout == Layout::Right, "{layout}: {turn}");
        }
    }

    #[test]
    fn a_face_map_is_a_permutation_of_one_to_six() {
        let map = |pairs: &[(&str, u8)]| {
            pairs
                .iter()
                .map(|(d, n)| (d.to_string(), *n))
                .collect::<std::collections::BTreeMap<_, _>>()
        };
        let right = [
            ("+x", 2),
            ("-x", 5),
            ("+y", 3),
            ("-y", 4),
            ("+z", 1),
            ("-z", 6),
        ];
        assert_eq!(Layout::from_map(&map(&right)).unwrap(), Layout::Right);
        // 1 and 2 swapped: no longer opposite faces summing to seven, but a die all the same.
        let odd = [
            ("+x", 1),
            ("-x", 5),
            ("+y", 3),
            ("-y", 4),
            ("+z", 2),
            ("-z", 6),
        ];
        let l = Layout::from_map(&map(&odd)).unwrap();
        assert_eq!(l.numbers(), [1, 5, 3, 4, 2, 6]);
        assert_eq!(l.direction_of(2), Some(4));
        assert_eq!(l.to_string(), "+x=1 -x=5 +y=3 -y=4 +z=2 -z=6");
        let twice = [
            ("+x", 1),
            ("-x", 1),
            ("+y", 3),
            ("-y", 4),
            ("+z", 2),
            ("-z", 6),
        ];
        let e = Layout::from_map(&map(&twice)).unwrap_err().to_string();
        assert!(e.contains("each number once"), "{e}");
        let e = Layout::from_map(&map(&[("up", 1)]))
            .unwrap_err()
            .to_string();
        assert!(e.contains("'up' is not a face"), "{e}");
    }

    #[test]
    fn the_face_up_is_the_end_of_the_vertical_axis_that_points_up() {
        // At the identity, body y is world up: the +y face (3) is up.
        let id = UnitQuaternion::identity();
        assert_eq!(up_direction(&id, Side::Width), Some(2));
        // Turned half a turn about x: −y up (4).
        let flip = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI);
        assert_eq!(up_direction(&flip, Side::Width), Some(3));
        // A quarter turn about x takes +z to world +y... (R ẑ = −ŷ for +90°, so −z is up).
        let quarter =
            UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::FRAC_PI_2);
        let up_z = (quarter * Vector3::z()).y;
        let d = up_direction(&quarter, Side::Length).unwrap();
        assert_eq!(d == 4, up_z > 0.0, "{d} {up_z}");
        assert_eq!(up_direction(&id, Side::Unknown), None);
        assert_eq!(side_of(5), Side::Length);
    }
}
