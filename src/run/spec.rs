//! A run's specification: everything that decides its result, and nothing that does not
//! (threads, output paths). It is stored with a checkpoint and in every `--json` output;
//! `--resume` reads it back, `merge` compares it, and its key binds a checkpoint's chunks to
//! the run that wrote them.

use crate::engine::EngineKind;
use crate::error::{Error, Field, Result};
use crate::model::scene::Scene;
use crate::model::throws::{ThrowKind, ThrowRanges, ThrowStyle, Throws};
use crate::sim::roll::RollConfig;
use serde::{Deserialize, Serialize};

/// The most rolls one run takes.
pub const MAX_ROLLS: u64 = 1_000_000_000;

/// Where a run's throws come from.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ThrowSpec {
    /// Keyed by (seed, index), or DicePhys's sequence.
    pub kind: ThrowKind,
    /// The seed (a 32-bit `srand` seed for DicePhys's sequence).
    pub seed: u64,
    /// The ranges each throw's numbers are drawn from.
    pub ranges: ThrowRanges,
    /// How each die is thrown: the paper's (left out of the JSON, so that a paper run's
    /// specification and its key are as before), a tumble, or at rest.
    #[serde(default, skip_serializing_if = "ThrowStyle::is_paper")]
    pub style: ThrowStyle,
    /// A hand's throw's concentration κ (`ThrowStyle::Hand`, or a toss thrown in a hand's
    /// directions; left out otherwise).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kappa: Option<f64>,
}

/// The largest concentration κ a hand's throw takes: its angles' spread is then about
/// 1/√κ ≈ 0.06°, the paper's throw for any purpose (`--throw paper` is the limit itself).
pub const MAX_KAPPA: f64 = 1e6;

impl ThrowSpec {
    /// Keyed throws from the paper's ranges.
    pub fn keyed(seed: u64) -> ThrowSpec {
        ThrowSpec {
            kind: ThrowKind::Keyed,
            seed,
            ranges: ThrowRanges::default(),
            style: ThrowStyle::Paper,
            kappa: None,
        }
    }

    /// Keyed throws from the paper's ranges, thrown in `style` (not a hand's: see
    /// [`ThrowSpec::hand`]).
    pub fn keyed_style(seed: u64, style: ThrowStyle) -> ThrowSpec {
        ThrowSpec {
            style,
            ..ThrowSpec::keyed(seed)
        }
    }

    /// Keyed throws from the paper's ranges, thrown by a hand with concentration `kappa`.
    pub fn hand(seed: u64, kappa: f64) -> ThrowSpec {
        ThrowSpec {
            style: ThrowStyle::Hand,
            kappa: Some(kappa),
            ..ThrowSpec::keyed(seed)
        }
    }

    /// Checks the ranges, the seed, and that DicePhys's sequence is thrown the paper's way.
    pub fn validate(&self) -> Result<()> {
        self.ranges.validate()?;
        match (self.style, self.kappa) {
            (ThrowStyle::Hand, None) => {
                return Err(Error::field(
                    Field::Style,
                    "hand",
                    crate::text![
                        "needs ",
                        Field::Kappa,
                        " K (0: the tumble's spread; large: the paper's throw)"
                    ],
                ))
            }
            (ThrowStyle::Hand | ThrowStyle::Toss, Some(k)) if !(0.0..=MAX_KAPPA).contains(&k) => {
                return Err(Error::field(
                    Field::Kappa,
                    k,
                    crate::text![
                        format!("a hand's concentration is 0 to {MAX_KAPPA:e} ("),
                        Field::Style,
                        " paper is the limit of large kappa)"
                    ],
                ))
            }
            (ThrowStyle::Hand | ThrowStyle::Toss, Some(_)) | (_, None) => {}
            (s, Some(_)) => {
                return Err(Error::field(
                    Field::Kappa,
                    "",
                    crate::text![
                        "only ",
                        Field::Style,
                        " hand takes a concentration (and ",
                        Field::Style,
                        " toss, turned a hand's way), not ",
                        Field::Style,
                        format!(" {s}")
                    ],
                ))
            }
        }
        if self.style == ThrowStyle::Rest {
            // A die released at rest has no velocity, spin or drop: a range given is a mistake.
            let (given, paper) = (self.ranges, ThrowRanges::default());
            for (field, g, p) in [
                (Field::Velocity, given.velocity, paper.velocity),
                (Field::Spin, given.spin, paper.spin),
                (Field::DropHeight, given.drop_height, paper.drop_height),
            ] {
                if g != p {
                    return Err(Error::field(
                        field,
                        g,
                        crate::text![
                            Field::Style,
                            " rest releases the die at rest and uses no range; leave ",
                            field,
                            " out"
                        ],
                    ));
                }
            }
        }
        if self.kind == ThrowKind::Dicephys && !self.style.is_paper() {
            return Err(Error::field(
                Field::Style,
                self.style,
                crate::text![
                    "the dicephys throw source draws the paper's throw only; use the keyed \
                     throws (",
                    Field::Kind,
                    " keyed)"
                ],
            ));
        }
        if self.kind == ThrowKind::Dicephys && self.seed > u32::MAX as u64 {
            return Err(Error::field(
                Field::Seed,
                self.seed,
                "the dicephys throw source takes a 32-bit seed (srand)",
            ));
        }
        Ok(())
    }

