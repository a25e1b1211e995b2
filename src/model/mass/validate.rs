//! The checks on a die's description: its features against a cuboid's half sides or a die of
//! any shape, each refusal one line naming the field.

use super::features::{Features, Insert, PipShape, Pips, Shell};
use super::pips::pip_places;
use crate::error::{Error, Field, Result};
use crate::model::block::Mode;
use nalgebra::{Matrix3, SymmetricEigen, Vector3};

/// A length in m shown in mm as the user would write it: to 12 significant digits (so
/// 7.999 mm read in and stored in metres prints as 7.999, not 7.998999999999999, and
/// 8.0000001 as itself), a length too large to write out in scientific notation (1e308, not
/// inf or 309 digits).
fn shown_mm(v: f64) -> String {
    let mm: f64 = format!("{:.11e}", v * 1e3).parse().unwrap_or(v * 1e3);
    let plain = format!("{mm}");
    if plain.len() > 20 {
        format!("{mm:e}")
    } else {
        plain
    }
}

impl Features {
    /// Checks the features against the die's half sides: one line naming the field.
    pub fn validate(&self, half: &Vector3<f64>, mode: Mode) -> Result<()> {
        if self.plain() {
            return Ok(());
        }
        if mode == Mode::TwoD {
            return Err(Error::Invalid(
                "a centre of mass off the centre, pips, rounded edges and a printed shell are \
                 modelled in 3D only (2D is the paper's ideal block): roll it in 3D"
                    .into(),
            ));
        }
        let mm = shown_mm;
        let min_half = half.min();
        let r = self.edge_radius;
        if !(r.is_finite() && r >= 0.0 && r < min_half) {
            return Err(Error::field(
                Field::EdgeRadius,
                mm(r),
                format!(
                    "must be at least 0 and under half the shortest side ({} mm)",
                    mm(min_half)
                ),
            ));
        }
        if let Some(c) = self.com {
            let c = Vector3::from(c);
            // Inside the rounded box: within r of the inner box of half sides h − r.
            let out = (c.abs() - half.map(|h| h - r)).map(|x| x.max(0.0)).norm();
            let inside = if r > 0.0 {
                out < r
            } else {
                (c.abs() - half).max() < 0.0
            };
            if !(c.iter().all(|x| x.is_finite()) && inside) {
                return Err(Error::field(
                    Field::Com,
                    format!("{},{},{}", mm(c.x), mm(c.y), mm(c.z)),
                    "must lie inside the die (mm from its centre, body axes)",
                ));
            }
        }
        if let Some(p) = &self.pips {
            self.validate_pips(p, half)?;
        }
        if let Some(i) = &self.insert {
            self.validate_insert(i, half)?;
        }
        if let Some(t) = self.inertia {
            validate_inertia(t)?;
        }
        if let Some(sh) = &self.shell {
            self.validate_shell(sh, min_half, "half the shortest side")?;
        }
        Ok(())
    }

    /// Checks the features on a die of any shape: pips and rounded edges are the cuboid's
    /// (refused, with the reason); a centre of mass and an insert inside its hull.
    pub fn validate_on(&self, shape: &crate::model::shape::Shape, mode: Mode) -> Result<()> {
        let mm = shown_mm;
        let triple = |v: [f64; 3]| format!("{},{},{}", mm(v[0]), mm(v[1]), mm(v[2]));
        if mode == Mode::TwoD {
            return Err(Error::field(
                Field::Shape,
                &shape.name,
                "a die of any shape is rolled in 3D only (2D is the paper's block)",
            ));
        }
        if self.pips.is_some() {
            return Err(Error::field(
                Field::PipsDiameter,
                "",
                "pips are drilled in a cuboid's faces (the standard pattern); a die of another \
                 shape carries its mass as its mesh gives it",
            ));
        }
        if self.edge_radius != 0.0 {
            // A die of any shape takes its rounding in its hull (`Shape::rounded`), which
            // resolving the die does; a rounding left here was never applied.
            return Err(Error::field(
                Field::EdgeRadius,
                mm(self.edge_radius),
                "a die of any shape is rounded in its hull (Shape::rounded), not here",
            ));
        }
        if shape.radius > 0.0 && self.shell.is_some() {
            return Err(Error::field(
                Field::ShellWall,
                "",
                "a printed shell inside a die of any shape with rounded edges is not modelled \
                 (its inner solid is the sharp die's)",
            ));
        }
        if let Some(c) = self.com {
            if !(c.iter().all(|x| x.is_finite()) && shape.contains(&Vector3::from(c))) {
                return Err(Error::field(
                    Field::Com,
                    triple(c),
                    "must lie inside the die (mm from its centroid, body axes)",
                ));
            }
        }
        if let Some(i) = &self.insert {
            let corners_inside = (0..8).all(|n| {
                let corner = Vector3::from_fn(|k, _| {
                    let sign = if n >> k & 1 == 1 { 0.5 } else { -0.5 };
                    i.centre[k] + sign * i.size[k]
                });
                shape.contains(&corner)
            });
            if !(i.size.iter().all(|s| s.is_finite() && *s > 0.0) && corners_inside) {
                return Err(Error::field(
                    Field::InsertCentre,
                    triple(i.centre),
                    "the insert must lie inside the die (mm from its centroid)",
                ));
            }
            if !(i.density.is_finite() && (0.0..=1e5).contains(&i.density)) {
                return Err(Error::field(
                    Field::InsertDensity,
                    i.density,
                    "must be in [0, 100000] kg/m³",
                ));
            }
        }
        if let Some(t) = self.inertia {
            validate_inertia(t)?;
        }
        if let Some(sh) = &self.shell {
            self.validate_shell_on(sh, shape)?;
        }
        Ok(())
    }

