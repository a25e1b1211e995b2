//! `trace --html`: one self-contained page that plays throws in 3D (three.js, vendored in
//! vendor/three and inlined, so the page opens with no network) from the trace's own
//! positions and quaternions, thinned to what the eye needs, beside their heights and
//! energies, the early stop and the outcome.

pub mod die;

use crate::model::die::DieBody;
use crate::model::faces::Outcome;
use crate::model::state::BodyState;
use crate::sim::roll::{Fate, RollRecord};
use serde::Serialize;

pub use die::DieView;

/// three.js, its minified module build (vendor/three/README.md).
const THREE: &str = include_str!("../../../vendor/three/three.module.min.js");
/// The page: its markup and style, with `{{TITLE}}`, `{{DATA}}`, `{{THREE}}` and `{{VIEWER}}`.
const PAGE: &str = include_str!("page.html");
/// The viewer: reads the data, draws with three.js (WebGL) or, where WebGL is not to be had,
/// a 2D canvas.
const VIEWER: &str = include_str!("viewer.js");

/// Frames kept a second of simulated time: a quarter of real speed still shows 60 a second,
/// and the page interpolates between them.
pub const FRAMES_PER_SECOND: f64 = 240.0;
/// The most frames a throw keeps: past this the rate is halved (a coin rolling 200 s).
pub const MAX_FRAMES: usize = 12_000;

/// One throw's frames, as columns: time (s), centre of mass (m, xyz), orientation (wxyz),
/// kinetic and potential energy (J).
#[derive(Debug, Default, Serialize)]
pub struct Frames {
    /// s.
    pub t: Vec<f64>,
    /// x, y, z of each frame in turn, m.
    pub p: Vec<f64>,
    /// w, x, y, z of each frame in turn.
    pub q: Vec<f64>,
    /// Kinetic energy, J.
    pub k: Vec<f64>,
    /// Potential energy, J.
    pub u: Vec<f64>,
}

/// Rounds `x` to `digits` significant digits (the page's numbers: short, and plenty for the
/// eye).
fn sig(x: f64, digits: i32) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return if x.is_finite() { 0.0 } else { f64::NAN };
    }
    let scale = 10f64.powi(digits - 1 - x.abs().log10().floor() as i32);
    (x * scale).round() / scale
}

/// Fixed decimals: positions to 1 µm, a quaternion's parts to 1e-6.
fn fixed(x: f64, decimals: i32) -> f64 {
    let s = 10f64.powi(decimals);
    (x * s).round() / s
}

/// Keeps a throw's frames as it is rolled: the first, one each `1/FRAMES_PER_SECOND` s of
/// simulated time (halved when there are more than `MAX_FRAMES`), and the last.
#[derive(Debug)]
pub struct Recorder {
    dt: f64,
    every: u64,
    frames: Frames,
    last: Option<(u64, BodyState)>,
    last_kept: Option<u64>,
}

impl Recorder {
    /// A recorder for steps of `dt` s.
    pub fn new(dt: f64) -> Recorder {
        Recorder {
            dt,
            every: ((1.0 / FRAMES_PER_SECOND / dt).floor() as u64).max(1),
            frames: Frames::default(),
            last: None,
            last_kept: None,
        }
    }

    /// The state after `step` steps.
    pub fn push(&mut self, die: &DieBody, step: u64, s: &BodyState) {
        if step.is_multiple_of(self.every) {
            self.keep(die, step, s);
            if self.frames.t.len() > MAX_FRAMES {
                self.halve();
            }
        } else {
            self.last = Some((step, *s));
        }
    }

    fn keep(&mut self, die: &DieBody, step: u64, s: &BodyState) {
        let f = &mut self.frames;
        let q = s.rotation.quaternion();
        f.t.push(fixed(step as f64 * self.dt, 7));
        f.p.extend(s.position.iter().map(|x| fixed(*x, 6)));
        f.q.extend([q.w, q.i, q.j, q.k].map(|x| fixed(x, 6)));
        f.k.push(sig(die.kinetic(s), 4));
        f.u.push(sig(die.potential(s), 6));
        self.last = None;
        self.last_kept = Some(step);
    }

    /// Every other frame (the first kept), at half the rate from here on.
    fn halve(&mut self) {
        let f = &mut self.frames;
        let keep = |v: &mut Vec<f64>, width: usize| {
            *v = v
                .chunks(width)
                .step_by(2)
                .flatten()
                .copied()
                .collect::<Vec<f64>>();
        };
        keep(&mut f.t, 1);
        keep(&mut f.p, 3);
        keep(&mut f.q, 4);
        keep(&mut f.k, 1);
        keep(&mut f.u, 1);
        self.every *= 2;
    }

    /// The frames, the last state among them.
    pub fn finish(mut self, die: &DieBody) -> Frames {
        if let Some((step, s)) = self.last.take() {
            self.keep(die, step, &s);
        }
        self.frames
    }
}

