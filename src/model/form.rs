//! The die's form, as a scene holds it: the paper's cuboid, given by its sides, or a die of
//! any shape (`model::shape`), given by its solid and its labelled faces. One field, so that
//! a die of any shape has no block beside it to disagree with: its block is its bounding box,
//! derived when asked.

use crate::model::block::Block;
use crate::model::faces::Layout;
use crate::model::shape::{Shape, Solid};
use std::sync::Arc;

/// The die's form.
#[derive(Clone, Debug, PartialEq)]
pub enum Form {
    /// The paper's cuboid: its sides. Its faces are numbered by the scene's layout
    /// (`Features::layout`) and counted, as the paper counts them, by the side standing
    /// vertical (`faces::Outcome::side`).
    Cuboid(Block),
    /// A die of any shape, a box-shaped one (a d6, a box-shaped mesh) too: its solid, its
    /// faces and their labels, counted by label.
    Shape(Arc<Shape>),
}

impl Form {
    /// A die of any shape.
    pub fn shape(shape: Shape) -> Form {
        Form::Shape(Arc::new(shape))
    }

    /// The cuboid's sides, or a die of any shape's bounding box (what reads the die's size:
    /// the drop, the reports, a box-shaped die's closed forms).
    pub fn block(&self) -> Block {
        match self {
            Form::Cuboid(b) => *b,
            Form::Shape(s) => s.block(),
        }
    }

    /// The die of any shape, `None` for the cuboid.
    pub fn as_shape(&self) -> Option<&Shape> {
        match self {
            Form::Cuboid(_) => None,
            Form::Shape(s) => Some(s),
        }
    }

    /// The die of any shape, kept, `None` for the cuboid.
    pub fn into_shape(self) -> Option<Arc<Shape>> {
        match self {
            Form::Cuboid(_) => None,
            Form::Shape(s) => Some(s),
        }
    }

    /// The die of any shape, to change, `None` for the cuboid.
    pub fn shape_mut(&mut self) -> Option<&mut Arc<Shape>> {
        match self {
            Form::Cuboid(_) => None,
            Form::Shape(s) => Some(s),
        }
    }

    /// Its shape when its solid is not a box (a hull, a cylinder): what the engines, the mass
    /// and the roll take from a die of any shape. `None` for a box (the cuboid, a d6, a
    /// box-shaped mesh: `Shape::as_box`), which they all take by the box's closed forms, the
    /// paper's fast path, whatever its name.
    pub fn hull(&self) -> Option<&Shape> {
        self.as_shape().filter(|s| s.as_box().is_none())
    }

    /// A die of any shape that is a box (`Shape::as_box`): its outcome resting on each face,
    /// in `faces::DIRECTIONS`' order. `None` for the cuboid and for any other solid.
    pub fn box_faces(&self) -> Option<[u8; 6]> {
        self.as_shape().and_then(Shape::as_box).map(|b| b.faces)
    }

    /// What each of its outcomes shows, by its index (`faces::Outcome::Face`): a die of any
    /// shape's labels (`Shape::labels`; a label on several facets at each), the cuboid's
    /// numbers under `layout` by the direction of its face up (`faces::DIRECTIONS`).
    pub fn face_labels(&self, layout: Layout) -> Vec<String> {
        match self {
            Form::Shape(s) => s.labels().iter().map(|l| l.to_string()).collect(),
            Form::Cuboid(_) => layout.numbers().iter().map(u8::to_string).collect(),
        }
    }

    /// True for the cuboid, whose outcomes (its faces, by the direction up) the paper counts
    /// by the side standing vertical (`faces::Outcome::side`); a die of any shape, a
    /// box-shaped one too, is counted by its faces alone.
    pub fn counts_sides(&self) -> bool {
        matches!(self, Form::Cuboid(_))
    }

    /// True for a coin (a cylinder), which can roll on its rim for ever.
    pub fn is_coin(&self) -> bool {
        matches!(
            self.as_shape().map(|s| &s.solid),
            Some(Solid::Cylinder { .. })
        )
    }

    /// What it is, for a report's title: its shape's name (`d20`, `coin:24,2`, a mesh's), else
    /// its sides, "LxBxW mm".
    pub fn title(&self) -> String {
        match self {
            Form::Cuboid(b) => format!("{b} mm"),
            Form::Shape(s) => s.name.clone(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_shape_s_block_is_its_bounding_box_and_the_cuboid_s_its_sides() {
        let block = Block::from_mm(140.0, 24.0, 20.0).unwrap();
        let cuboid = Form::Cuboid(block);
        assert_eq!(cuboid.block(), block);
        assert!(cuboid.counts_sides() && cuboid.as_shape().is_none());
        let coin = crate::model::shape::named("coin:24,2", None).unwrap();
        let b = coin.block();
        let form = Form::shape(coin);
        assert_eq!(form.block(), b);
        assert!((b.breadth - 0.024).abs() < 1e-12 && (b.length - 0.002).abs() < 1e-12);
        assert!(form.is_coin() && !form.counts_sides() && form.hull().is_some());
        let d6 = Form::shape(crate::model::shape::named("d6", None).unwrap());
        assert!(d6.hull().is_none() && d6.box_faces().is_some() && !d6.counts_sides());
    }
}