    /// A printed die's shell: a wall thinner than the die's `inradius` (`what` it is), an
    /// infill fraction in [0, 1], and nothing inside it the model does not combine with it (an
    /// insert in the infill, a pip deeper than the wall).
    fn validate_shell(&self, sh: &Shell, inradius: f64, what: &str) -> Result<()> {
        let mm = shown_mm;
        if !(sh.wall.is_finite() && sh.wall > 0.0 && sh.wall < inradius) {
            return Err(Error::field(
                Field::ShellWall,
                mm(sh.wall),
                format!(
                    "must be positive and under the die's inradius, {} mm ({what})",
                    mm(inradius)
                ),
            ));
        }
        if !(sh.infill.is_finite() && (0.0..=1.0).contains(&sh.infill)) {
            return Err(Error::field(
                Field::ShellInfill,
                sh.infill,
                "must be a fraction in [0, 1] (of the volume inside the wall; 1: solid)",
            ));
        }
        if self.insert.is_some() {
            return Err(Error::field(
                Field::InsertCentre,
                "",
                "an insert in a printed die's infill is not modelled: give the insert or the \
                 shell, not both",
            ));
        }
        if let Some(p) = self.pips.filter(|p| p.depth > sh.wall) {
            return Err(Error::field(
                Field::PipsDepth,
                mm(p.depth),
                format!(
                    "is deeper than the shell's wall ({} mm): a pip reaching into the infill \
                     is not modelled",
                    mm(sh.wall)
                ),
            ));
        }
        Ok(())
    }

    /// A shell on a die of any shape: a convex one (a mesh with a dent or a hollow has no
    /// offset the model takes), its wall under its inradius, an inner solid found.
    fn validate_shell_on(&self, sh: &Shell, shape: &crate::model::shape::Shape) -> Result<()> {
        if shape.hull_note().is_some() {
            return Err(Error::field(
                Field::ShellWall,
                shown_mm(sh.wall),
                format!(
                    "a shell is modelled on a convex die; {} is not convex",
                    shape.name
                ),
            ));
        }
        self.validate_shell(sh, shape.inradius(), "the nearest facet from its centroid")?;
        if super::shell::inner_shape(shape, sh.wall).is_none() {
            return Err(Error::field(
                Field::ShellWall,
                shown_mm(sh.wall),
                "leaves no inner solid that can be integrated (a thinner wall)",
            ));
        }
        Ok(())
    }

