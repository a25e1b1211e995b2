//! What a roll is asked, by the library's names and units, with the library's defaults. The
//! command line's flags and the Python package's arguments are converted into these requests
//! and nothing more: the library builds the run from them and checks it, so that both front
//! ends make the same run from the same request, and neither holds a default or a check of
//! its own.

use crate::engine::EngineKind;
use crate::error::{Error, Field, Result};
use crate::model::block::Block;
use crate::model::die::Die;
use crate::model::faces::Layout;
use crate::model::mass::Features;
use crate::model::scene::{Floor, Mode, Preset, Scene};
use crate::model::throws::{ThrowKind, ThrowRanges, ThrowStyle, DEFAULT_SEED};
use crate::run::spec::{RunSpec, ThrowSpec};
use crate::sim::roll::{default_max_steps, RollConfig, Rule, DEFAULT_MARGIN};
use std::path::PathBuf;

/// Rolls a run takes when none are asked, and the most a run to a precision may take.
pub const DEFAULT_ROLLS: u64 = 10_000;
/// The most rolls a run to a precision takes when no cap is asked.
pub const DEFAULT_PRECISION_CAP: u64 = 10_000_000;

/// The die as it is made: a block, a named shape, a mesh or a die file, and what departs from
/// the uniform, sharp solid. Lengths in mm.
#[derive(Clone, Debug, Default)]
pub struct DieRequest {
    /// The cuboid, LENGTHxBREADTHxWIDTH; `None` with no shape and no mesh: a 16 mm d6.
    pub block: Option<Block>,
    /// A named shape (`d20`, `coin:D,H`, …) in place of the block.
    pub shape: Option<String>,
    /// A named shape's size, mm.
    pub size: Option<f64>,
    /// A mesh's lengths times this.
    pub scale: Option<f64>,
    /// A die file: a mesh, or TOML; what is given beside it overrides its values.
    pub file: Option<PathBuf>,
    /// Its density, kg/m³ (the file's, else 800).
    pub density: Option<f64>,
    /// Its centre of mass from its geometric centre, mm.
    pub com: Option<[f64; 3]>,
    /// Its pips, DIAMETER,DEPTH in mm.
    pub pips: Option<[f64; 2]>,
    /// Its edges' and corners' radius, mm.
    pub edge_radius: Option<f64>,
    /// A printed die's shell: WALL in mm, INFILL a fraction in [0, 1].
    pub shell: Option<[f64; 2]>,
    /// Its numbering (the file's, else right-handed).
    pub layout: Option<Layout>,
}

impl DieRequest {
    /// The die asked, from its flags and its die file (the flags override the file's
    /// values), checked; a layout beside a die of any shape is refused (it shows its own
    /// labels).
    pub fn resolve(&self) -> Result<Die> {
        let read: crate::model::mass::ReadFile = &crate::run::io::read_die_bytes;
        let shape = crate::model::mass::described_shape(
            self.file.as_deref(),
            self.shape.as_deref(),
            self.size,
            self.scale,
            read,
        )?;
        if let (Some(l), Some(s)) = (self.layout, &shape) {
            return Err(layout_beside(l, s));
        }
        let (mut features, density) = Features::described(
            self.file.as_deref(),
            self.com,
            self.pips,
            self.edge_radius,
            self.shell,
            self.density,
            read,
        )?;
        if let Some(l) = self.layout {
            // The numbering is the run's (in its specification), pips or none.
            features.layout = l;
        }
        // A die of any shape but a box has its edges rounded in its hull; a box's rounding
        // stays the cuboid's (`mass::take_rounding`).
        let mut shape = shape.map(std::sync::Arc::new);
        let (r, name) = (features.edge_radius, shape.as_ref().map(|s| s.name.clone()));
        crate::model::mass::take_rounding(shape.as_mut(), &mut features).map_err(|why| {
            Error::field(
                Field::EdgeRadius,
                r * 1e3,
                format!("{}: {why}", name.unwrap_or_default()),
            )
        })?;
        Ok(Die {
            shape,
            features,
            density,
        })
    }

    /// The die asked ([`DieRequest::resolve`]), a die of any shape resting on the facets it
    /// rests on at its own centre of mass (a loaded die's outcomes; a box's pips drilled as
    /// its labels number its faces): as `fit`, `predict`'s other die and a `die` column's take
    /// it. An error names the flag or file that gave the die.
    pub fn resolve_resting(&self) -> Result<Die> {
        let d = self.resolve()?;
        if d.shape.is_none() {
            return Ok(d);
        }
        // At its own density: an insert's weight moves the centre of mass by its density
        // against the body's.
        let scene = d
            .scene(DEFAULT_CUBOID, Mode::ThreeD)
            .resting_at_com()
            .map_err(|e| self.at_its_centre_of_mass(&e))?;
        Ok(Die {
            shape: scene.die.into_shape(),
            features: scene.features,
            density: d.density,
        })
    }

