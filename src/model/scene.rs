//! The scene a throw happens in: the block, the surface, the time step, 2D or 3D, and the
//! engine settings. Defaults are DicePhys's, as the paper ran it (the paper's section
//! "Computation"; docs/guide.md, "Presets").

use crate::error::{Error, Field, Result};
use crate::model::block::Block;
pub use crate::model::block::Mode;
pub use crate::model::form::Form;
use crate::model::mass::{Composition, Features, MassProps};
use crate::model::shape::Shape;
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// Gravity, m/s², along −y.
pub const GRAVITY: f64 = 9.81;

/// The engines' contact settings, by name (Bullet's solver; under `laws` Rapier's friction too).
#[derive(
    Clone,
    Copy,
    Debug,
    PartialEq,
    Eq,
    Hash,
    Serialize,
    Deserialize,
    strum::Display,
    strum::EnumString,
    strum::IntoStaticStr,
    strum::VariantNames,
)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum Preset {
    /// Bullet 2.81's behaviour on Debian's 3.24, as the paper ran it.
    Dicephys281,
    /// Debian 3.24's stock defaults.
    Bullet3,
    /// Bullet 2.81's behaviour (dicephys281) with every penetration corrected by a split
    /// impulse, so that a bounce leaves at exactly e times the approach speed.
    Split,
    /// Each engine held to the closed forms a loaded die needs (tests/it/impact.rs): Bullet
    /// as `split`, with friction in Coulomb's cone (two directions per contact point, not
    /// one along the slip, solved together in the disc μ N and against the slip, not each
    /// clamped on its own) and the die turning as Euler's equations say (Bullet's gyroscopic
    /// impulse at a scale where its own arithmetic does not drop it); Rapier with Coulomb's
    /// friction at each contact point (`FrictionModel::Coulomb`, not one constraint at the
    /// patch's centre and a twist) and in its bounce (vendor/rapier3d-f64/PATCH.md). For a
    /// die whose moments differ (a loaded or long die).
    Laws,
}

impl Preset {
    /// The preset's name on the command line and in reports.
    pub fn name(self) -> &'static str {
        self.into()
    }
}

/// The floor: DicePhys's static 10000 x 100 x 10000 m box, or a static plane.
#[derive(
    Clone,
    Copy,
    Debug,
    PartialEq,
    Eq,
    Hash,
    Serialize,
    Deserialize,
    strum::Display,
    strum::EnumString,
    strum::IntoStaticStr,
    strum::VariantNames,
)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum Floor {
    /// DicePhys's static box, top face at y = 0.
    Box,
    /// A static plane at y = 0.
    Plane,
}

impl Floor {
    /// "box" or "plane".
    pub fn name(self) -> &'static str {
        self.into()
    }
}

/// A coin's rolling resistance unless one is asked, m (0.05 mm, a hard table's order):
/// measured on `docs/results/shapes.md`, it ends every roll of every thickness from 2 to
/// 14 mm before the step cap (with none, 37–43 % are still rolling at 5 s), and moves the
/// edge's share by at most 0.03 across 0.01–0.2 mm.
pub const COIN_ROLLING_RESISTANCE: f64 = 5e-5;

