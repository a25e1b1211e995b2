//! What a fit is asked, by the library's names, with the library's defaults: the command
//! line's `fit` flags and the Python package's `fit()` arguments are converted into a
//! [`FitRequest`] and nothing more; the library builds the fit's configuration from it and
//! checks it, so that both front ends make the same fit and neither holds a default or a check
//! of its own.

use super::data::{self, DataRow};
use super::design::DesignSpec;
use super::estimate::Search;
use super::params::{Fixed, FixedThrow, Kind, Method, ModelSpec};
use super::FitConfig;
use crate::engine::EngineKind;
use crate::error::{Error, Field, Result};
use crate::model::throws::{Range, DEFAULT_SEED};
use crate::run::request::DieRequest;
use crate::sim::roll::DEFAULT_MAX_STEPS;

/// A fit asked.
#[derive(Clone, Debug)]
pub struct FitRequest {
    /// The measured counts, as read.
    pub rows: Vec<DataRow>,
    /// The free parameters, in any order, each once.
    pub free: Vec<Kind>,
    /// Surface parameters shared by every surface.
    pub shared: Vec<Kind>,
    /// A free parameter's box in place of its default range, each once.
    pub ranges: Vec<(Kind, Range)>,
    /// e where it is not free.
    pub restitution: f64,
    /// μ where it is not free.
    pub friction: f64,
    /// The throw where κ is not free (`None`: the paper's; a die of any shape's, the tumble).
    pub throw: Option<FixedThrow>,
    /// The spin's scale where it is not free.
    pub spin_scale: f64,
    /// The die thrown, as `roll` takes it (its `block` unused: every row names its own).
    pub die: DieRequest,
    /// The engine.
    pub engine: EngineKind,
    /// The time step, s.
    pub dt: f64,
    /// The step cap per roll; left at [`DEFAULT_MAX_STEPS`], a die of any shape takes its own
    /// (`roll::SHAPE_MAX_STEPS`), as `roll` gives it.
    pub max_steps: u64,
    /// Parameter points per block per pass.
    pub points: usize,
    /// Rolls at each point.
    pub point_rolls: u64,
    /// The surrogate's first degree (`None`: the default for the die's outcomes).
    pub degree: Option<usize>,
    /// Its highest degree (`None`: the default).
    pub max_degree: Option<usize>,
    /// A second pass over the box the first narrows to (and the passes after it).
    pub refine: bool,
    /// The same throws at every design point.
    pub common_throws: bool,
    /// The throws' seed, and the search's.
    pub seed: u64,
}

impl Default for FitRequest {
    fn default() -> Self {
        let (fixed, design) = (Fixed::default(), DesignSpec::default());
        FitRequest {
            rows: Vec::new(),
            free: vec![Kind::E, Kind::Mu],
            shared: Vec::new(),
            ranges: Vec::new(),
            restitution: fixed.e,
            friction: fixed.mu,
            throw: None,
            spin_scale: fixed.spin,
            die: DieRequest::default(),
            engine: EngineKind::Bullet,
            dt: crate::run::request::SceneRequest::default().dt,
            max_steps: DEFAULT_MAX_STEPS,
            points: design.points,
            point_rolls: design.rolls,
            degree: None,
            max_degree: None,
            refine: true,
            common_throws: false,
            seed: DEFAULT_SEED,
        }
    }
}

/// Refuses a parameter named twice in one list (which of the two was meant?).
fn once(field: Field, kinds: impl Iterator<Item = Kind>) -> Result<()> {
    let mut seen = Vec::new();
    for k in kinds {
        if seen.contains(&k) {
            return Err(Error::field(
                field,
                "",
                format!("{k} is given twice; give each parameter once"),
            ));
        }
        seen.push(k);
    }
    Ok(())
}

impl FitRequest {
    /// The model; `shape`: the die is of any shape, thrown in a tumble unless a throw is
    /// asked.
    fn model(&self, shape: bool) -> Result<ModelSpec> {
        once(Field::Free, self.free.iter().copied())?;
        once(Field::Shared, self.shared.iter().copied())?;
        once(Field::Range, self.ranges.iter().map(|r| r.0))?;
        let mut free = self.free.clone();
        free.sort();
        let mut model = ModelSpec::free(&free);
        for (kind, r) in &self.ranges {
            let i = free.iter().position(|k| k == kind).ok_or_else(|| {
                Error::field(
                    Field::Range,
                    "",
                    crate::text![format!("{kind} is not among "), Field::Free],
                )
            })?;
            model.ranges[i] = *r;
        }
        model.shared = self.shared.clone();
        model.fixed = Fixed {
            e: self.restitution,
            mu: self.friction,
            throw: self.throw.unwrap_or(if shape {
                FixedThrow::Tumble
            } else {
                FixedThrow::Paper
            }),
            spin: self.spin_scale,
            ..Fixed::default()
        };
        model.validate()?;
        Ok(model)
    }

    /// The fit's configuration, checked.
    pub fn config(&self) -> Result<FitConfig> {
        // A loaded die's outcomes are the facets it rests on at its own centre of mass.
        let die = self.die.resolve_resting()?;
        // The rows' own dice (a `die` column): each row read against its die, the rest
        // against the command line's.
        let dice = super::dice::resolve_rows(&self.rows)?;
        let own = |r: &DataRow| dice.iter().find(|d| Some(&d.name) == r.die.as_ref());
        let mut rows = Vec::with_capacity(self.rows.len());
        for r in &self.rows {
            let read = match own(r).map_or(&die.shape, |d| &d.die.shape) {
                Some(s) => data::on_shape(std::slice::from_ref(r), s),
                None => Ok(vec![r.clone()]),
            };
            rows.extend(read.map_err(|e| Error::field(Field::Data, "", e.to_string()))?);
        }
        // The surrogate's degree for the die of most outcomes.
        let outcomes = dice
            .iter()
            .map(|d| &d.die)
            .chain(die.shape.is_some().then_some(&die))
            .map(crate::model::die::Die::outcomes)
            .max()
            .unwrap_or(6);
        let (degree, max_degree) = DesignSpec::degrees(self.degree, self.max_degree, outcomes);
        // The step cap left at DicePhys's is the die's, as `roll`'s (`roll::default_max_steps`):
        // a die of any shape that never comes to rest (a rounded die rocking, a coin rolling on
        // its rim) ends unconverged at 200 s, not at 20,000 s, which made a rounding fit of V1
        // take hours.
        let max_steps =
            if self.max_steps == DEFAULT_MAX_STEPS && (die.shape.is_some() || !dice.is_empty()) {
                crate::sim::roll::SHAPE_MAX_STEPS
            } else {
                self.max_steps
            };
        let cfg = FitConfig {
            rows,
            model: self.model(die.shape.is_some() || !dice.is_empty())?,
            method: Method {
                engine: self.engine,
                dt: self.dt,
                max_steps,
                die,
                dice,
            },
            design: DesignSpec {
                points: self.points,
                rolls: self.point_rolls,
                degree,
                max_degree,
                refine: self.refine,
                common: self.common_throws,
            },
            search: Search {
                seed: self.seed,
                ..Search::default()
            },
            seed: self.seed,
        };
        cfg.validate()?;
        Ok(cfg)
    }
}
