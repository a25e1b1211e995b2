//! Command-line arguments shared by the commands that simulate.

use crate::block::Block;
use crate::engine::EngineKind;
use crate::error::{Error, Result};
use crate::roll::{Rule, Settle, DEFAULT_MARGIN, DEFAULT_MAX_STEPS};
use crate::scene::{Floor, Mode, Preset, Scene};
use crate::throws::{Range, ThrowKind, ThrowRanges};
use clap::Args;

/// The scene: the block, the surface, the time step.
#[derive(Args, Debug, Clone)]
pub struct SceneArgs {
    /// The block, LENGTHxBREADTHxWIDTH in mm (the paper's order), e.g. 140x24x20.
    #[arg(long, value_parser = parse_block)]
    pub block: Block,
    /// DicePhys's 2D mode: a 1 m deep box locked to the x-y plane.
    #[arg(long = "2d")]
    pub two_d: bool,
    /// Fixed time step, s (the paper: 0.001).
    #[arg(long, default_value_t = 0.001)]
    pub dt: f64,
    /// The contact's friction coefficient μ (the die's; the floor's is 1).
    #[arg(long, default_value_t = 0.29)]
    pub friction: f64,
    /// The contact's restitution e (the die's; the floor's is 1).
    #[arg(long, default_value_t = 0.5)]
    pub restitution: f64,
    /// Allow a restitution above 1 (an engine-stability study, not physics).
    #[arg(long)]
    pub allow_restitution_above_one: bool,
    /// The die's density, kg/m³.
    #[arg(long, default_value_t = 800.0)]
    pub density: f64,
    /// Bullet solver settings: dicephys281 (Bullet 2.81 as the paper ran it) or bullet3.
    #[arg(long, default_value = "dicephys281", value_parser = parse_preset)]
    pub preset: Preset,
    /// The floor: box (DicePhys's 10 km static box) or plane.
    #[arg(long, default_value = "box", value_parser = parse_floor)]
    pub floor: Floor,
    /// The box floor's thickness, m (DicePhys's: 100). A table top (0.02) is thin enough for
    /// a die to pass through at a coarse step: a real tunnel, counted as failed.
    #[arg(long, value_name = "M", allow_hyphen_values = true)]
    pub floor_thickness: Option<f64>,
}

/// Where the throws come from.
#[derive(Args, Debug, Clone)]
pub struct ThrowArgs {
    /// Seed of the throws.
    #[arg(long, default_value_t = 2385)]
    pub seed: u64,
    /// keyed (each throw from (seed, index)) or dicephys (DicePhys's glibc rand() sequence).
    #[arg(long, default_value = "keyed", value_parser = parse_throw_kind)]
    pub throws: ThrowKind,
    /// Linear velocity along x, m/s: LO:HI, or one number.
    #[arg(long, default_value = "-0.2:0.2", value_parser = parse_range, allow_hyphen_values = true)]
    pub velocity: Range,
    /// Spin about the length axis, rad/s: LO:HI, or one number.
    #[arg(long, default_value = "31:160", value_parser = parse_range, allow_hyphen_values = true)]
    pub spin: Range,
    /// Drop height added to the longest side, m: LO:HI, or one number.
    #[arg(long, default_value = "0.2:0.4", value_parser = parse_range, allow_hyphen_values = true)]
    pub drop_height: Range,
}

/// How many rolls, how.
#[derive(Args, Debug, Clone)]
pub struct RunArgs {
    /// Number of rolls.
    #[arg(long, default_value_t = 10_000)]
    pub rolls: u64,
    /// Worker threads (0: one per core).
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    /// Steps after which a roll not at rest counts as unconverged.
    #[arg(long, default_value_t = DEFAULT_MAX_STEPS)]
    pub max_steps: u64,
    /// What ends a roll: certificate (the exact early stop: energy below the barrier out of
    /// the current face) or dicephys (at rest by DicePhys's rule). Default: certificate at
    /// dt <= 1/250 s, where it is audited exact; dicephys at coarser steps.
    #[arg(long, value_parser = ["dicephys", "certificate"])]
    pub settle: Option<String>,
    /// The certificate's reserve, a fraction of the barrier in [0, 1).
    #[arg(long, default_value_t = DEFAULT_MARGIN)]
    pub margin: f64,
    /// Settle by DicePhys's rule but record when the certificate would have stopped each roll
    /// and whether it named the same outcome.
    #[arg(long)]
    pub audit: bool,
    /// Free flight: fast (integrated in closed form where the engine's flight is ballistic,
    /// the default) or stepped (every step by the engine).
    #[arg(long, default_value = "fast", value_parser = ["fast", "stepped"])]
    pub flight: String,
    /// DicePhys exactly as the paper ran it: --settle dicephys --flight stepped (with the
    /// defaults --floor box --preset dicephys281).
    #[arg(long)]
    pub faithful: bool,
}