/// Everything a throw happens in.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(into = "Written", from = "Written")]
pub struct Scene {
    /// The die: the paper's cuboid, or a die of any shape.
    pub die: Form,
    /// 2D or 3D.
    pub mode: Mode,
    /// kg/m³. The paper does not give it; outcomes should not depend on it.
    pub density: f64,
    /// The die's friction; Bullet multiplies it by the floor's (1), so the contact's μ.
    pub friction: f64,
    /// The die's restitution; multiplied by the floor's (1), so the contact's e.
    pub restitution: f64,
    /// The floor's friction (DicePhys: 1).
    pub floor_friction: f64,
    /// The floor's restitution (DicePhys: 1).
    pub floor_restitution: f64,
    /// Fixed time step, s.
    pub dt: f64,
    /// Bullet's solver settings.
    pub preset: Preset,
    /// Box or plane.
    pub floor: Floor,
    /// The box floor's thickness, m: DicePhys's is 100 m (`DICEPHYS_FLOOR_THICKNESS`), which
    /// nothing gets through; a table top (2 cm) lets a die at a coarse step pass through it.
    pub floor_thickness: f64,
    /// m/s², along −y.
    pub gravity: f64,
    /// Linear damping, a rate in 1/s: out of contact the die's velocity decays as e^(−λt).
    /// DicePhys: 0 (none). How each engine applies it: [`Scene::bullet_damping`],
    /// [`Scene::rapier_damping`]. Written into a specification only when not 0, so that a
    /// default run's specification, and the key its checkpoints carry, are unchanged.
    pub linear_damping: f64,
    /// Angular damping, a rate in 1/s, as `linear_damping` but for the angular velocity.
    pub angular_damping: f64,
    /// Rolling resistance, m: the lever arm of the floor's push against a die rolling or
    /// turning in place on it, so that a torque up to this length times the contact force
    /// opposes both (Bullet's rolling and spinning friction). DicePhys: 0, none, as neither
    /// engine has by default; then a cylinder rolling on its side or a coin spinning on its
    /// rim never stops. Bullet, and Rapier's 3D body (a couple after each step,
    /// `Rapier3d::resist_rolling`). Written into a specification only when not 0.
    pub rolling_resistance: f64,
    /// The bounce threshold, m/s: a contact met slower than this along its normal does not
    /// bounce (restitution 0), a faster one bounces with e, as Bullet 3 drops restitution below
    /// its `m_restitutionVelocityThreshold` (the preset `bullet3`'s own is 0.2 m/s; the larger
    /// of the two holds). A real die's slow impacts lose what a fast one keeps (a plastic or
    /// sticky contact), which one e cannot say. DicePhys: 0, every impact bounces. Bullet only.
    /// Written into a specification only when not 0.
    pub bounce_threshold: f64,
    /// The contact time, s: a soft table (`model::compliance`), each impact a spring and a
    /// dashpot whose flat landing lasts this long and leaves at `restitution` times its
    /// speed. 0: the rigid contact (DicePhys's), an impulse in one step. Bullet only; at
    /// least two steps. Written into a specification only when not 0.
    pub contact_time: f64,
    /// Static friction over sliding friction, μs/μk: a contact point that is not sliding as a
    /// step begins (its slip slower than `Scene::stick_speed`) holds up to μs = this × μ times
    /// its push, a sliding one μ (the sliding friction, `friction` × `floor_friction`). A real
    /// pair of surfaces holds more than it drags (steel on steel 0.74 against 0.57, wood on wood
    /// up to twice), which one μ cannot say. DicePhys: 1, one μ. Bullet only. Written into a
    /// specification only when not 1.
    pub static_ratio: f64,
    /// The engine may put a die that has slowed down to sleep (Bullet's deactivation after
    /// 2 s under 0.8 m/s and 1 rad/s, Rapier's after 0.5 s under its thresholds), as DicePhys
    /// let Bullet do. False: never, for a die that moves slowly for long (an over-damped roll,
    /// which sleeping would freeze mid-fall). Written into a specification only when false.
    pub sleeping: bool,
    /// How the die departs from the ideal block: its centre of mass, pips, rounded edges
    /// (`model::mass`), and how its faces are numbered (`layout`, which decides what its
    /// faces read, so it is the run's too). Written into a specification only when any is
    /// not the default.
    pub features: Features,
}

/// A scene as its specification writes it: every field in the order and the form it has
/// always had, since a checkpoint's key is the hash of these bytes (`run::spec::RunSpec::key`)
/// — the die's block first (a die of any shape's bounding box), its shape last and only where
/// there is one. Read back, a shape's block is its own bounding box, not the one written.
#[derive(Serialize, Deserialize)]
struct Written {
    block: Block,
    mode: Mode,
    density: f64,
    friction: f64,
    restitution: f64,
    floor_friction: f64,
    floor_restitution: f64,
    dt: f64,
    preset: Preset,
    floor: Floor,
    floor_thickness: f64,
    gravity: f64,
    #[serde(default, skip_serializing_if = "is_zero")]
    linear_damping: f64,
    #[serde(default, skip_serializing_if = "is_zero")]
    angular_damping: f64,
    #[serde(default, skip_serializing_if = "is_zero")]
    rolling_resistance: f64,
    #[serde(default, skip_serializing_if = "is_zero")]
    bounce_threshold: f64,
    #[serde(default, skip_serializing_if = "is_zero")]
    contact_time: f64,
    #[serde(default = "one", skip_serializing_if = "is_one")]
    static_ratio: f64,
    #[serde(default = "yes", skip_serializing_if = "is_true")]
    sleeping: bool,
    #[serde(default, skip_serializing_if = "Features::is_default")]
    features: Features,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    shape: Option<Arc<Shape>>,
}

