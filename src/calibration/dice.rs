//! Several dice in one fit (issue 71.1): a counts file's `die` column names each row's die, a
//! shape or a die file ([`crate::calibration::data`]); the fit keeps each die resolved once
//! ([`RowDie`], in `Method::dice`) and simulates a row as its own die (`Method::for_die`),
//! with the surface's and the thrower's parameters shared across dice as across blocks.

use crate::calibration::data::{self, DataRow};
use crate::error::{Error, Field, Result};
use crate::model::mass::Features;
use crate::model::shape::Shape;
use crate::run::request::DieRequest;
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// A row's own die: its name as the rows give it, its shape resting on the facets it rests on
/// at its own centre of mass, what departs from the uniform solid, and its density.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RowDie {
    /// The row's `die` cell (a die file's path joined to the counts file's folder).
    pub name: String,
    /// The die.
    pub shape: Arc<Shape>,
    /// Its centre of mass, pips, shell… as its file gives them.
    #[serde(default, skip_serializing_if = "Features::is_default")]
    pub die: Features,
    /// kg/m³, where its file gives one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density: Option<f64>,
}

impl RowDie {
    /// The die a `die` cell names: a die file (by its extension, [`data::is_die_file`]) or a
    /// shape name, as `--die` and `--shape` take them.
    pub fn resolve(name: &str) -> Result<RowDie> {
        let req = if data::is_die_file(name) {
            DieRequest {
                file: Some(name.into()),
                ..DieRequest::default()
            }
        } else {
            DieRequest {
                shape: Some(name.into()),
                ..DieRequest::default()
            }
        };
        let got = req.resolve_resting()?;
        let Some(shape) = got.shape else {
            return Err(Error::Invalid(
                "describes no shape or mesh (a cuboid's rows count its sides, in a file of \
                 blocks)"
                    .into(),
            ));
        };
        Ok(RowDie {
            name: name.into(),
            shape: Arc::new(shape),
            die: got.features,
            density: got.density,
        })
    }
}

/// Every die `rows` name, each resolved once, in first-seen order; a die that cannot be had is
/// refused in one line naming the row and the die.
pub fn resolve_rows(rows: &[DataRow]) -> Result<Vec<RowDie>> {
    let mut out: Vec<RowDie> = Vec::new();
    for r in rows {
        let Some(name) = &r.die else { continue };
        if out.iter().any(|d| &d.name == name) {
            continue;
        }
        let d = RowDie::resolve(name).map_err(|e| {
            let why = match &e {
                Error::Field { why, .. } => why.to_string(),
                e => e.to_string(),
            };
            Error::field(
                Field::Data,
                "",
                format!(
                    "row '{}': its die '{}': {why}",
                    data::shown(&r.label),
                    // Whole (a path is long), its control characters escaped.
                    name.chars()
                        .flat_map(|c| match c.is_control() {
                            true => c.escape_default().collect::<Vec<_>>(),
                            false => vec![c],
                        })
                        .collect::<String>()
                ),
            )
        })?;
        out.push(d);
    }
    Ok(out)
}

/// The names of the dice `rows` name, in first-seen order.
pub fn names(rows: &[DataRow]) -> Vec<&str> {
    let mut out: Vec<&str> = Vec::new();
    for r in rows {
        if let Some(d) = r.die.as_deref() {
            if !out.contains(&d) {
                out.push(d);
            }
        }
    }
    out
}
