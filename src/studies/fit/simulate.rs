//! Rolling the designs of a fit: each parameter point a cell of its own (resumable, keyed).

use crate::calibration::design::{points, Design, DesignSpec, Key};
use crate::calibration::params::{self, Method, ModelSpec};
use crate::error::Result;
use crate::inference::surrogate::{DesignPoint, Surrogate};
use crate::model::scene::Mode;
use crate::run::runner::Runner;
use std::path::Path;

/// Everything `simulate` needs.
pub struct Plan<'a> {
    /// The model (which parameters are free, their ranges).
    pub model: &'a ModelSpec,
    /// How each throw is simulated.
    pub method: &'a Method,
    /// How densely.
    pub design: &'a DesignSpec,
    /// The run's seed.
    pub seed: u64,
}

impl Plan<'_> {
    /// The rolls `simulate` makes for `keys`.
    pub fn total_rolls(&self, keys: usize) -> u64 {
        let dims = self.model.free.len();
        keys as u64 * points(dims, self.design.points).len() as u64 * self.design.rolls
    }
}

/// Simulates every key over the design (each point a cell of its own under `dir`, resumed
/// from there) and fits its surrogate. `None` if a stop request ended it early: what was rolled
/// is kept in `dir`.
pub fn simulate(
    plan: &Plan,
    keys: &[Key],
    runner: &Runner,
    dir: Option<&Path>,
) -> Result<Option<Vec<Design>>> {
    let dims = plan.model.free.len();
    let xs = points(dims, plan.design.points);
    let mut done_before = 0u64;
    let mut out = Vec::new();
    for key in keys {
        let (block, mode) = (key.block, key.mode);
        let mut design_points = Vec::new();
        let (mut unsettled, mut rolls) = (0u64, 0u64);
        for (g, x) in xs.iter().enumerate() {
            let values = params::values(&plan.model.fixed, &key.axes, x);
            let seed = key.seed(plan.seed, g);
            let spec = plan
                .method
                .spec(block, mode, &values, seed, plan.design.rolls);
            spec.validate(false)?;
            let ck = match dir {
                Some(d) => Some(
                    runner.open_cell(&d.join(key.tag()).join(format!("point-{g:05}")), &spec)?,
                ),
                None => None,
            };
            let base = done_before;
            let progress = |n| (runner.progress)(base + n);
            let done = runner
                .with_progress(&progress)
                .run(&spec, ck.as_ref(), &mut |_| Ok(()))?;
            done_before += plan.design.rolls;
            if !done.complete {
                return Ok(None);
            }
            let t = &done.tally;
            unsettled += t.rolls - (t.counts.length + t.counts.breadth + t.counts.width);
            rolls += t.rolls;
            design_points.push(DesignPoint {
                x: x.clone(),
                counts: vec![t.counts.length, t.counts.breadth, t.counts.width],
            });
        }
        // A 2D block has no length outcome: its surrogate is over breadth and width.
        let (outcomes, pts): (usize, Vec<DesignPoint>) = match mode {
            Mode::ThreeD => (3, design_points.clone()),
            Mode::TwoD => (
                2,
                design_points
                    .iter()
                    .map(|p| DesignPoint {
                        x: p.x.clone(),
                        counts: p.counts[1..].to_vec(),
                    })
                    .collect(),
            ),
        };
        let surrogate = Surrogate::fit_best(
            &pts,
            dims,
            outcomes,
            plan.design.degree,
            plan.design.max_degree,
        );
        out.push(Design {
            block,
            mode,
            axes: key.axes.clone(),
            points: design_points,
            unsettled,
            rolls,
            surrogate,
        });
    }
    Ok(Some(out))
}