impl From<Scene> for Written {
    fn from(s: Scene) -> Written {
        Written {
            block: s.die.block(),
            shape: s.die.into_shape(),
            mode: s.mode,
            density: s.density,
            friction: s.friction,
            restitution: s.restitution,
            floor_friction: s.floor_friction,
            floor_restitution: s.floor_restitution,
            dt: s.dt,
            preset: s.preset,
            floor: s.floor,
            floor_thickness: s.floor_thickness,
            gravity: s.gravity,
            linear_damping: s.linear_damping,
            angular_damping: s.angular_damping,
            rolling_resistance: s.rolling_resistance,
            bounce_threshold: s.bounce_threshold,
            contact_time: s.contact_time,
            static_ratio: s.static_ratio,
            sleeping: s.sleeping,
            features: s.features,
        }
    }
}

impl From<Written> for Scene {
    fn from(w: Written) -> Scene {
        Scene {
            die: w.shape.map_or(Form::Cuboid(w.block), Form::Shape),
            mode: w.mode,
            density: w.density,
            friction: w.friction,
            restitution: w.restitution,
            floor_friction: w.floor_friction,
            floor_restitution: w.floor_restitution,
            dt: w.dt,
            preset: w.preset,
            floor: w.floor,
            floor_thickness: w.floor_thickness,
            gravity: w.gravity,
            linear_damping: w.linear_damping,
            angular_damping: w.angular_damping,
            rolling_resistance: w.rolling_resistance,
            bounce_threshold: w.bounce_threshold,
            contact_time: w.contact_time,
            static_ratio: w.static_ratio,
            sleeping: w.sleeping,
            features: w.features,
        }
    }
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

fn is_one(v: &f64) -> bool {
    *v == 1.0
}

fn one() -> f64 {
    1.0
}

fn is_true(v: &bool) -> bool {
    *v
}

fn yes() -> bool {
    true
}

/// The largest damping rate accepted, 1/s. Bullet takes damping as d in [0, 1] and scales the
/// velocity by (1 − d)^dt each step, so a rate λ is d = 1 − e^(−λ); above about 36/s, 1 − d
/// rounds to 0 in double precision and Bullet would zero the velocity every step instead. At
/// 30/s, 1 − d = 9.4e-14 is held to 6e-4 of itself: the rate to 2e-5.
pub const MAX_DAMPING: f64 = 30.0;

/// The largest friction coefficient accepted: Bullet clamps a contact's combined friction
/// to 10 (`btManifoldResult`'s `MAX_FRICTION`), so a larger μ would run silently as 10.
pub const MAX_FRICTION: f64 = 10.0;

/// The largest rolling resistance accepted, m: 1 mm, already the lever arm of soft felt
/// under a heavy die (hard surfaces are near 0.01 mm).
pub const MAX_ROLLING_RESISTANCE: f64 = 1e-3;

/// The largest ratio of static to sliding friction a scene takes: 3, beyond the largest of
/// the handbooks' dry pairs (wood on wood, leather on metal: about 2 to 2.5).
pub const MAX_STATIC_RATIO: f64 = 3.0;

/// The largest bounce threshold a scene takes, m/s: a die dropped from 20 cm meets the table at
/// 2 m/s, so every impact of a throw is below it.
pub const MAX_BOUNCE_THRESHOLD: f64 = 2.0;

/// The longest contact time a scene takes, s: 50 ms, a die sinking into a cushion.
pub const MAX_CONTACT_TIME: f64 = 0.05;

/// The fewest steps a soft contact may last: a shorter one is not resolved (its spring acts
/// within a step, and backward Euler's own damping takes the bounce).
pub const MIN_CONTACT_STEPS: f64 = 2.0;

/// The finest time step accepted, s: 1 µs. A roll at rest by DicePhys's rule takes about a
/// second of simulated time, a million steps here; finer steps only multiply the work (a
/// 1e-12 s step would never end) and lose the motion to rounding in the position update.
pub const MIN_DT: f64 = 1e-6;

/// The coarsest time step accepted, s.
pub const MAX_DT: f64 = 0.1;

/// The lightest die accepted, kg/m³ (foam is about 10): far lighter, the mass and inertia
/// underflow and every roll ends non-finite.
pub const MIN_DENSITY: f64 = 1.0;

/// Checks a time step `dt` given as `field`: in [`MIN_DT`], [`MAX_DT`] s.
pub fn check_dt(field: Field, dt: f64) -> Result<()> {
    if dt.is_finite() && (MIN_DT..=MAX_DT).contains(&dt) {
        Ok(())
    } else {
        Err(Error::field(
            field,
            dt,
            format!("must be in [{MIN_DT}, {MAX_DT}] s"),
        ))
    }
}

/// DicePhys's floor box is 100 m thick, its top face at y = 0.
pub const DICEPHYS_FLOOR_THICKNESS: f64 = 100.0;

impl Scene {
    /// The box floor's thickness, m, as a front end sets it: refused on the plane floor,
    /// which is a half-space.
    pub fn set_floor_thickness(&mut self, t: f64) -> crate::Result<()> {
        if self.floor == Floor::Plane {
            return Err(crate::Error::field(
                crate::error::Field::FloorThickness,
                t,
                crate::text![
                    "the plane floor is a half-space; give ",
                    crate::error::Field::Floor,
                    " box"
                ],
            ));
        }
        self.floor_thickness = t;
        Ok(())
    }
    /// Checks every value before anything runs. A restitution above 1 is not physics; it is
    /// accepted (up to 10) only for engine-stability studies that ask for it.
    pub fn validate(&self, allow_restitution_above_one: bool) -> Result<()> {
        let bad = |field, v: f64, why: String| Err(Error::field(field, v, why));
        check_dt(Field::Dt, self.dt)?;
        if !(self.friction.is_finite() && (0.0..=MAX_FRICTION).contains(&self.friction)) {
            return bad(
                Field::Friction,
                self.friction,
                format!(
                    "must be in [0, {MAX_FRICTION}] (Bullet holds a contact's friction at \
                     {MAX_FRICTION} at most)"
                ),
            );
        }
        let e_max = if allow_restitution_above_one {
            10.0
        } else {
            1.0
        };
        if !(self.restitution.is_finite() && self.restitution >= 0.0 && self.restitution <= e_max) {
            return Err(Error::field(
                Field::Restitution,
                self.restitution,
                crate::text![
                    "must be in [0, 1] (above 1 only with ",
                    Field::AllowRestitutionAboveOne,
                    ")"
                ],
            ));
        }
        if !(self.floor_thickness.is_finite()
            && (0.001..=DICEPHYS_FLOOR_THICKNESS).contains(&self.floor_thickness))
        {
            return bad(
                Field::FloorThickness,
                self.floor_thickness,
                "must be in [0.001, 100] m".into(),
            );
        }
        if !(self.density.is_finite() && (MIN_DENSITY..=1e5).contains(&self.density)) {
            return bad(
                Field::Density,
                self.density,
                format!("must be in [{MIN_DENSITY}, 100000] kg/m³"),
            );
        }
        for (name, v) in [
            (Field::LinearDamping, self.linear_damping),
            (Field::AngularDamping, self.angular_damping),
        ] {
            if !(v.is_finite() && (0.0..=MAX_DAMPING).contains(&v)) {
                return bad(
                    name,
                    v,
                    format!("must be in [0, {MAX_DAMPING}] 1/s (Bullet cannot hold a faster rate)"),
                );
            }
        }
        if !(self.rolling_resistance.is_finite()
            && (0.0..=MAX_ROLLING_RESISTANCE).contains(&self.rolling_resistance))
        {
            return bad(
                Field::RollingResistance,
                self.rolling_resistance * 1e3,
                format!("must be in [0, {}] mm", MAX_ROLLING_RESISTANCE * 1e3),
            );
        }
        if !(self.bounce_threshold.is_finite()
            && (0.0..=MAX_BOUNCE_THRESHOLD).contains(&self.bounce_threshold))
        {
            return bad(
                Field::BounceThreshold,
                self.bounce_threshold,
                format!("must be in [0, {MAX_BOUNCE_THRESHOLD}] m/s"),
            );
        }
        if !(self.static_ratio.is_finite() && (1.0..=MAX_STATIC_RATIO).contains(&self.static_ratio))
        {
            return bad(
                Field::StaticRatio,
                self.static_ratio,
                format!(
                    "must be in [1, {MAX_STATIC_RATIO}]: static friction holds at least what \
                     sliding friction drags"
                ),
            );
        }
        self.check_contact()?;
        if let (Some(shape), Mode::TwoD) = (self.die.as_shape(), self.mode) {
            // A box-shaped die too: its mass is the box's (`Form::hull`), its outcomes
            // its faces in 3D.
            return Err(Error::field(
                Field::Shape,
                &shape.name,
                "a die of any shape is rolled in 3D only (2D is the paper's block)",
            ));
        }
        MassProps::of(self)?;
        Ok(())
    }

