//! Integration tests against the real Bullet, through the real shim. Run optimised
//! (`cargo test --release`): each rolls thousands of real throws.

use dicephys::engine::{new_engine, EngineKind};
use dicephys::model::block::{Block, Side};
use dicephys::model::scene::{Mode, Scene};
use dicephys::model::state::BodyState;
use dicephys::model::throws::{ThrowKind, ThrowRanges, Throws};
use dicephys::run::batch;
use dicephys::run::tally::Tally;
use dicephys::sim::roll::{roll, run_from, Fate, RollConfig};
use nalgebra::{UnitQuaternion, Vector3};
use std::f64::consts::FRAC_PI_2;

fn block() -> Block {
    "140x24x20".parse().unwrap()
}

/// A die set down at rest, a hair above the floor, with `up` (a body axis) vertical.
fn at_rest(rotation: UnitQuaternion<f64>, half_height: f64) -> BodyState {
    BodyState {
        position: Vector3::new(0.0, half_height + 1e-4, 0.0),
        rotation,
        linear_velocity: Vector3::zeros(),
        angular_velocity: Vector3::zeros(),
        sleeping: false,
    }
}

fn settle_at_rest(
    engine: EngineKind,
    mode: Mode,
    rotation: UnitQuaternion<f64>,
    half: f64,
) -> Fate {
    let scene = Scene::paper(block(), mode);
    let mut e = new_engine(engine, &scene).unwrap();
    let end = run_from(
        e.as_mut(),
        &scene,
        &at_rest(rotation, half),
        &RollConfig {
            max_steps: 20_000,
            ..RollConfig::default()
        },
        |_, _| {},
    );
    end.fate
}

#[test]
fn a_box_at_rest_on_each_face_classifies_right() {
    let b = block();
    // Body x = breadth, y = width, z = length. Identity: width vertical.
    let cases_3d = [
        (UnitQuaternion::identity(), b.width / 2.0, Side::Width),
        (
            UnitQuaternion::from_axis_angle(&Vector3::z_axis(), FRAC_PI_2),
            b.breadth / 2.0,
            Side::Breadth,
        ),
        (
            UnitQuaternion::from_axis_angle(&Vector3::x_axis(), FRAC_PI_2),
            b.length / 2.0,
            Side::Length,
        ),
    ];
    for (rot, half, want) in cases_3d {
        assert_eq!(
            settle_at_rest(EngineKind::Bullet, Mode::ThreeD, rot, half).settled_side(),
            Some(want),
            "3D, {want:?} vertical"
        );
    }
    for (rot, half, want) in &cases_3d[..2] {
        assert_eq!(
            settle_at_rest(EngineKind::Bullet, Mode::TwoD, *rot, *half).settled_side(),
            Some(*want),
            "2D, {want:?} vertical"
        );
    }
}

#[test]
fn same_seed_same_counts_for_any_thread_count() {
    let scene = Scene::paper(block(), Mode::ThreeD);
    let throws = Throws::new(ThrowKind::Keyed, 11, ThrowRanges::default(), 0);
    let settle = RollConfig::default();
    let one = batch::run(
        EngineKind::Bullet,
        &scene,
        &throws,
        &settle,
        0..300,
        1,
        &|_| {},
    )
    .unwrap();
    let two = batch::run(
        EngineKind::Bullet,
        &scene,
        &throws,
        &settle,
        0..300,
        2,
        &|_| {},
    )
    .unwrap();
    assert_eq!(one, two, "records differ between 1 and 2 threads");
    assert_eq!(
        Tally::of(&one, true).unwrap(),
        Tally::of(&two, true).unwrap()
    );
}

#[test]
fn a_throw_rolls_the_same_alone_and_inside_a_batch() {
    let scene = Scene::paper(block(), Mode::ThreeD);
    let throws = Throws::new(ThrowKind::Keyed, 5, ThrowRanges::default(), 0);
    let settle = RollConfig::default();
    let batch = batch::run(
        EngineKind::Bullet,
        &scene,
        &throws,
        &settle,
        0..40,
        2,
        &|_| {},
    )
    .unwrap();
    for i in [0u64, 17, 39] {
        let mut fresh = new_engine(EngineKind::Bullet, &scene).unwrap();
        let alone = roll(fresh.as_mut(), &scene, &throws.get(i), &settle);
        assert_eq!(alone, batch[i as usize], "throw {i}");
    }
}

/// The reference: DicePhys 2.81's outcome for each of its first 2,000 throws.
fn reference(file: &str) -> Vec<String> {
    let path = format!("{}/tests/data/{file}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap();
    text.lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap().to_string())
        .collect()
}