    /// The pips: a positive diameter, a depth a cap or cylinder can have, paint and spacing in
    /// range, every pip inside its face (clear of the rounding) and apart from the others.
    fn validate_pips(&self, p: &Pips, half: &Vector3<f64>) -> Result<()> {
        let mm = shown_mm;
        let min_half = half.min();
        let r = self.edge_radius;
        let bad = |field: Field, v: f64, why: String| Err(Error::field(field, mm(v), why));
        if !(p.diameter.is_finite() && p.diameter > 0.0) {
            return bad(
                Field::PipsDiameter,
                p.diameter,
                "must be a positive number of mm".into(),
            );
        }
        let deepest = match p.shape {
            PipShape::Cap => 0.5 * p.diameter,
            PipShape::Cylinder => min_half,
        };
        if !(p.depth.is_finite() && p.depth > 0.0 && p.depth <= deepest && p.depth < min_half) {
            return bad(
                Field::PipsDepth,
                p.depth,
                format!(
                    "must be positive, at most {} mm ({})",
                    mm(deepest.min(min_half)),
                    match p.shape {
                        PipShape::Cap => "a cap is at most a hemisphere",
                        PipShape::Cylinder => "under half the shortest side",
                    }
                ),
            );
        }
        if !(p.fill_density.is_finite() && (0.0..=1e5).contains(&p.fill_density)) {
            return Err(Error::field(
                Field::PipsFillDensity,
                p.fill_density,
                "must be in [0, 100000] kg/m³",
            ));
        }
        if !(p.spacing.is_finite() && p.spacing > 0.0 && p.spacing < 0.5) {
            return Err(Error::field(
                Field::PipsSpacing,
                p.spacing,
                "must be in (0, 0.5): a fraction of the face's side",
            ));
        }
        let places = pip_places(half, p, self.layout);
        let rad = 0.5 * p.diameter;
        for &(i, _, pj, pk) in &places {
            let (j, k) = ((i + 1) % 3, (i + 2) % 3);
            if pj.abs() + rad > half[j] - r || pk.abs() + rad > half[k] - r {
                return bad(
                    Field::PipsDiameter,
                    p.diameter,
                    "pips cross an edge of their face (or its rounding): smaller pips or a smaller spacing".into(),
                );
            }
        }
        for (n, a) in places.iter().enumerate() {
            for b in &places[n + 1..] {
                if a.0 == b.0 && a.1 == b.1 && (a.2 - b.2).hypot(a.3 - b.3) <= p.diameter {
                    return bad(
                        Field::PipsDiameter,
                        p.diameter,
                        "pips on a face overlap each other: smaller pips or a larger spacing"
                            .into(),
                    );
                }
            }
        }
        Ok(())
    }

    /// The insert: positive sizes, inside the die clear of its rounding and pips, a density in
    /// range.
    fn validate_insert(&self, i: &Insert, half: &Vector3<f64>) -> Result<()> {
        let mm = shown_mm;
        let r = self.edge_radius;
        // Clear of the rounding and of the pips' cavities: inside the box whose faces
        // lie the larger of the two inside the die's.
        let skin = r.max(self.pips.map_or(0.0, |p| p.depth));
        let triple = |v: [f64; 3]| format!("{},{},{}", mm(v[0]), mm(v[1]), mm(v[2]));
        if !(i.size.iter().all(|s| s.is_finite() && *s > 0.0)) {
            return Err(Error::field(
                Field::InsertSize,
                triple(i.size),
                "must be three positive lengths, mm",
            ));
        }
        let inside = (0..3).all(|k| {
            i.centre[k].is_finite() && i.centre[k].abs() + 0.5 * i.size[k] <= half[k] - skin
        });
        if !inside {
            return Err(Error::field(
                Field::InsertCentre,
                triple(i.centre),
                format!(
                    "the insert must lie inside the die, clear of its rounding and pips \
                     (within {} mm of each face)",
                    mm(skin)
                ),
            ));
        }
        if !(i.density.is_finite() && (0.0..=1e5).contains(&i.density)) {
            return Err(Error::field(
                Field::InsertDensity,
                i.density,
                "must be in [0, 100000] kg/m³",
            ));
        }
        Ok(())
    }
}

/// An inertia given outright: finite, positive definite, and each principal moment at most
/// the sum of the other two (as every solid's).
fn validate_inertia(t: [f64; 6]) -> Result<()> {
    let [xx, yy, zz, xy, xz, yz] = t;
    let m = Matrix3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz);
    let e = SymmetricEigen::new(m).eigenvalues;
    let physical = t.iter().all(|x| x.is_finite())
        && e.iter().all(|&x| x > 0.0)
        && (0..3).all(|k| e[k] <= e[(k + 1) % 3] + e[(k + 2) % 3]);
    if !physical {
        return Err(Error::field(
            Field::Inertia,
            t.map(|x| format!("{}", x * 1e9)).join(","),
            "no solid has this inertia: its principal moments must be positive and \
             each at most the sum of the other two (g mm²: xx, yy, zz, xy, xz, yz)",
        ));
    }
    Ok(())
}