    /// A soft contact's time within what the step resolves, its restitution one a dashpot
    /// gives, and no bounce threshold beside it (its spring, not a restitution, bounces).
    fn check_contact(&self) -> Result<()> {
        let bad = |field, v: f64, why: String| Err(Error::field(field, v, why));
        if self.contact_time == 0.0 {
            return Ok(());
        }
        let lo = MIN_CONTACT_STEPS * self.dt;
        if !(self.contact_time.is_finite() && (lo..=MAX_CONTACT_TIME).contains(&self.contact_time))
        {
            return Err(Error::field(
                Field::ContactTime,
                self.contact_time * 1e3,
                crate::text![
                    format!(
                        "must be 0 (a rigid contact) or in [{}, {}] ms: at least \
                         {MIN_CONTACT_STEPS} steps of ",
                        lo * 1e3,
                        MAX_CONTACT_TIME * 1e3
                    ),
                    Field::Dt
                ],
            ));
        }
        if !(self.restitution > 0.0 && self.restitution <= 1.0) {
            return bad(
                Field::Restitution,
                self.restitution,
                "a soft contact's restitution must be in (0, 1]: its dashpot cannot stop a \
                 landing dead nor give back more than it took"
                    .into(),
            );
        }
        if self.bounce_threshold > 0.0 {
            return Err(Error::field(
                Field::BounceThreshold,
                self.bounce_threshold,
                crate::text![
                    "a soft contact bounces by its spring, not by a restitution: give one of ",
                    Field::ContactTime,
                    " and ",
                    Field::BounceThreshold
                ],
            ));
        }
        Ok(())
    }

