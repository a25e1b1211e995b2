//! A design under a fit's calibration (`design --fit`, issue 73): the table's e, μ and rolling
//! resistance and the thrower's throw that a fit found, with the design's own die in place of
//! the fit's, as `predict --die` carries a calibration to a die it never saw
//! (`calibration::other_die`).
//!
//! A coin keeps its own rolling resistance (0.05 mm, where the engine has it) where the fit
//! measured none.
//!
//! The design takes the fit at its maximum (its best values), not at its posterior draws: the
//! design's interval is the simulation's error at those values, and the calibration's own
//! uncertainty is not carried into it (`predict` carries it, for one die).

use crate::calibration::other_die::{check, method, without_die_params};
use crate::calibration::params::Fixed;
use crate::calibration::predict::group;
use crate::calibration::FitResult;
use crate::error::Result;
use crate::model::die::Die;
use crate::run::spec::RunSpec;
use serde::Serialize;

/// Which calibration a design was made under.
#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct Calibration {
    /// The fit, as it was named (its fit.json's path).
    pub fit: String,
    /// The surface whose e and μ were taken ("all" where the fit shares them).
    pub surface: String,
    /// The thrower whose throw was taken ("all" where the fit shares it).
    pub thrower: String,
    /// The values taken: the fit's fixed values with its free ones at its maximum (a fitted
    /// die's own centre of mass or pips dropped: the design's die is its own).
    pub values: Fixed,
}

/// `spec`'s die (its shape, features and density; its seed and rolls) in the fit's calibrated
/// scene and throw, on the fit's engine, step and step cap: the run a design scans. `name` is
/// how the fit was given; `surface` and `thrower` pick the fit's values where it has several
/// (as `predict --surface`, `--thrower`). Refused, in one line, where the fit's throw cannot
/// throw the die (a fit of blocks spins a die about a long axis that a die of any shape has
/// not) or the surface or thrower is not the fit's.
pub fn calibrated(
    fit: &FitResult,
    name: &str,
    spec: &RunSpec,
    surface: &Option<String>,
    thrower: &Option<String>,
) -> Result<(RunSpec, Calibration)> {
    let surface = group(fit, true, surface, "surface")?;
    let thrower = group(fit, false, thrower, "thrower")?;
    let die = Die {
        shape: spec.scene.die.clone().into_shape(),
        features: spec.scene.features,
        density: Some(spec.scene.density),
    };
    check(&die, fit)?;
    // A new row's coordinates, as `predict` builds them: the fit's parameters of this surface
    // and thrower, at the fit's maximum.
    let row = FitResult::new_row(&surface, &thrower, spec.scene.die.block(), spec.scene.mode);
    let mut values = without_die_params(fit.values_at(&row, &fit.estimate.x));
    // A coin keeps its own rolling resistance where the fit measured none (not free, and 0:
    // its dice's default, not a finding): with none, a coin rolling on its rim never stops,
    // and every roll that ends there runs to the step cap.
    let coin_engine = fit.config.method.engine.resists_rolling(spec.scene.mode);
    if spec.scene.die.is_coin()
        && coin_engine
        && values.rolling == 0.0
        && !fit
            .config
            .model
            .is_free(crate::calibration::params::Kind::Rolling)
    {
        values.rolling = crate::model::scene::COIN_ROLLING_RESISTANCE * 1e3;
    }
    let method = method(&die, &fit.config.method);
    let out = method.spec(
        spec.scene.die.block(),
        spec.scene.mode,
        &values,
        spec.throws.seed,
        spec.rolls,
    );
    out.validate(false)?;
    Ok((
        out,
        Calibration {
            fit: name.to_string(),
            surface,
            thrower,
            values,
        },
    ))
}
