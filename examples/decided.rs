//! How late does the energy certificate decide a roll? For each throw, the engine steps the
//! fast roll takes (it ends when the certificate holds) beside the engine step of the roll's
//! last change of face region (after it the outcome never changes: what a perfect early stop
//! would need), and two looser stops that drop part of the translational energy from the
//! certificate's bound, with how often each would have named the wrong face.
//!
//!   cargo run --release --example decided -- [3d|2d] [ROLLS] [BLOCK]
//!
//! Bullet, the paper's throws (keyed, seed 2385), dt 1 ms, the fast defaults.

use dicephys::engine::{new_engine, Engine, EngineKind};
use dicephys::model::die::{up_in_body, DieBody};
use dicephys::model::scene::{Mode, Scene};
use dicephys::model::state::BodyState;
use dicephys::model::throws::{ThrowKind, ThrowRanges, Throws};
use dicephys::sim::roll::{roll, roll_observed, RollConfig, Rule, DEFAULT_MARGIN};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

/// An engine that counts its own steps, so that a watcher of the roll knows how many engine
/// steps (not flown ones) came before a state.
struct Counting(Box<dyn Engine>, Arc<AtomicU64>);

impl Engine for Counting {
    fn reset(&mut self, s: &BodyState) -> dicephys::Result<()> {
        self.1.store(0, Ordering::Relaxed);
        self.0.reset(s)
    }
    fn set_state(&mut self, s: &BodyState) -> dicephys::Result<()> {
        self.0.set_state(s)
    }
    fn ballistic_flight(&self) -> bool {
        self.0.ballistic_flight()
    }
    fn contact_free(&self) -> bool {
        self.0.contact_free()
    }
    fn step(&mut self) -> dicephys::Result<()> {
        self.1.fetch_add(1, Ordering::Relaxed);
        self.0.step()
    }
    fn state(&self) -> BodyState {
        self.0.state()
    }
}

/// A looser stop: the first engine step at which the certificate's test holds with `drop`
/// height (m) taken off the energy, and the face region it would have named.
#[derive(Default)]
struct Loose {
    at: Option<(u64, usize)>,
}

impl Loose {
    fn push(&mut self, k: u64, i: usize, excess: f64, drop: f64, allowed: f64) {
        if self.at.is_none() && excess - drop < allowed {
            self.at = Some((k, i));
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let mode = match args.get(1).map(String::as_str) {
        Some("2d") => Mode::TwoD,
        _ => Mode::ThreeD,
    };
    let n: u64 = args.get(2).map_or(2000, |s| s.parse().expect("ROLLS"));
    let block = args.get(3).map_or("140x24x20", String::as_str);
    let scene = Scene::paper(block.parse().expect("BLOCK"), mode);
    let die = DieBody::of(&scene);
    let counter = Arc::new(AtomicU64::new(0));
    let mut engine = Counting(
        new_engine(EngineKind::Bullet, &scene).expect("bullet"),
        counter.clone(),
    );
    let throws = Throws::new(ThrowKind::Keyed, 2385, ThrowRanges::default(), n);
    let settle_fully = RollConfig {
        rule: Rule::Dicephys,
        ..RollConfig::fast()
    };
    let (mut certificate, mut decided) = (0u64, 0u64);
    let (mut horizontal, mut translational) = ((0u64, 0u64), (0u64, 0u64));
    for index in 0..n {
        let throw = throws.get(index);
        certificate += roll(&mut engine, &scene, &throw, &RollConfig::fast()).engine_steps;
        // The same throw settled fully, watched: the region of every state, and where the
        // looser stops would have fired.
        let (mut region, mut last_change) = (usize::MAX, 0u64);
        let (mut h, mut t) = (Loose::default(), Loose::default());
        roll_observed(&mut engine, &scene, &throw, &settle_fully, |_, s| {
            let (i, side) = die.face_region(&up_in_body(&s.rotation));
            let k = counter.load(Ordering::Relaxed);
            if i != region {
                (region, last_change) = (i, k);
            }
            if s.position.y > 0.0 {
                let g = die.gravity;
                let rest = die.rest[i][side];
                let allowed = (1.0 - DEFAULT_MARGIN) * (die.barrier[i][side] - rest);
                let excess = die.energy(s) / (die.mass * g) - rest;
                let v = s.linear_velocity;
                let hor = 0.5 * (v.x * v.x + v.z * v.z) / g;
                h.push(k, i, excess, hor, allowed);
                t.push(k, i, excess, hor + 0.5 * v.y * v.y / g, allowed);
            }
        });
        decided += last_change;
        for (loose, sum) in [(&h, &mut horizontal), (&t, &mut translational)] {
            if let Some((k, i)) = loose.at {
                sum.0 += k;
                sum.1 += u64::from(i != region);
            }
        }
    }
    let mean = |x: u64| x as f64 / n as f64;
    println!("{block} {mode:?}, {n} rolls: engine steps per roll");
    println!(
        "  the certificate (the fast roll ends):   {:.1}",
        mean(certificate)
    );
    println!(
        "  the last change of face region:         {:.1}",
        mean(decided)
    );
    println!(
        "  without horizontal kinetic energy:      {:.1}, wrong face on {} rolls",
        mean(horizontal.0),
        horizontal.1
    );
    println!(
        "  without all translational energy:       {:.1}, wrong face on {} rolls",
        mean(translational.0),
        translational.1
    );
}