    /// The paper's MDF scene (μ = 0.29, e = 0.5, dt = 1 ms) for a block.
    pub fn paper(block: Block, mode: Mode) -> Scene {
        Scene {
            die: Form::Cuboid(block),
            mode,
            density: 800.0,
            friction: 0.29,
            restitution: 0.5,
            floor_friction: 1.0,
            floor_restitution: 1.0,
            dt: 0.001,
            preset: Preset::Dicephys281,
            floor: Floor::Box,
            floor_thickness: DICEPHYS_FLOOR_THICKNESS,
            gravity: GRAVITY,
            linear_damping: 0.0,
            angular_damping: 0.0,
            rolling_resistance: 0.0,
            bounce_threshold: 0.0,
            contact_time: 0.0,
            static_ratio: 1.0,
            sleeping: true,
            features: Features::default(),
        }
    }

    /// The slip below which a contact point counts as not sliding (static friction holds it,
    /// `static_ratio`): g dt, what gravity adds to a speed in one step. A point that held
    /// through the last step ends it slipping by no more than the solver's residual, far
    /// below this; a point found slower than this cannot be told from one at rest by a step
    /// of this length.
    pub fn stick_speed(&self) -> f64 {
        self.gravity * self.dt
    }

    /// True if the die's velocities are damped (either rate above 0).
    pub fn damped(&self) -> bool {
        self.linear_damping > 0.0 || self.angular_damping > 0.0
    }

    /// The damping as Bullet takes it (`btRigidBody::setDamping`), (linear, angular):
    /// d = 1 − e^(−λ), so that Bullet's factor per step, (1 − d)^dt, is e^(−λ dt). Bullet
    /// applies it once a step, before the contacts are solved.
    pub fn bullet_damping(&self) -> (f64, f64) {
        let d = |rate: f64| -(-rate).exp_m1();
        (d(self.linear_damping), d(self.angular_damping))
    }

