//! The null hypothesis a die's faces are judged against (`fair --null`): what a fair die of
//! its shape would show.

use serde::{Deserialize, Serialize};

/// What a fair die's faces would show.
#[derive(
    Clone,
    Copy,
    Debug,
    Default,
    PartialEq,
    Eq,
    Serialize,
    Deserialize,
    strum::Display,
    strum::EnumString,
    strum::VariantNames,
)]
#[serde(rename_all = "kebab-case")]
#[strum(serialize_all = "kebab-case")]
pub enum Null {
    /// Every face it can show equally often: 1/6 (in 2D, 1/4 for each side).
    #[default]
    Uniform,
    /// The quasi-static theory: what the die shows released at rest in a random orientation
    /// and rolling down without a bounce, the end of the gradient flow of its centre of mass's
    /// height. For a cuboid that is each face's solid angle from the centre of mass over 4π
    /// (Simpson's, eq. after (InElasK), for the paper's block; the inner box's for a made die;
    /// `theory::quasi_static`), hence its other name, `solid-angle`; for a die of any shape,
    /// the flow's exact basins (`theory::basins`). 3D only.
    #[serde(rename = "quasi-static", alias = "solid-angle")]
    #[strum(to_string = "quasi-static", serialize = "solid-angle")]
    QuasiStatic,
}