    /// Why the die cannot rest at its own centre of mass, named by the flag or file that gave
    /// it.
    fn at_its_centre_of_mass(&self, why: &str) -> Error {
        let (field, value) = match &self.file {
            Some(p) => (Field::Die, p.display().to_string()),
            None => (Field::Shape, self.shape.clone().unwrap_or_default()),
        };
        Error::field(field, value, format!("at its centre of mass: {why}"))
    }
}

/// The scene asked: the die, its surface, its floor, the time step.
#[derive(Clone, Debug)]
pub struct SceneRequest {
    /// The die.
    pub die: DieRequest,
    /// DicePhys's 2D mode.
    pub two_d: bool,
    /// The fixed time step, s.
    pub dt: f64,
    /// The contact's μ.
    pub friction: f64,
    /// The contact's e.
    pub restitution: f64,
    /// Allow e above 1 (an engine-stability study).
    pub allow_restitution_above_one: bool,
    /// Bullet's solver settings.
    pub preset: Preset,
    /// The floor.
    pub floor: Floor,
    /// The box floor's thickness, m (`None`: DicePhys's).
    pub floor_thickness: Option<f64>,
    /// Damping rates, 1/s.
    pub linear_damping: f64,
    /// Damping rates, 1/s.
    pub angular_damping: f64,
    /// Rolling resistance's lever arm, mm (`None`: the die's own default on its engine,
    /// `Scene::default_rolling_resistance`).
    pub rolling_resistance_mm: Option<f64>,
    /// The bounce threshold, m/s (0: none).
    pub bounce_threshold: f64,
    /// The contact time, ms (0: the rigid contact).
    pub contact_time_ms: f64,
    /// Static friction over sliding friction (1: one friction).
    pub static_ratio: f64,
    /// Let the engine put the die to sleep.
    pub sleep: bool,
}

impl Default for SceneRequest {
    /// The paper's scene (`Scene::paper`): its values are the defaults.
    fn default() -> Self {
        let paper = Scene::paper(DEFAULT_CUBOID, Mode::ThreeD);
        SceneRequest {
            die: DieRequest::default(),
            two_d: false,
            dt: paper.dt,
            friction: paper.friction,
            restitution: paper.restitution,
            allow_restitution_above_one: false,
            preset: paper.preset,
            floor: paper.floor,
            floor_thickness: None,
            linear_damping: paper.linear_damping,
            angular_damping: paper.angular_damping,
            rolling_resistance_mm: None,
            bounce_threshold: 0.0,
            contact_time_ms: 0.0,
            static_ratio: paper.static_ratio,
            sleep: paper.sleeping,
        }
    }
}

/// The default die where it is made as only a cuboid is: the 16 mm cube (the default d6's).
pub const DEFAULT_CUBOID: Block = Block {
    length: 0.016,
    breadth: 0.016,
    width: 0.016,
};

impl SceneRequest {
    /// True if no die is named but what is asked of it is a cuboid's: pips, rounded edges, an
    /// insert, an inertia or a numbering of its faces (flags, or a die file with no mesh).
    fn default_is_cuboid(&self, f: &Features) -> bool {
        let d = &self.die;
        d.layout.is_some()
            || d.pips.is_some()
            || d.edge_radius.is_some()
            || f.pips.is_some()
            || f.edge_radius > 0.0
            || f.insert.is_some()
            || f.inertia.is_some()
            || f.layout != crate::model::faces::Layout::default()
    }

