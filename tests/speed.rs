//! The speed levers change no outcome: checked on fixed throws against the faithful roll.

use dicephys::batch::{self, Tally};
use dicephys::engine::EngineKind;
use dicephys::roll::{Fate, Rule, Settle};
use dicephys::scene::{Mode, Scene};
use dicephys::throws::{ThrowKind, ThrowRanges, Throws};

fn rolls(kind: EngineKind, mode: Mode, settle: Settle, n: u64) -> Vec<dicephys::roll::RollRecord> {
    let scene = Scene::paper("140x24x20".parse().unwrap(), mode);
    let throws = Throws::new(ThrowKind::Keyed, 99, ThrowRanges::default(), 0);
    batch::run(kind, &scene, &throws, &settle, 0..n, 0, &|_| {}).unwrap()
}

#[test]
fn the_early_stop_names_the_outcome_of_the_full_settle() {
    for (kind, mode, n) in [
        (EngineKind::Bullet, Mode::ThreeD, 400),
        (EngineKind::Bullet, Mode::TwoD, 400),
        (EngineKind::Rapier, Mode::ThreeD, 150),
        (EngineKind::Rapier, Mode::TwoD, 150),
    ] {
        // Audit: settle fully, and record where the certificate would have stopped.
        let audit = rolls(
            kind,
            mode,
            Settle {
                audit: true,
                ..Settle::default()
            },
            n,
        );
        let t = Tally::of(&audit);
        assert_eq!(
            t.certified_wrong, 0,
            "{kind} {mode:?}: the certificate was wrong"
        );
        assert!(
            t.certified > n * 9 / 10,
            "{kind} {mode:?}: it fired on {} of {n}",
            t.certified
        );
        // And stopping there gives the same outcome, throw by throw, in fewer steps.
        let early = rolls(
            kind,
            mode,
            Settle {
                rule: Rule::Certificate,
                ..Settle::default()
            },
            n,
        );
        for (a, b) in audit.iter().zip(&early) {
            if let (Fate::Settled(x), Fate::Settled(y)) = (a.fate, b.fate) {
                assert_eq!(x, y, "{kind} {mode:?} throw {}", a.throw.index);
            }
            assert!(b.steps <= a.steps);
        }
    }
}

#[test]
fn fast_flight_keeps_the_outcomes_of_stepped_flight() {
    // Closed-form flight differs from stepped flight only by rounding; a chaotic roll may
    // still tip the other way, rarely. Tolerance: 99 % of throws identical.
    for mode in [Mode::ThreeD, Mode::TwoD] {
        let stepped = rolls(EngineKind::Bullet, mode, Settle::default(), 400);
        let fast = rolls(
            EngineKind::Bullet,
            mode,
            Settle {
                fast_flight: true,
                ..Settle::default()
            },
            400,
        );
        let same = stepped
            .iter()
            .zip(&fast)
            .filter(|(a, b)| a.fate == b.fate)
            .count();
        assert!(same >= 396, "{mode:?}: {same} of 400 identical");
        let engine_steps: u64 = fast.iter().map(|r| r.engine_steps).sum();
        let steps: u64 = stepped.iter().map(|r| r.engine_steps).sum();
        assert!(
            engine_steps * 2 < steps,
            "{mode:?}: fast flight saved under half the engine's steps"
        );
    }
}