    /// The damping as Rapier takes it (`RigidBodyBuilder::linear_damping`), (linear,
    /// angular): c = (e^(λ dt) − 1)/dt, so that Rapier's factor per step, 1/(1 + c·dt), is
    /// e^(−λ dt), as Bullet's. Rapier applies it once a step, after the contacts are solved.
    pub fn rapier_damping(&self) -> (f64, f64) {
        let c = |rate: f64| (rate * self.dt).exp_m1() / self.dt;
        (c(self.linear_damping), c(self.angular_damping))
    }

    /// Full sides along the body's x, y, z axes (breadth, width, length); in 2D the depth
    /// along z is 1 m, as DicePhys's 2D die.
    pub fn body_sides(&self) -> [f64; 3] {
        let b = self.die.block();
        match self.mode {
            Mode::ThreeD => [b.breadth, b.width, b.length],
            Mode::TwoD => [b.breadth, b.width, 1.0],
        }
    }

    /// What the die's mass properties depend on (`model::mass`).
    pub fn composition(&self) -> Composition<'_> {
        Composition {
            sides: self.body_sides(),
            density: self.density,
            plain_mass: self.mass(),
            mode: self.mode,
            features: &self.features,
            shape: self.die.hull(),
        }
    }

    /// The paper's scene (`Scene::paper`) for a die of any shape.
    pub fn paper_shape(shape: Shape, mode: Mode) -> Scene {
        let block = shape.block();
        Scene {
            die: Form::shape(shape),
            ..Scene::paper(block, mode)
        }
    }

    /// A box-shaped die whose labels are the numbers 1 to 6: the layout they make, which
    /// places its pips (`model::mass`).
    pub fn box_layout(&self) -> Option<crate::model::faces::Layout> {
        let shape = self.die.as_shape()?;
        let faces = self.die.box_faces()?;
        // A layout numbers the face up: each direction's number is what the die shows
        // resting on the face opposite.
        let mut numbers = [0u8; 6];
        for (d, n) in numbers.iter_mut().enumerate() {
            *n = shape.faces[usize::from(faces[d ^ 1])].label.parse().ok()?;
        }
        crate::model::faces::Layout::from_numbers(numbers)
    }

    /// The labels its die shows, each once, in the order of its outcomes (`Form::face_labels`:
    /// a die of any shape's labels, a block's numbers under `layout`; a block in 2D shows the
    /// four faces about z, and a die of any shape is 3D only).
    pub fn labels(&self, layout: crate::model::faces::Layout) -> Vec<String> {
        let shown = match self.mode {
            Mode::ThreeD => usize::MAX,
            Mode::TwoD => 4,
        };
        let mut out: Vec<String> = Vec::new();
        for l in self.die.face_labels(layout).into_iter().take(shown) {
            if !out.contains(&l) {
                out.push(l);
            }
        }
        out
    }

    /// The scene with its die's outcomes at its own centre of mass (`Shape::resting_at`): a
    /// die of any shape loaded off its centroid rests on the facets it rests on there, and a
    /// facet it rolls off is no outcome. Unchanged for the cuboid, a coin, or a centred die.
    /// A box-shaped die with pips has them drilled as its labels number its faces
    /// (`Scene::box_layout`).
    pub fn resting_at_com(mut self) -> std::result::Result<Scene, String> {
        if let (Form::Shape(_), Some(_)) = (&self.die, self.features.pips) {
            self.features.layout = self.box_layout().ok_or_else(|| {
                "pips are drilled in a box's faces numbered 1 to 6; this die is not one".to_string()
            })?;
        }
        if let Form::Shape(shape) = &self.die {
            let com = MassProps::compute(&self).com;
            self.die = Form::shape(shape.resting_at(&com)?);
        }
        Ok(self)
    }

    /// The die's mass, multiplied in DicePhys's order so that the numbers agree to the bit.
    pub fn mass(&self) -> f64 {
        if let Some(s) = self.die.hull() {
            return s.volume * self.density;
        }
        let b = self.die.block();
        match self.mode {
            Mode::ThreeD => b.breadth * b.width * b.length * self.density,
            Mode::TwoD => b.breadth * b.width * self.density,
        }
    }