    /// The scene, with every value checked before anything runs.
    pub fn scene(&self) -> Result<Scene> {
        let d = &self.die;
        let mut die = d.resolve()?;
        let mode = if self.two_d { Mode::TwoD } else { Mode::ThreeD };
        let block = match (d.block, &die.shape) {
            (Some(_), Some(_)) => {
                return Err(Error::field(
                    Field::Block,
                    "",
                    crate::text![
                        "is the cuboid; ",
                        Field::Shape,
                        " or a mesh ",
                        Field::Die,
                        " replaces it: give one"
                    ],
                ))
            }
            (Some(b), None) => b,
            (None, Some(_)) => DEFAULT_CUBOID,
            // No die given: a 16 mm d6 (rolled as the box it is); the 16 mm cube as the
            // cuboid where the die is made as only a cuboid is (pips, rounded edges, an
            // insert, its inertia, its faces' numbering), so that what is asked applies to
            // the die rolled as before.
            (None, None) if self.default_is_cuboid(&die.features) => DEFAULT_CUBOID,
            (None, None) => {
                die.shape = Some(std::sync::Arc::new(crate::model::shape::named("d6", None)?));
                DEFAULT_CUBOID
            }
        };
        let mut scene = die.scene(block, mode);
        scene.dt = self.dt;
        scene.friction = self.friction;
        scene.restitution = self.restitution;
        scene.preset = self.preset;
        scene.floor = self.floor;
        scene.linear_damping = self.linear_damping;
        scene.rolling_resistance = self.rolling_resistance_mm.unwrap_or(0.0) / 1000.0;
        scene.bounce_threshold = self.bounce_threshold;
        scene.contact_time = self.contact_time_ms / 1000.0;
        scene.static_ratio = self.static_ratio;
        scene.angular_damping = self.angular_damping;
        scene.sleeping = self.sleep;
        if let Some(t) = self.floor_thickness {
            scene.set_floor_thickness(t)?;
        }
        scene.validate(self.allow_restitution_above_one)?;
        // A loaded die's outcomes are the facets it rests on at its own centre of mass.
        scene
            .resting_at_com()
            .map_err(|e| d.at_its_centre_of_mass(&e))
    }
}

/// A layout given beside a die of any shape (a named one, a mesh, or the default d6): it
/// numbers a cuboid's faces, and this die shows its own labels.
pub fn layout_beside(l: Layout, shape: &crate::model::shape::Shape) -> Error {
    Error::field(
        Field::Layout,
        l,
        crate::text![
            "numbers a cuboid's faces (",
            Field::Block,
            "); ",
            shape.name.clone(),
            " shows its own labels"
        ],
    )
}

/// Where the throws come from and how the die is thrown.
#[derive(Clone, Debug)]
pub struct ThrowRequest {
    /// Keyed, or DicePhys's sequence.
    pub source: ThrowKind,
    /// The seed.
    pub seed: u64,
    /// The ranges its numbers are drawn from.
    pub ranges: ThrowRanges,
    /// How the die is thrown (`None`: the command's own default, or a hand's if `kappa`).
    pub style: Option<ThrowStyle>,
    /// A hand's concentration κ.
    pub kappa: Option<f64>,
}

impl Default for ThrowRequest {
    fn default() -> Self {
        ThrowRequest {
            source: ThrowKind::Keyed,
            seed: DEFAULT_SEED,
            ranges: ThrowRanges::default(),
            style: None,
            kappa: None,
        }
    }
}

impl ThrowRequest {
    /// The throws, checked, in the style asked; else a hand's if κ is given, else `default`.
    pub fn spec_or(&self, default: ThrowStyle) -> Result<ThrowSpec> {
        let style = self.style.unwrap_or(if self.kappa.is_some() {
            ThrowStyle::Hand
        } else {
            default
        });
        let spec = ThrowSpec {
            kind: self.source,
            seed: self.seed,
            ranges: self.ranges,
            style,
            kappa: self.kappa,
        };
        spec.validate()?;
        Ok(spec)
    }
}

/// How each roll is carried out and ended.
#[derive(Clone, Debug)]
pub struct EndRequest {
    /// The rest rule (`None`: the early stop where it is exact, else DicePhys's rule).
    pub settle: Option<Rule>,
    /// Free flight integrated outside the engine (else every step by the engine).
    pub fast_flight: bool,
    /// DicePhys exactly as the paper ran it.
    pub faithful: bool,
    /// Settle by DicePhys's rule and record the certificate's verdict beside it.
    pub audit: bool,
    /// The step cap (`None`: DicePhys's, or a die of any shape's).
    pub max_steps: Option<u64>,
    /// The certificate's reserve.
    pub margin: f64,
}

impl Default for EndRequest {
    fn default() -> Self {
        EndRequest {
            settle: None,
            fast_flight: true,
            faithful: false,
            audit: false,
            max_steps: None,
            margin: DEFAULT_MARGIN,
        }
    }
}

impl EndRequest {
    /// How each roll of `scene` is carried out and ended, checked: the step cap DicePhys's,
    /// or for a die of any shape `SHAPE_MAX_STEPS` (a cylinder rolling on its side stops only
    /// by rolling resistance).
    pub fn roll(&self, scene: &Scene) -> Result<RollConfig> {
        self.roll_at(scene.dt, self.cap(scene))
    }

    /// The step cap of each roll of `scene`: the one asked, or the die's default
    /// ([`default_max_steps`]).
    pub fn cap(&self, scene: &Scene) -> u64 {
        self.max_steps.unwrap_or_else(|| default_max_steps(scene))
    }

