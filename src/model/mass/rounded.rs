//! A convex die with its edges and corners rounded by r (issue 72): its inner parallel body
//! (the facets moved in by r, `polytope::inner_hull`) swept by a ball of radius r. Its outer facets
//! stay where they were, each shrunk by the rounding; its edges become cylinders' strips and
//! its corners pieces of the ball: the same body `--edge-radius` makes of the box.
//!
//! What collides is the inner body's hull with a margin of r (Bullet keeps a hull's surface its
//! margin out, Rapier's round hull its border), so the engines take it exactly. Its mass
//! properties are integrated from a polytope inscribed in it: the hull of each inner corner
//! moved by r along every facet's normal and along `polytope::DIRECTIONS` directions spread evenly
//! over the sphere. Every such point lies in the rounded body, its flat faces are exact, and
//! its rounded strips are chords no deeper than r (1 − cos θ), θ the largest angle from any
//! direction to the nearest of the set (about 0.04 rad for 4,000): 0.07 % of r, under 1 µm on
//! a 1 mm rounding, far below a printer's resolution. The volume comes out short by a few
//! parts in 10⁴ of a die rounded by a tenth of its size, falling as 1/N; the box's closed form
//! (`rounded_box`) and Steiner's volume of a rounded octahedron check it (`rounded_tests`).
//! About 30 ms a die.

use crate::model::shape::Shape;
use std::sync::{Arc, Mutex};

/// Where a die's rounding goes, decided in this one place for `roll`'s flags, a fit's cells
/// and `fair --vary`: a box (the cuboid, a box-shaped die) keeps it in its features
/// (`Features::edge_radius`, the rounded box's closed forms and Bullet's box path); any other
/// die of any shape takes it in its hull ([`rounded_shared`]), its features' radius then 0.
/// An error (a rounding the die cannot take, `Shape::rounded`'s reason) leaves both as they
/// were.
pub fn take_rounding(
    shape: Option<&mut Arc<Shape>>,
    features: &mut super::features::Features,
) -> Result<(), String> {
    let r = features.edge_radius;
    if let Some(s) = shape.filter(|s| r > 0.0 && s.as_box().is_none()) {
        *s = rounded_shared(s, r)?;
        features.edge_radius = 0.0;
    }
    Ok(())
}

/// How many roundings [`rounded_shared`] keeps.
const KEPT: usize = 4;

/// The roundings made last: the die rounded (kept, so that its address is not reused while
/// it is a key), the radius's bits, the rounded die.
type Kept = Vec<(Arc<Shape>, u64, Arc<Shape>)>;
static ROUNDINGS: Mutex<Kept> = Mutex::new(Vec::new());

/// `shape.rounded(radius)`, shared: the last few roundings are kept, so that a fit's cells,
/// its rolled check and its draws at one radius round the die once, not once a cell (about
/// 30 ms for V1, a hull of ~70,000 points). The result is a pure function of the die and the
/// radius, so keeping it changes no number, whatever the thread count.
pub fn rounded_shared(shape: &Arc<Shape>, radius: f64) -> Result<Arc<Shape>, String> {
    let key = radius.to_bits();
    let kept = |k: &Kept| {
        k.iter()
            .find(|(s, r, _)| Arc::ptr_eq(s, shape) && *r == key)
            .map(|(_, _, out)| out.clone())
    };
    if let Some(out) = kept(&ROUNDINGS.lock().unwrap_or_else(|e| e.into_inner())) {
        return Ok(out);
    }
    let out = Arc::new(shape.rounded(radius)?);
    let mut k = ROUNDINGS.lock().unwrap_or_else(|e| e.into_inner());
    if kept(&k).is_none() {
        if k.len() == KEPT {
            k.remove(0);
        }
        k.push((shape.clone(), key, out.clone()));
    }
    Ok(out)
}