    /// Height of the floor's bottom face: the die is through the floor once wholly below it
    /// (−∞ for the plane, which is a half-space).
    pub fn floor_bottom(&self) -> f64 {
        match self.floor {
            Floor::Box => -self.floor_thickness,
            Floor::Plane => f64::NEG_INFINITY,
        }
    }

    /// The drop height is added to this: the longest side (in 2D, of breadth and width).
    pub fn drop_base(&self) -> f64 {
        let b = self.die.block();
        if let Some(s) = self.die.as_shape() {
            // Its bounding box's longest side, or its reach from the centroid if that is more
            // (with a centre of mass moved inside it), so it starts clear however it is turned.
            let com = self
                .features
                .com
                .map_or(0.0, |c| nalgebra::Vector3::from(c).norm());
            return b
                .width
                .max(b.breadth)
                .max(b.length)
                .max(s.circumradius() + com);
        }
        match self.mode {
            Mode::ThreeD => b.width.max(b.breadth).max(b.length),
            Mode::TwoD => b.width.max(b.breadth),
        }
    }
}

impl MassProps {
    /// The mass properties of the scene's die (`MassProps::of_composition`), checked.
    pub fn of(scene: &Scene) -> Result<MassProps> {
        MassProps::of_composition(&scene.composition())
    }

    /// `of` for a scene already checked (`Scene::validate` calls `of`).
    pub fn compute(scene: &Scene) -> MassProps {
        MassProps::compute_composition(&scene.composition())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn damping_is_the_same_rate_in_both_engines() {
        let mut s = Scene::paper("140x24x20".parse().unwrap(), Mode::ThreeD);
        assert_eq!(s.bullet_damping(), (0.0, 0.0));
        assert_eq!(s.rapier_damping(), (0.0, 0.0));
        for rate in [0.5, 5.0, MAX_DAMPING] {
            s.linear_damping = rate;
            s.angular_damping = rate;
            let want = (-rate * s.dt).exp();
            let (d, _) = s.bullet_damping();
            let (c, _) = s.rapier_damping();
            // Bullet: v ← v (1 − d)^dt; Rapier: v ← v / (1 + c dt).
            assert!(((1.0 - d).powf(s.dt) / want - 1.0).abs() < 1e-4, "{rate}");
            assert!(
                ((1.0 / (1.0 + c * s.dt)) / want - 1.0).abs() < 1e-12,
                "{rate}"
            );
        }
        s.validate(false).unwrap();
        for bad in [-1.0, MAX_DAMPING * 1.01, f64::NAN, f64::INFINITY] {
            s.linear_damping = bad;
            assert!(
                matches!(
                    s.validate(false),
                    Err(Error::Field {
                        field: Field::LinearDamping,
                        ..
                    })
                ),
                "{bad}"
            );
        }
    }

    #[test]
    fn a_default_scene_serialises_as_before() {
        let s = Scene::paper("140x24x20".parse().unwrap(), Mode::ThreeD);
        let json = serde_json::to_string(&s).unwrap();
        assert!(
            !json.contains("damping") && !json.contains("sleeping"),
            "{json}"
        );
        let back: Scene = serde_json::from_str(&json).unwrap();
        assert_eq!(back, s);
    }

    /// A die of any shape is written as its specification always wrote it, its bounding box
    /// first and its shape after every other field, and read back as its own bounding box
    /// whatever block the specification holds.
    #[test]
    fn a_shape_s_scene_is_written_block_first_and_read_as_its_own_box() {
        let d20 = crate::model::shape::named("d20", None).unwrap();
        let own = d20.block();
        let s = Scene::paper_shape(d20, Mode::ThreeD);
        let json = serde_json::to_string(&s).unwrap();
        assert!(json.starts_with(&format!(
            "{{\"block\":{}",
            serde_json::to_string(&own).unwrap()
        )));
        let shape_at = json.find("\"shape\":").unwrap();
        assert!(json.find("\"gravity\":").unwrap() < shape_at, "{json}");
        let back: Scene = serde_json::from_str(&json).unwrap();
        assert_eq!(back, s);
        let stale = json.replacen(&format!("{}", own.length), "0.5", 1);
        assert_ne!(stale, json);
        let back: Scene = serde_json::from_str(&stale).unwrap();
        assert_eq!(back.die.block(), own);
    }
}