    /// How each roll at time step `dt` is carried out, with the step cap `max_steps`.
    pub fn roll_at(&self, dt: f64, max_steps: u64) -> Result<RollConfig> {
        RollConfig::chosen(
            dt,
            self.settle,
            self.fast_flight,
            self.faithful,
            self.audit,
            max_steps,
            self.margin,
        )
    }
}

/// A whole roll asked: the scene, the throws, how each roll ends, the engine and how many.
#[derive(Clone, Debug)]
pub struct RollRequest {
    /// The scene.
    pub scene: SceneRequest,
    /// The throws.
    pub throws: ThrowRequest,
    /// How each roll ends.
    pub end: EndRequest,
    /// The engine.
    pub engine: EngineKind,
    /// Rolls (`None`: [`DEFAULT_ROLLS`], or [`DEFAULT_PRECISION_CAP`] for a run to a
    /// precision).
    pub rolls: Option<u64>,
    /// Rolled to a precision: `rolls` is then its cap.
    pub to_precision: bool,
    /// Only the throws of one shard.
    pub shard: Option<crate::run::spec::Shard>,
}

impl Default for RollRequest {
    fn default() -> Self {
        RollRequest {
            scene: SceneRequest::default(),
            throws: ThrowRequest::default(),
            end: EndRequest::default(),
            engine: EngineKind::Bullet,
            rolls: None,
            to_precision: false,
            shard: None,
        }
    }
}

impl RollRequest {
    /// The rolls asked, or the default ([`DEFAULT_ROLLS`]; a run to a precision's cap
    /// [`DEFAULT_PRECISION_CAP`]).
    pub fn rolls(&self) -> u64 {
        self.rolls.unwrap_or(if self.to_precision {
            DEFAULT_PRECISION_CAP
        } else {
            DEFAULT_ROLLS
        })
    }

    /// The run, checked, its throws in the style asked, else the paper's (a die of any shape,
    /// which has no long axis to spin about: a tumble).
    pub fn spec(&self) -> Result<RunSpec> {
        self.spec_or(ThrowStyle::Paper)
    }

    /// The run, checked, its throws in the style asked, else `default` (a die of any shape: a
    /// tumble).
    pub fn spec_or(&self, default: ThrowStyle) -> Result<RunSpec> {
        let mut scene = self.scene.scene()?;
        // The default die is thrown in a tumble, as the d6 it stands for (the paper's throw
        // spins a cube about one axis).
        let defaulted = self.scene.die.block.is_none() && scene.die.as_shape().is_none();
        // Unless one is asked: a coin rolls against a hard table's resistance where the engine
        // has it (with none, a coin on its rim rolls to the step cap); every other die against
        // none, as DicePhys.
        if self.scene.rolling_resistance_mm.is_none()
            && scene.die.is_coin()
            && self.engine.resists_rolling(scene.mode)
        {
            scene.rolling_resistance = crate::model::scene::COIN_ROLLING_RESISTANCE;
        }
        let default = match ThrowStyle::default_for(&scene) {
            ThrowStyle::Paper if defaulted => ThrowStyle::Tumble,
            ThrowStyle::Paper => default,
            other => other,
        };
        let spec = RunSpec {
            engine: self.engine,
            roll: self.end.roll(&scene)?,
            throws: self.throws.spec_or(default)?,
            scene,
            rolls: self.rolls(),
            shard: self.shard,
        };
        spec.validate(self.scene.allow_restitution_above_one)?;
        Ok(spec)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::roll::{DEFAULT_MAX_STEPS, SHAPE_MAX_STEPS};

    fn scene_of(die: DieRequest) -> Scene {
        SceneRequest {
            die,
            ..SceneRequest::default()
        }
        .scene()
        .unwrap()
    }

    #[test]
    fn the_step_cap_is_the_dies_unless_asked() {
        // Issue 69.10: `trace` took DicePhys's 20,000,000 for a coin where `roll` took a die
        // of any shape's 200,000; both now ask `EndRequest::cap`.
        let coin = scene_of(DieRequest {
            shape: Some("coin:24,8.5".into()),
            ..DieRequest::default()
        });
        let block = scene_of(DieRequest {
            block: Some("140x24x20".parse().unwrap()),
            ..DieRequest::default()
        });
        let end = EndRequest::default();
        assert_eq!(end.cap(&coin), SHAPE_MAX_STEPS);
        assert_eq!(end.roll(&coin).unwrap().max_steps, SHAPE_MAX_STEPS);
        assert_eq!(end.cap(&block), DEFAULT_MAX_STEPS);
        let asked = EndRequest {
            max_steps: Some(500),
            ..EndRequest::default()
        };
        assert_eq!(asked.cap(&coin), 500);
        assert_eq!(asked.cap(&block), 500);
    }
}