    /// The throw source, able to give throws `0..n`.
    pub fn source(&self, n: u64) -> Throws {
        Throws::styled(self.kind, self.style, self.kappa, self.seed, self.ranges, n)
    }
}

/// A share of a run's throws: indices i with i mod n = k.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// This share, 0 ≤ k < n.
    pub k: u64,
    /// How many shares.
    pub n: u64,
}

impl Shard {
    /// Checks 0 ≤ k < n.
    pub fn validate(&self) -> Result<()> {
        if self.n == 0 || self.k >= self.n {
            return Err(Error::Invalid(format!(
                "shard {}/{} is not K/N with 0 <= K < N",
                self.k, self.n
            )));
        }
        Ok(())
    }
}

impl std::str::FromStr for Shard {
    type Err = Error;
    fn from_str(s: &str) -> Result<Shard> {
        let bad = || Error::Invalid(format!("shard '{s}' is not K/N with 0 <= K < N"));
        let (k, n) = s.split_once('/').ok_or_else(bad)?;
        let shard = Shard {
            k: k.parse().map_err(|_| bad())?,
            n: n.parse().map_err(|_| bad())?,
        };
        shard.validate().map_err(|_| bad())?;
        Ok(shard)
    }
}

/// Everything that decides a run's result.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunSpec {
    /// The engine.
    pub engine: EngineKind,
    /// The scene: block, surface, time step, 2D or 3D.
    pub scene: Scene,
    /// The throws.
    pub throws: ThrowSpec,
    /// How each roll is carried out and ended.
    pub roll: RollConfig,
    /// Throws 0..rolls (of which a shard takes its share).
    pub rolls: u64,
    /// This run's share of the throws, or all of them.
    pub shard: Option<Shard>,
}

impl RunSpec {
    /// Checks every value before anything runs. A restitution above 1 passes only when the
    /// caller allows it (an engine-stability study).
    pub fn validate(&self, allow_restitution_above_one: bool) -> Result<()> {
        self.scene.validate(allow_restitution_above_one)?;
        self.throws.validate()?;
        self.roll.validate()?;
        // The contact laws Bullet has and the others lack: each refused where it is not, by
        // its flag, with the engines that have it. Rapier's 3D body takes rolling resistance
        // (`Rapier3d::resist_rolling`).
        let s = &self.scene;
        let bullet = self.engine == EngineKind::Bullet;
        for (on, has, field, shown, what, hint) in [
            (
                s.rolling_resistance > 0.0,
                self.engine.resists_rolling(s.mode),
                Field::RollingResistance,
                s.rolling_resistance * 1e3,
                "rolling resistance",
                "give --engine bullet, or rapier in 3D",
            ),
            (
                s.bounce_threshold > 0.0,
                bullet,
                Field::BounceThreshold,
                s.bounce_threshold,
                "bounce threshold",
                "give --engine bullet",
            ),
            (
                s.contact_time > 0.0,
                bullet,
                Field::ContactTime,
                s.contact_time * 1e3,
                "soft contact",
                "give --engine bullet",
            ),
            (
                s.static_ratio != 1.0,
                bullet,
                Field::StaticRatio,
                s.static_ratio,
                "static friction apart from sliding friction",
                "give --engine bullet",
            ),
        ] {
            if on && !has {
                return Err(Error::field(
                    field,
                    shown,
                    format!("{} has no {what}; {hint}", self.engine.name()),
                ));
            }
        }
        if let Some(shape) = self.scene.die.as_shape() {
            use crate::model::throws::ThrowStyle;
            let hands = self.throws.style == ThrowStyle::Toss && self.throws.kappa.is_some();
            if hands || matches!(self.throws.style, ThrowStyle::Paper | ThrowStyle::Hand) {
                return Err(Error::field(
                    Field::Style,
                    self.throws.style.name(),
                    format!(
                        "the paper's throw and a hand's spin a die about its long axis, which \
                         {} has not: use tumble, toss (without kappa), flip or rest",
                        shape.name
                    ),
                ));
            }
        }
        if self.rolls == 0 {
            return Err(Error::field(Field::Rolls, 0, "need at least one roll"));
        }
        if self.rolls > MAX_ROLLS {
            return Err(Error::field(
                Field::Rolls,
                self.rolls,
                format!("at most {MAX_ROLLS}"),
            ));
        }
        if let Some(s) = self.shard {
            s.validate()?;
        }
        Ok(())
    }

