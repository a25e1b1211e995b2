//! Several dice in one fit (issue 71.1): a counts file's `die` column names each row's die, a
//! shape or a die file ([`crate::calibration::data`]); the fit keeps each die resolved once
//! ([`RowDie`], in `Method::dice`) and simulates a row as its own die (`Method::for_die`),
//! with the surface's and the thrower's parameters shared across dice as across blocks.

use crate::calibration::data::{self, DataRow};
use crate::error::{Error, Field, Result};
use crate::model::die::Die;
use crate::run::request::DieRequest;
use serde::{Deserialize, Serialize};

/// A row's own die: its name as the rows give it, and the die, of a shape (never the cuboid,
/// whose rows count its sides in a file of blocks), resting on the facets it rests on at its
/// own centre of mass.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RowDie {
    /// The row's `die` cell (a die file's path joined to the counts file's folder).
    pub name: String,
    /// The die, written as its fields.
    #[serde(flatten)]
    pub die: Die,
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
        let die = req.resolve_resting()?;
        if die.shape.is_none() {
            return Err(Error::Invalid(
                "describes no shape or mesh (a cuboid's rows count its sides, in a file of \
                 blocks)"
                    .into(),
            ));
        }
        Ok(RowDie {
            name: name.into(),
            die,
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
