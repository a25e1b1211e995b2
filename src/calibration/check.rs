//! Is the fit's simulation method accurate enough for the data? At the fitted parameters, each
//! block rolled by the fit's method and by a finer reference on the same keyed throws; their
//! difference in P(breadth vertical) and P(length vertical), paired throw by throw, against
//! the data's own binomial error on that block (the smallest of its rows'). The rolling is
//! [`crate::studies::fit::check`]'s.

use crate::model::block::Block;
use crate::model::scene::Mode;
use serde::{Deserialize, Serialize};

/// A departure of one probability, paired: the method's less the reference's, and its error.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Departure {
    /// p(method) − p(reference).
    pub value: f64,
    /// Its standard error from the paired throws: √(Var(I_m − I_r)/n).
    pub err: f64,
}

impl Departure {
    /// The departure of two paired series of indicators (one per throw).
    pub fn paired(method: &[bool], reference: &[bool]) -> Departure {
        let n = method.len().min(reference.len());
        if n < 2 {
            return Departure {
                value: f64::NAN,
                err: f64::NAN,
            };
        }
        let d: Vec<f64> = method
            .iter()
            .zip(reference)
            .map(|(&a, &b)| a as u8 as f64 - b as u8 as f64)
            .collect();
        let mean = d.iter().sum::<f64>() / n as f64;
        let var = d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
        Departure {
            value: mean,
            err: (var / n as f64).sqrt(),
        }
    }
}

/// One block's check.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct BlockCheck {
    /// The block.
    pub block: Block,
    /// 2D or 3D.
    pub mode: Mode,
    /// Throws rolled by each method (settled by both).
    pub rolls: u64,
    /// P(breadth vertical)'s departure.
    pub breadth: Departure,
    /// P(length vertical)'s departure.
    pub length: Departure,
    /// The data's binomial error on P(breadth vertical) for this block (its most precise row).
    pub data_err: f64,
    /// |departure| + 2σ within the data's error, for both probabilities.
    pub within: bool,
}

/// The method check.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct MethodCheck {
    /// The fit's time step, s.
    pub dt: f64,
    /// The reference's.
    pub reference_dt: f64,
    /// Each block.
    pub blocks: Vec<BlockCheck>,
}

/// What a block's check resolves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Verdict {
    /// |departure| + 2σ within the data's error for both probabilities.
    Within,
    /// |departure| − 2σ beyond the data's error for one of them.
    Outside,
    /// Neither: the check's own error is too wide. `Some(n)`: the rolls that would resolve it
    /// if the departures stayed where they are; `None` when a departure is already at the
    /// data's error (only more rolls showing it smaller would resolve it).
    Unresolved(Option<u64>),
}

impl BlockCheck {
    /// Within, outside, or not resolved by the rolls made.
    pub fn verdict(&self) -> Verdict {
        let ds = [self.breadth, self.length];
        if ds
            .iter()
            .all(|d| d.value.abs() + 2.0 * d.err <= self.data_err)
        {
            return Verdict::Within;
        }
        if ds
            .iter()
            .any(|d| d.value.abs() - 2.0 * d.err > self.data_err)
        {
            return Verdict::Outside;
        }
        // 2σ shrinks as 1/√n: n' = n (2σ / (err − |d|))².
        let need = ds.iter().try_fold(self.rolls, |m, d| {
            let room = self.data_err - d.value.abs();
            (room > 0.0).then(|| {
                let n = self.rolls as f64 * (2.0 * d.err / room).powi(2);
                m.max(n.ceil() as u64)
            })
        });
        Verdict::Unresolved(need)
    }
}

impl MethodCheck {
    /// Every block within its data's error.
    pub fn passes(&self) -> bool {
        self.blocks.iter().all(|b| b.within)
    }
}