    /// A warning, before anything rolls, for a die that may never come to rest (reliability
    /// round 5, class H; issue 48): a coin with no rolling resistance rolls on its rim or its
    /// side, and a cube rounded almost to a ball rolls like one; such rolls run to the step
    /// cap and are counted unconverged.
    pub fn endless_roll_warning(&self) -> Option<String> {
        let s = &self.scene;
        if s.rolling_resistance > 0.0 {
            return None;
        }
        let remedy = if self.engine.resists_rolling(s.mode) {
            "--rolling-resistance 0.05 (mm) lets it stop"
        } else {
            "--engine bullet --rolling-resistance 0.05 (mm) lets it stop"
        };
        let cap = self.roll.max_steps;
        if s.die.is_coin() {
            return Some(format!(
                "a coin with no rolling resistance may roll on its rim or its side until the \
                 step cap ({cap} steps), counted unconverged: {remedy}"
            ));
        }
        let b = s.die.block();
        let half = b.breadth.min(b.width).min(b.length) / 2.0;
        let flat = half - s.features.edge_radius;
        (s.die.hull().is_none() && s.features.edge_radius > 0.0 && flat < 0.1 * half).then(|| {
            format!(
                "the die's faces are flat over only {:.3} mm of their {:.1} mm half side \
                 (edge radius {} mm): it rolls like a ball and may reach the step cap ({cap} \
                 steps), counted unconverged: {remedy}",
                flat * 1e3,
                half * 1e3,
                s.features.edge_radius * 1e3
            )
        })
    }

    /// A note, before anything rolls, for a die loaded off its centre (its centre of mass
    /// 2 % of its smallest half side or more from the geometric centre) rolled on `engines`
    /// under any preset but `laws`: those presets keep each engine's own contact model, off
    /// the closed forms a loaded die that bounces needs (Bullet's bounce, friction and turn;
    /// Rapier's impact and friction: docs/guide.md, "Presets"). The arbiter takes no preset.
    /// Measured (`roll --block 16x16x16 --com 0,0,-1 --throw tumble --rolls 20000 --seed 1`):
    /// face 1 up 4,440 times under dicephys281, 4,311 under laws, 4,318 on the arbiter at
    /// 0.1 ms; face 6 2,530, 2,653 and 2,648 (±82 and ±68 on a difference, 1σ). Loaded 4.5 mm,
    /// P(6 up) is 5 % against the arbiter's 12.4 %.
    pub fn loaded_die_note(&self, engines: &[EngineKind]) -> Option<String> {
        use crate::model::mass::MassProps;
        use crate::model::scene::Preset;
        let s = &self.scene;
        let bodies = engines.iter().any(|e| *e != EngineKind::Moreau);
        if s.preset == Preset::Laws || !bodies {
            return None;
        }
        let b = s.die.block();
        let half = b.breadth.min(b.width).min(b.length) / 2.0;
        let off = MassProps::compute(s).com.norm();
        (off >= 0.02 * half).then(|| {
            format!(
                "a die loaded {:.2} mm off its centre under --preset {} is rolled off the closed \
                 forms a loaded die needs (Bullet's bounce, friction and turn; Rapier's impact \
                 and friction); --preset laws holds each engine to them, and --engine moreau \
                 --dt 1e-4 is the arbiter",
                off * 1e3,
                s.preset.name()
            )
        })
    }

    /// The throw indices this run rolls.
    pub fn indices(&self) -> Indices {
        match self.shard {
            Some(Shard { k, n }) => Indices {
                k,
                n,
                end: self.rolls,
            },
            None => Indices::all(self.rolls),
        }
    }

    /// The same run without its shard: equal for every shard of one run.
    pub fn unsharded(&self) -> RunSpec {
        RunSpec {
            shard: None,
            ..self.clone()
        }
    }

    /// A short, stable key of the whole specification (64-bit FNV-1a of its JSON, in hex):
    /// written into each checkpoint chunk, so that a chunk of another run is never counted.
    /// JSON of this struct is stable: fields in declaration order, floats round-tripped.
    pub fn key(&self) -> String {
        let json = serde_json::to_vec(self).unwrap_or_default();
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        for b in json {
            h ^= b as u64;
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
        format!("{h:016x}")
    }
}

/// The throws of a run or of one shard: indices k, k + n, k + 2n, … below `end`, generated
/// chunk by chunk so that a run of any size holds one chunk's indices at a time.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Indices {
    /// The first index.
    pub k: u64,
    /// The stride.
    pub n: u64,
    /// One past the last index of the whole run.
    pub end: u64,
}

impl Indices {
    /// Every index below `end`.
    pub fn all(end: u64) -> Indices {
        Indices { k: 0, n: 1, end }
    }

    /// How many indices.
    pub fn len(&self) -> u64 {
        if self.k >= self.end {
            0
        } else {
            (self.end - self.k).div_ceil(self.n)
        }
    }

    /// True if there are none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The `c`-th run of at most `size` indices.
    pub fn chunk(&self, c: u64, size: u64) -> Vec<u64> {
        let first = c.saturating_mul(size);
        let last = first.saturating_add(size).min(self.len());
        (first..last).map(|j| self.k + j * self.n).collect()
    }
}