fn match_dicephys(mode: Mode, block: &str, file: &str) -> f64 {
    let want = reference(file);
    let scene = Scene::paper(block.parse().unwrap(), mode);
    let n = want.len() as u64;
    let throws = Throws::new(ThrowKind::Dicephys, 2385, ThrowRanges::default(), n);
    let got = batch::run(
        EngineKind::Bullet,
        &scene,
        &throws,
        &RollConfig::default(),
        0..n,
        0,
        &|_| {},
    )
    .unwrap();
    let same = got
        .iter()
        .zip(&want)
        .filter(|(r, w)| matches!(r.fate, Fate::Settled(o) if o.side().name() == w.as_str()))
        .count();
    same as f64 / n as f64
}

#[test]
fn matches_dicephys_throw_for_throw_3d() {
    // DicePhys's own source rebuilt on Bullet 3.24 gets 99.95 %; the issue asks >= 99.5 %.
    let f = match_dicephys(
        Mode::ThreeD,
        "140x24x20",
        "dicephys-2.81-per-roll-3d-140x24x20.csv",
    );
    assert!(f >= 0.995, "3D: {:.2} % identical outcomes", 100.0 * f);
}

#[test]
fn matches_dicephys_throw_for_throw_2d() {
    let f = match_dicephys(
        Mode::TwoD,
        "140x22x13",
        "dicephys-2.81-per-roll-2d-140x22x13.csv",
    );
    assert!(f >= 0.995, "2D: {:.2} % identical outcomes", 100.0 * f);
}

#[test]
fn keyed_throws_agree_with_dicephys_ratio_within_3_sigma() {
    // Reference: DicePhys 2.81, 3D 140x24x20, 40,000 rolls: 14163 / 25837 = 0.5482 ± 0.0057.
    // Independent keyed throws, fixed seed; tolerance 3 combined standard errors.
    let scene = Scene::paper(block(), Mode::ThreeD);
    let throws = Throws::new(ThrowKind::Keyed, 20_141_407, ThrowRanges::default(), 0);
    let recs = batch::run(
        EngineKind::Bullet,
        &scene,
        &throws,
        &RollConfig::default(),
        0..3000,
        0,
        &|_| {},
    )
    .unwrap();
    let t = Tally::of(&recs, true).unwrap();
    let ours = dicephys::theory::stats::ratio(t.counts.breadth, t.counts.width);
    let theirs = dicephys::theory::stats::ratio(14163, 25837);
    let z = dicephys::theory::stats::z_score(ours.value, ours.err, theirs.value, theirs.err);
    assert!(
        z.abs() < 3.0,
        "ratio {:.4} ± {:.4} is {z:.2} σ from DicePhys's {:.4}",
        ours.value,
        ours.err,
        theirs.value
    );
    assert_eq!(t.failed_total() + t.unconverged, 0);
}

/// The shim's shortcuts on Bullet's step (`DiceWorld` in cpp/shim.cc: no swept bounding box,
/// no second prediction of the transform, no damping by pow(1, dt), the die's island found
/// directly; `DieSolver`: the contact solver without its pools and function pointers) change
/// nothing: every state of every roll is bit for bit that of Bullet's own world and solver,
/// awake or asleep, in 2D and 3D, on the box floor and the plane, at 1 ms and 1/60 s, with
/// Bullet 3's preset (its gyroscopic impulse) and with damping. A change of one unit in the
/// last place of a friction direction fails it (checked by sabotage).
#[test]
fn the_shims_shortcuts_leave_every_state_as_bullets_own_world_has_it() {
    use dicephys::engine::bullet::Bullet;
    use dicephys::engine::Engine;
    use dicephys::model::scene::{Floor, Preset};
    use dicephys::model::throws::ThrowStyle;
    let mut asleep = 0;
    let (d281, b3) = (Preset::Dicephys281, Preset::Bullet3);
    let (three, two, plane) = (Mode::ThreeD, Mode::TwoD, Floor::Plane);
    let (paper, rest, ms) = (ThrowStyle::Paper, ThrowStyle::Rest, 0.001);
    let box_ = Floor::Box;
    let coarse = 1.0 / 60.0;
    let cases = [
        (three, box_, ms, paper, d281, 0.0),
        (two, box_, ms, paper, d281, 0.0),
        (three, box_, ms, ThrowStyle::Tumble, d281, 0.0),
        (three, box_, ms, rest, d281, 0.0),
        (two, box_, ms, rest, d281, 0.0),
        (three, plane, ms, paper, d281, 0.0),
        (three, box_, coarse, paper, d281, 0.0),
        (two, box_, coarse, paper, d281, 0.0),
        (three, box_, ms, paper, b3, 0.0),
        (two, box_, ms, paper, b3, 0.0),
        (three, box_, ms, paper, d281, 2.0),
    ];
    for (mode, floor, dt, style, preset, damping) in cases {
        let mut scene = Scene::paper(block(), mode);
        (scene.floor, scene.dt, scene.preset) = (floor, dt, preset);
        (scene.linear_damping, scene.angular_damping) = (damping, damping);
        let throws = Throws::styled(
            ThrowKind::Keyed,
            style,
            None,
            11,
            ThrowRanges::default(),
            40,
        );
        let mut ours = Bullet::new(&scene).unwrap();
        let mut stock = Bullet::stock(&scene).unwrap();
        for index in 0..40 {
            let start = throws.get(index).start(&scene);
            let mut states = [Vec::new(), Vec::new()];
            let mut ends = Vec::new();
            for (k, engine) in [&mut ours as &mut dyn Engine, &mut stock]
                .into_iter()
                .enumerate()
            {
                let seen = &mut states[k];
                ends.push(run_from(
                    engine,
                    &scene,
                    &start,
                    &RollConfig::faithful(),
                    |_, s| seen.push(*s),
                ));
            }
            let case =
                format!("{mode:?} {floor:?} dt {dt} {style:?} {preset:?} {damping} throw {index}");
            assert_eq!(ends[0], ends[1], "{case}");
            assert_eq!(states[0], states[1], "{case}");
            asleep += states[0].iter().filter(|s| s.sleeping).count();
        }
    }
    // Dice released at rest fall asleep (Bullet's 2 s timer) before the rest rule fires on a
    // few throws: the sleeping island is exercised too.
    assert!(
        asleep > 0,
        "no die fell asleep: the sleeping island went untested"
    );
}

