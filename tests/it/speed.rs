//! The speed levers change no outcome: checked on fixed throws against the faithful roll.

use dicephys::engine::EngineKind;
use dicephys::model::scene::{Floor, Mode, Scene};
use dicephys::model::throws::{ThrowKind, ThrowRanges, Throws};
use dicephys::run::batch;
use dicephys::run::tally::Tally;
use dicephys::sim::roll::{Fate, RollConfig, RollRecord, Rule};

/// `n` fixed throws of 140x24x20 on DicePhys's box floor.
fn rolls(kind: EngineKind, mode: Mode, settle: RollConfig, n: u64) -> Vec<RollRecord> {
    rolls_on(Floor::Box, kind, mode, settle, n)
}

fn rolls_on(
    floor: Floor,
    kind: EngineKind,
    mode: Mode,
    settle: RollConfig,
    n: u64,
) -> Vec<RollRecord> {
    let mut scene = Scene::paper("140x24x20".parse().unwrap(), mode);
    scene.floor = floor;
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
            RollConfig {
                audit: true,
                ..RollConfig::default()
            },
            n,
        );
        let t = Tally::of(&audit, true).unwrap();
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
            RollConfig {
                rule: Rule::Certificate,
                ..RollConfig::default()
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
        let stepped = rolls(EngineKind::Bullet, mode, RollConfig::default(), 400);
        let fast = rolls(
            EngineKind::Bullet,
            mode,
            RollConfig {
                fast_flight: true,
                ..RollConfig::default()
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
    // Over the plane floor, where Bullet's contacts reach out before the die arrives.
    let run = |fast_flight| {
        let settle = RollConfig {
            fast_flight,
            ..RollConfig::default()
        };
        rolls_on(Floor::Plane, EngineKind::Bullet, Mode::TwoD, settle, 400)
    };
    let (stepped, fast) = (run(false), run(true));
    let same = stepped
        .iter()
        .zip(&fast)
        .filter(|(a, b)| a.fate == b.fate)
        .count();
    assert!(same >= 396, "plane floor: {same} of 400 identical");
}

#[test]
fn the_plane_floor_is_not_the_box_floor() {
    // The lever "a static plane instead of DicePhys's 10 km box" must leave the statistics
    // alone to be kept. It does not: Bullet's convex-plane contact adds one point per step
    // where the box-box test makes a whole face's, and the 2D ratio moves by many standard
    // errors (measured at 20,000 rolls: 0.479 ± 0.007 on the box, 0.747 ± 0.011 on the plane).
    // So the plane stays off by default and the benchmark marks it unproven. Fixed seed,
    // 1,500 throws: the two differ by more than 3 combined standard errors.
    let ratio = |floor| {
        let settle = RollConfig {
            rule: Rule::Certificate,
            fast_flight: true,
            ..RollConfig::default()
        };
        let recs = rolls_on(floor, EngineKind::Bullet, Mode::TwoD, settle, 1500);
        let c = Tally::of(&recs, true).unwrap().counts;
        dicephys::theory::stats::ratio(c.breadth, c.width)
    };
    let (b, p) = (ratio(Floor::Box), ratio(Floor::Plane));
    let z = dicephys::theory::stats::z_score(p.value, p.err, b.value, b.err);
    assert!(z > 3.0, "box {b:?}, plane {p:?}: z = {z:.1}");
}

#[test]
fn jumped_flight_rolls_every_throw_as_walked_flight() {
    // `roll` jumps the stretches of free flight where no check can fire; `roll_observed`
    // (which must show every state) walks them step by step, as the fast defaults did before
    // jumping. Every record must be the same bit for bit: outcome, steps, engine steps, the
    // certified step, the flags and the dips. 500 keyed throws of each MDF block, 3D and 2D,
    // under the fast defaults and under DicePhys's rule with fast flight (where the
    // certificate is not watched and the jumps run longer).
    use dicephys::engine::new_engine;
    use dicephys::sim::roll::{roll, roll_observed};
    let throws = Throws::new(ThrowKind::Keyed, 10, ThrowRanges::default(), 0);
    let flight_only = RollConfig {
        fast_flight: true,
        ..RollConfig::default()
    };
    for block in crate::helpers::MDF_BLOCKS {
        for mode in [Mode::ThreeD, Mode::TwoD] {
            let scene = Scene::paper(block.parse().unwrap(), mode);
            let mut e = new_engine(EngineKind::Bullet, &scene).unwrap();
            for (cfg, n) in [(RollConfig::fast(), 500), (flight_only, 50)] {
                for i in 0..n {
                    let t = throws.get(i);
                    let jumped = roll(e.as_mut(), &scene, &t, &cfg);
                    let walked = roll_observed(e.as_mut(), &scene, &t, &cfg, |_, _| {});
                    assert_eq!(
                        jumped, walked,
                        "{block} {mode:?} throw {i} ({:?})",
                        cfg.rule
                    );
                }
            }
        }
    }
}

#[test]
fn rapier_flight_rolls_every_throw_as_rapier_steps_it() {
    // Rapier flies its own free flight in Rust, operation for operation as its solver would
    // (`Engine::own_flight`), and hands the die back only where a step of its own would leave
    // the world the same. Every record must be bit for bit the one Rapier stepping every step
    // gives, but for the engine steps, which must be fewer: jumped (`roll`) and walked
    // (`roll_observed`), under the fast defaults and under DicePhys's rule (longer rolls: the
    // bounces and the sleep timer). Each engine: the free 3D body, the locked 3D body in 2D,
    // the true 2D body.
    use dicephys::engine::new_engine;
    use dicephys::sim::roll::{roll, roll_observed};
    let throws = Throws::new(ThrowKind::Keyed, 10, ThrowRanges::default(), 0);
    let flight_only = RollConfig {
        fast_flight: true,
        ..RollConfig::default()
    };
    for (kind, mode) in [
        (EngineKind::Rapier, Mode::ThreeD),
        (EngineKind::RapierLocked, Mode::TwoD),
        (EngineKind::Rapier, Mode::TwoD),
    ] {
        for block in ["140x24x20", "140x30x10"] {
            let scene = Scene::paper(block.parse().unwrap(), mode);
            let mut e = new_engine(kind, &scene).unwrap();
            for (cfg, n) in [(RollConfig::fast(), 150), (flight_only, 20)] {
                let stepped_cfg = RollConfig {
                    fast_flight: false,
                    ..cfg
                };
                let (mut flown_steps, mut engine_steps) = (0, 0);
                for i in 0..n {
                    let t = throws.get(i);
                    let stepped = roll(e.as_mut(), &scene, &t, &stepped_cfg);
                    let jumped = roll(e.as_mut(), &scene, &t, &cfg);
                    let walked = roll_observed(e.as_mut(), &scene, &t, &cfg, |_, _| {});
                    let what = format!("{kind:?} {block} {mode:?} throw {i} ({:?})", cfg.rule);
                    assert_eq!(jumped, walked, "{what}: jumped against walked");
                    assert_eq!(stepped.engine_steps, stepped.steps, "{what}");
                    assert_eq!(
                        RollRecord {
                            engine_steps: stepped.engine_steps,
                            ..jumped
                        },
                        stepped,
                        "{what}: flown against stepped"
                    );
                    flown_steps += jumped.steps - jumped.engine_steps;
                    engine_steps += jumped.engine_steps;
                }
                // Measured: about 40 % of the steps flown under the fast defaults, 18 %
                // under DicePhys's rule (which runs on through the die's rocking at rest).
                assert!(
                    flown_steps > engine_steps / 10,
                    "{kind:?} {block} {mode:?} ({:?}): {flown_steps} flown, {engine_steps} by Rapier",
                    cfg.rule
                );
            }
        }
    }
}