pub fn parse_block(s: &str) -> std::result::Result<Block, String> {
    s.parse()
}
pub fn parse_range(s: &str) -> std::result::Result<Range, String> {
    s.parse()
}
pub fn parse_preset(s: &str) -> std::result::Result<Preset, String> {
    s.parse()
}
pub fn parse_floor(s: &str) -> std::result::Result<Floor, String> {
    s.parse()
}
pub fn parse_throw_kind(s: &str) -> std::result::Result<ThrowKind, String> {
    s.parse()
}
pub fn parse_engine(s: &str) -> std::result::Result<EngineKind, String> {
    s.parse()
}

fn usage(msg: String) -> Error {
    Error::Usage(msg)
}

impl SceneArgs {
    /// The scene, with every value checked before anything runs.
    pub fn scene(&self) -> Result<Scene> {
        let mode = if self.two_d { Mode::TwoD } else { Mode::ThreeD };
        if !(self.dt.is_finite() && self.dt > 0.0 && self.dt <= 0.1) {
            return Err(usage(format!("--dt {}: must be in (0, 0.1] s", self.dt)));
        }
        if !(self.friction.is_finite() && self.friction >= 0.0) {
            return Err(usage(format!(
                "--friction {}: must be finite and >= 0",
                self.friction
            )));
        }
        let e_max = if self.allow_restitution_above_one {
            10.0
        } else {
            1.0
        };
        if !(self.restitution.is_finite() && self.restitution >= 0.0 && self.restitution <= e_max) {
            return Err(usage(format!(
                "--restitution {}: must be in [0, 1] (above 1 only with --allow-restitution-above-one)",
                self.restitution
            )));
        }
        if !(self.density.is_finite() && self.density > 0.0 && self.density <= 1e5) {
            return Err(usage(format!(
                "--density {}: must be in (0, 100000] kg/m³",
                self.density
            )));
        }
        let mut scene = Scene::paper(self.block, mode);
        scene.dt = self.dt;
        scene.friction = self.friction;
        scene.restitution = self.restitution;
        scene.density = self.density;
        scene.preset = self.preset;
        scene.floor = self.floor;
        if let Some(t) = self.floor_thickness {
            if self.floor == Floor::Plane {
                return Err(usage(
                    "--floor-thickness: the plane floor is a half-space; use --floor box".into(),
                ));
            }
            if !(0.001..=crate::scene::DICEPHYS_FLOOR_THICKNESS).contains(&t) {
                return Err(usage(format!(
                    "--floor-thickness {t}: must be in [0.001, 100] m"
                )));
            }
            scene.floor_thickness = t;
        }
        Ok(scene)
    }
}

impl ThrowArgs {
    pub fn ranges(&self) -> Result<ThrowRanges> {
        if self.spin.lo < 0.0 {
            return Err(usage(format!("--spin {}: must be >= 0 rad/s", self.spin)));
        }
        if self.drop_height.lo < 0.0 {
            return Err(usage(format!(
                "--drop-height {}: must be >= 0 m",
                self.drop_height
            )));
        }
        for (name, r, max) in [
            ("--velocity", self.velocity, 100.0),
            ("--spin", self.spin, 10_000.0),
            ("--drop-height", self.drop_height, 100.0),
        ] {
            if r.lo.abs() > max || r.hi.abs() > max {
                return Err(usage(format!(
                    "{name} {r}: magnitudes above {max} are not accepted"
                )));
            }
        }
        if self.throws == ThrowKind::Dicephys && self.seed > u32::MAX as u64 {
            return Err(usage(format!(
                "--seed {}: the dicephys throw source takes a 32-bit seed (srand)",
                self.seed
            )));
        }
        Ok(ThrowRanges {
            velocity: self.velocity,
            spin: self.spin,
            drop_height: self.drop_height,
        })
    }
}

impl RunArgs {
    /// Checks the values; the settling as at the paper's dt, 1 ms (`check_at` for a scene's).
    pub fn check(&self) -> Result<Settle> {
        self.check_at(0.001)
    }

    /// Checks the values; the settling for a scene with time step `dt` (the early stop by
    /// default only where it is exact, `roll::EARLY_STOP_MAX_DT`).
    pub fn check_at(&self, dt: f64) -> Result<Settle> {
        if self.rolls == 0 {
            return Err(usage("--rolls 0: need at least one roll".into()));
        }
        if self.rolls > 1_000_000_000 {
            return Err(usage(format!("--rolls {}: at most 1e9", self.rolls)));
        }
        if self.max_steps == 0 {
            return Err(usage("--max-steps 0: need at least one step".into()));
        }
        if self.threads > 1024 {
            return Err(usage(format!("--threads {}: at most 1024", self.threads)));
        }
        if !(self.margin.is_finite() && (0.0..1.0).contains(&self.margin)) {
            return Err(usage(format!(
                "--margin {}: must be in [0, 1)",
                self.margin
            )));
        }
        // An audit compares the certificate with the full settle, so it settles fully.
        let certificate = match self.settle.as_deref() {
            Some(s) => s == "certificate",
            None => crate::roll::early_stop_exact(dt),
        };
        let rule = if certificate && !self.faithful && !self.audit {
            Rule::Certificate
        } else {
            Rule::Dicephys
        };
        Ok(Settle {
            max_steps: self.max_steps,
            rule,
            margin: self.margin,
            audit: self.audit,
            fast_flight: self.flight == "fast" && !self.faithful,
        })
    }
}