/// One throw on the page.
#[derive(Debug, Serialize)]
pub struct ThrowView {
    /// Its index in the seed's sequence.
    pub index: u64,
    /// How it ended, `trace`'s own line (`report::trace::ending`).
    pub ending: String,
    /// The outcome it ended on, as the die's outcomes name it (a label, or "breadth
    /// vertical"); `None` if it failed.
    pub outcome: Option<String>,
    /// The early stop: when it would have ended the roll (s) and the outcome it named.
    pub early_stop: Option<(f64, String)>,
    /// Its frames.
    pub frames: Frames,
}

impl ThrowView {
    /// Throw `index`, ended by `record` (`report::trace::roll`'s) as `ending` says, rolled
    /// at `dt`, a die of any shape's outcomes named by `labels`.
    pub fn of(
        index: u64,
        ending: String,
        record: &RollRecord,
        dt: f64,
        labels: &[String],
        frames: Frames,
    ) -> ThrowView {
        let outcome = match record.fate {
            Fate::Settled(o) | Fate::Unconverged(o) => named(o, labels),
            Fate::Failed(_) => None,
        };
        let early_stop = record
            .certified
            .and_then(|(step, o)| Some((step as f64 * dt, named(o, labels)?)));
        ThrowView {
            index,
            ending,
            outcome,
            early_stop,
            frames,
        }
    }
}

/// The outcome `o` as the page's die names its outcomes: a die of any shape's face by its
/// label (`labels`), a cuboid's (no labels) as "breadth vertical".
fn named(o: Outcome, labels: &[String]) -> Option<String> {
    match (o, labels.is_empty()) {
        (Outcome::Unknown, _) => None,
        (Outcome::Face(k), false) => labels.get(usize::from(k)).cloned(),
        (Outcome::Face(_), true) => Some(format!("{} vertical", o.side().name())),
    }
}

/// The page's data.
#[derive(Debug, Serialize)]
struct Data<'a> {
    die: &'a DieView,
    /// The time step, s, and the engine's name, for the page's caption.
    dt: f64,
    engine: &'a str,
    throws: &'a [ThrowView],
}

/// The page for `throws` of `die`, rolled at `dt` by `engine`.
pub fn page(die: &DieView, dt: f64, engine: &str, throws: &[ThrowView]) -> String {
    let data = Data {
        die,
        dt,
        engine,
        throws,
    };
    // JSON inside a script element: no `</` may end it early.
    let json = serde_json::to_string(&data)
        .expect("the page's data serialise")
        .replace("</", "<\\/");
    let title = format!("{} ({engine}), throw {}", die.name, indices(throws));
    fill(
        PAGE,
        &[
            ("TITLE", &escape(&title)),
            ("DATA", &json),
            ("VIEWER", VIEWER),
            ("THREE", THREE),
        ],
    )
}

/// `template` with each `{{KEY}}` replaced by its value, in one pass (a value is never
/// searched for keys).
fn fill(template: &str, values: &[(&str, &str)]) -> String {
    let mut out =
        String::with_capacity(template.len() + values.iter().map(|v| v.1.len()).sum::<usize>());
    let mut rest = template;
    while let Some(at) = rest.find("{{") {
        out.push_str(&rest[..at]);
        let after = &rest[at + 2..];
        match values
            .iter()
            .find(|(k, _)| after.starts_with(&format!("{k}}}}}")))
        {
            Some((k, v)) => {
                out.push_str(v);
                rest = &after[k.len() + 2..];
            }
            None => {
                out.push_str("{{");
                rest = after;
            }
        }
    }
    out.push_str(rest);
    out
}

/// "3" or "0–9" or "0, 4".
fn indices(throws: &[ThrowView]) -> String {
    let ix: Vec<u64> = throws.iter().map(|t| t.index).collect();
    match ix[..] {
        [one] => one.to_string(),
        [first, .., last] if last - first + 1 == ix.len() as u64 => format!("{first}–{last}"),
        _ => ix.iter().map(u64::to_string).collect::<Vec<_>>().join(", "),
    }
}

/// Text for HTML.
pub fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rounds_to_significant_digits() {
        assert_eq!(sig(0.0123456, 3), 0.0123);
        assert_eq!(sig(-987.6, 2), -990.0);
        assert_eq!(sig(0.0, 3), 0.0);
    }

    #[test]
    fn the_page_holds_no_early_end_of_its_scripts() {
        let die = DieView {
            name: "x</script>".into(),
            polys: vec![],
            outcomes: vec![],
            reach: 0.01,
            pip_radius: 0.0,
        };
        let page = page(&die, 0.001, "bullet", &[]);
        assert_eq!(page.matches("</script>").count(), 4);
        for key in ["{{TITLE}}", "{{DATA}}", "{{VIEWER}}", "{{THREE}}"] {
            assert!(!page.contains(key), "{key} left in the page");
        }
    }
}