/// Rolling resistance's exact limit: a cylinder (30 mm across, 30 long) set rolling on its
/// side with `--rolling-resistance` δ. A torque δN against the roll (N = mg) and rolling
/// without slipping, (I + m r²) ω̇ = −δ m g with I = m r²/2, so it slows at a = 2δg/(3r).
/// Each engine's deceleration less its own without resistance is held to the law within 2 %,
/// and without resistance each rolls on.
/// - Bullet (its rolling friction), from 0.3 m/s over 0.2 s: 0.04376 m/s² against 0.04360 at
///   δ = 0.1 mm, 0.08737 against 0.08720 at 0.2 mm (0.4 %), 0.00014 without. Not slower or
///   longer: Bullet keeps a contact point while it drifts less than its breaking threshold,
///   and on a round die the kept point rides round with the roll, behind the true contact,
///   where the floor's push drives the roll on: from 0.15 m/s (10 rad/s) over 1 s this
///   cylinder gains 0.027 m/s without resistance (as if δ were −0.06 mm), and the law is met
///   to 16 % and 9 %. A known limit of Bullet's persistent manifold, not mended here.
/// - Rapier (its couple after each step, `Rapier3d::resist_rolling`), from 0.15 m/s over 1 s,
///   slower than 1° a step, where Rapier too carried its contact round with the die until
///   dicephys recomputed a round die's contacts every step (`RoundContacts`,
///   `engine/rapier3d.rs`): before, this cylinder sped up to 17.45 rad/s, 1° a step, with or
///   without δ = 0.1 mm; now 0.04370 and 0.08729, of which 0.00012 it loses without any:
///   the resistance's own 0.04359 and 0.08717 (0.04 %).
#[test]
fn a_cylinder_rolling_on_its_side_slows_as_rolling_resistance_says() {
    let shape = dicephys::model::shape::coin(30.0, 30.0).unwrap();
    let r = 0.015;
    for (engine, v0, secs) in [
        (EngineKind::Bullet, 0.3, 0.2),
        (EngineKind::Rapier, 0.15, 1.0),
    ] {
        let decel = |delta: f64| {
            let mut scene = Scene::paper_shape(shape.clone(), Mode::ThreeD);
            scene.rolling_resistance = delta;
            scene.sleeping = false;
            let mut e = new_engine(engine, &scene).unwrap();
            // Body z (the axis) along world x; rolling along world z about world x.
            let start = BodyState {
                position: Vector3::new(0.0, r, 0.0),
                rotation: UnitQuaternion::from_axis_angle(&Vector3::y_axis(), FRAC_PI_2),
                linear_velocity: Vector3::new(0.0, 0.0, v0),
                angular_velocity: Vector3::new(v0 / r, 0.0, 0.0),
                sleeping: false,
            };
            e.reset(&start).unwrap();
            // The speed after `secs` against the start: the mean deceleration.
            let steps = (secs / scene.dt) as usize;
            for _ in 0..steps {
                e.step().unwrap();
            }
            let s = e.state();
            assert!(
                s.rotation.transform_vector(&Vector3::z()).x.abs() > 0.99,
                "{engine:?}: still on its side"
            );
            (v0 - s.linear_velocity.z) / secs
        };
        let law = |delta: f64| 2.0 * delta * 9.81 / (3.0 * r);
        let (a1, a2) = (decel(1e-4), decel(2e-4));
        let none = decel(0.0);
        assert!(
            none.abs() < 0.05 * law(1e-4),
            "{engine:?}: without resistance it rolls on: {none}"
        );
        for (a, delta) in [(a1, 1e-4), (a2, 2e-4)] {
            let a = a - none;
            assert!(
                (a / law(delta) - 1.0).abs() < 0.02,
                "{engine:?} δ {delta}: {a} against {}",
                law(delta)
            );
        }
    }
}
