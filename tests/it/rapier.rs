//! Rapier behind the engine interface: real Rapier, no mocks. A die laid on each face stays on
//! it, a reused world forgets its last throw, a batch is the same for any thread count.

use dicephys::engine::rapier2d::Rapier2d;
use dicephys::engine::rapier3d::Rapier3d;
use dicephys::engine::{new_engine, Engine, EngineKind};
use dicephys::model::block::{Block, Side};
use dicephys::model::scene::{Mode, Scene};
use dicephys::model::state::BodyState;
use dicephys::model::throws::{ThrowKind, ThrowRanges, Throws};
use dicephys::run::batch;
use dicephys::sim::roll::{roll, roll_observed, RollConfig, RollRecord};
use nalgebra::{UnitQuaternion, Vector3};
use std::f64::consts::FRAC_PI_2;

fn scene(mode: Mode) -> Scene {
    Scene::paper("140x24x20".parse::<Block>().unwrap(), mode)
}

fn throws() -> Throws {
    Throws::new(ThrowKind::Keyed, 1, ThrowRanges::default(), 0)
}

/// Enough for any roll here to settle; bounds a test's time if one does not.
const CAP: RollConfig = RollConfig {
    max_steps: 20_000,
    rule: dicephys::sim::roll::Rule::Dicephys,
    margin: dicephys::sim::roll::DEFAULT_MARGIN,
    audit: false,
    fast_flight: false,
};

/// An engine whose every throw starts from one given state instead of the throw's: so that
/// `roll::roll` itself (rest rule, failure checks, outcome) runs a die laid on a face.
struct StartAt {
    inner: Box<dyn Engine>,
    start: BodyState,
}

impl Engine for StartAt {
    fn reset(&mut self, _: &BodyState) -> dicephys::Result<()> {
        self.inner.reset(&self.start)
    }
    fn set_state(&mut self, now: &BodyState) -> dicephys::Result<()> {
        self.inner.set_state(now)
    }
    fn ballistic_flight(&self) -> bool {
        self.inner.ballistic_flight()
    }
    fn step(&mut self) -> dicephys::Result<()> {
        self.inner.step()
    }
    fn state(&self) -> BodyState {
        self.inner.state()
    }
}

/// At rest, a hair (1 µm) above the floor, with `rotation` and the side `vertical` upright.
fn laid(rotation: UnitQuaternion<f64>, vertical: f64) -> BodyState {
    BodyState {
        position: Vector3::new(0.0, 0.5 * vertical + 1e-6, 0.0),
        rotation,
        linear_velocity: Vector3::zeros(),
        angular_velocity: Vector3::zeros(),
        sleeping: false,
    }
}

fn roll_from(kind: EngineKind, scene: &Scene, start: BodyState) -> RollRecord {
    let mut e = StartAt {
        inner: new_engine(kind, scene).unwrap(),
        start,
    };
    roll(&mut e, scene, &throws().get(0), &CAP)
}

fn assert_settles_on(kind: EngineKind, scene: &Scene, start: BodyState, want: Side) {
    let r = roll_from(kind, scene, start);
    assert_eq!(
        r.fate.settled_side(),
        Some(want),
        "{kind} {}: {want:?} vertical, after {} steps",
        scene.mode.name(),
        r.steps
    );
}

// Body x = breadth, y = width, z = length; world y is up.
fn breadth_up() -> UnitQuaternion<f64> {
    UnitQuaternion::from_axis_angle(&Vector3::z_axis(), FRAC_PI_2)
}
fn length_up() -> UnitQuaternion<f64> {
    UnitQuaternion::from_axis_angle(&Vector3::x_axis(), -FRAC_PI_2)
}

#[test]
fn a_3d_box_laid_on_each_face_rests_on_it() {
    let s = scene(Mode::ThreeD);
    let b = s.die.block();
    for kind in [EngineKind::Rapier, EngineKind::RapierLocked] {
        assert_settles_on(kind, &s, laid(breadth_up(), b.breadth), Side::Breadth);
        assert_settles_on(
            kind,
            &s,
            laid(UnitQuaternion::identity(), b.width),
            Side::Width,
        );
        assert_settles_on(kind, &s, laid(length_up(), b.length), Side::Length);
    }
}

#[test]
fn a_2d_box_laid_on_each_side_rests_on_it() {
    let s = scene(Mode::TwoD);
    let b = s.die.block();
    for kind in [EngineKind::Rapier, EngineKind::RapierLocked] {
        assert_settles_on(kind, &s, laid(breadth_up(), b.breadth), Side::Breadth);
        assert_settles_on(
            kind,
            &s,
            laid(UnitQuaternion::identity(), b.width),
            Side::Width,
        );
    }
}

#[test]
fn a_throw_that_starts_just_above_the_floor_rolls_to_width_vertical() {
    // Throw::start puts the centre at the longest side plus the drop height: a negative drop
    // height lays the (unrotated) block on its length x breadth face.
    for mode in [Mode::ThreeD, Mode::TwoD] {
        let s = scene(mode);
        let mut t = throws().get(0);
        t.drop_height = 0.5 * s.die.block().width + 1e-6 - s.drop_base();
        t.velocity = 0.0;
        t.spin = 0.0;
        for kind in [EngineKind::Rapier, EngineKind::RapierLocked] {
            let mut e = new_engine(kind, &s).unwrap();
            let r = roll(e.as_mut(), &s, &t, &CAP);
            assert_eq!(r.fate.settled_side(), Some(Side::Width), "{kind} {mode:?}");
        }
    }
}

#[test]
fn the_die_has_the_scenes_mass_and_inertia() {
    let rest = laid(UnitQuaternion::identity(), 0.02);
    for mode in [Mode::ThreeD, Mode::TwoD] {
        let s = scene(mode);
        let mut e = Rapier3d::new(&s).unwrap();
        e.reset(&rest).unwrap();
        let m = e.die_mass().unwrap();
        assert!(
            (m - s.mass()).abs() <= 1e-15 * s.mass(),
            "{m} vs {}",
            s.mass()
        );
    }
    let s = scene(Mode::TwoD);
    let mut e = Rapier2d::new(&s).unwrap();
    e.reset(&rest).unwrap();
    let (m, i) = e.die_mass_inertia().unwrap();
    let (b, w) = (s.die.block().breadth, s.die.block().width);
    let want_i = s.mass() / 12.0 * (b * b + w * w);
    assert!(
        (m - s.mass()).abs() <= 1e-15 * s.mass(),
        "{m} vs {}",
        s.mass()
    );
    assert!((i - want_i).abs() <= 1e-15 * want_i, "{i} vs {want_i}");
}

#[test]
fn rapier2d_refuses_a_3d_scene_and_a_start_off_the_plane() {
    assert!(Rapier2d::new(&scene(Mode::ThreeD)).is_err());
    let mut e = Rapier2d::new(&scene(Mode::TwoD)).unwrap();
    assert!(e.reset(&laid(length_up(), 0.14)).is_err());
    assert!(e.reset(&laid(breadth_up(), 0.024)).is_ok());
}

/// Every state of a roll, and its record.
fn trajectory(e: &mut dyn Engine, s: &Scene, index: u64) -> (RollRecord, Vec<BodyState>) {
    let mut states = Vec::new();
    let t = throws().get(index);
    let r = roll_observed(e, s, &t, &CAP, |_, st| states.push(*st));
    (r, states)
}

#[test]
fn a_reused_world_forgets_the_last_throw() {
    for (kind, mode) in [
        (EngineKind::Rapier, Mode::ThreeD),
        (EngineKind::Rapier, Mode::TwoD),
        (EngineKind::RapierLocked, Mode::TwoD),
    ] {
        let s = scene(mode);
        let mut fresh = new_engine(kind, &s).unwrap();
        let alone = trajectory(fresh.as_mut(), &s, 3);

        let mut reused = new_engine(kind, &s).unwrap();
        for i in 0..3 {
            trajectory(reused.as_mut(), &s, i);
        }
        let after = trajectory(reused.as_mut(), &s, 3);
        assert_eq!(alone.0, after.0, "{kind} {mode:?}: records differ");
        assert!(
            alone.1 == after.1,
            "{kind} {mode:?}: the trajectories differ (bit for bit)"
        );
    }
}

#[test]
fn a_batch_is_the_same_on_one_thread_and_two() {
    for mode in [Mode::ThreeD, Mode::TwoD] {
        let s = scene(mode);
        let run = |threads| {
            batch::run(
                EngineKind::Rapier,
                &s,
                &throws(),
                &CAP,
                0..200,
                threads,
                &|_| {},
            )
            .unwrap()
        };
        let one = run(1);
        assert_eq!(one.len(), 200);
        assert_eq!(one, run(2), "{mode:?}");
    }
}

/// Lying on its length x breadth face, pushed along x at 0.5 m/s: with μ = 0.29 friction
/// stops it in 0.5 / (μ g) ≈ 0.18 s.
fn slides_to_a_stop(kind: EngineKind, mode: Mode) -> bool {
    let s = scene(mode);
    let mut start = laid(UnitQuaternion::identity(), s.die.block().width);
    start.linear_velocity.x = 0.5;
    let mut e = new_engine(kind, &s).unwrap();
    e.reset(&start).unwrap();
    for _ in 0..1000 {
        e.step().unwrap();
    }
    e.state().linear_velocity.x.abs() < 1e-3
}

#[test]
fn friction_stops_a_sliding_box() {
    for (kind, mode) in [
        (EngineKind::Bullet, Mode::ThreeD),
        (EngineKind::Bullet, Mode::TwoD),
        (EngineKind::Rapier, Mode::ThreeD),
        (EngineKind::Rapier, Mode::TwoD),
    ] {
        assert!(slides_to_a_stop(kind, mode), "{kind} {mode:?}");
    }
}

/// Rapier 0.36.1 solves a contact's two friction directions together, dividing by the
/// determinant of their 2x2 effective-mass matrix. On a body with a locked translation, one
/// tangent (z) has no effective mass, the determinant is 0, and Rapier's safe inverse makes
/// the whole friction impulse 0: a body with z translation locked slides without friction.
/// So `rapier-locked` locks only the rotations about x and y; this checks friction works.
#[test]
fn friction_stops_a_sliding_locked_3d_box() {
    assert!(slides_to_a_stop(EngineKind::RapierLocked, Mode::TwoD));
}

#[test]
fn a_flown_step_is_rapiers_own_step_bit_for_bit() {
    // Rapier's free flight flown in Rust (`Engine::own_flight`) against Rapier stepping: the
    // same states to the bit, step after step; then, handed back, the same landing and
    // bounce, step after step. The free 3D body, the locked 3D body in 2D, the true 2D body.
    for (kind, mode) in [
        (EngineKind::Rapier, Mode::ThreeD),
        (EngineKind::RapierLocked, Mode::TwoD),
        (EngineKind::Rapier, Mode::TwoD),
    ] {
        let scene = scene(mode);
        let planar = mode == Mode::TwoD;
        let start = BodyState {
            position: Vector3::new(0.0, 0.5, 0.0),
            rotation: if planar {
                UnitQuaternion::from_euler_angles(0.0, 0.0, 0.2)
            } else {
                UnitQuaternion::from_euler_angles(0.3, 0.1, 0.2)
            },
            linear_velocity: Vector3::new(0.1, 1.0, 0.0),
            angular_velocity: if planar {
                Vector3::new(0.0, 0.0, 120.0)
            } else {
                Vector3::new(5.0, -3.0, 120.0)
            },
            sleeping: false,
        };
        let mut stepped = new_engine(kind, &scene).unwrap();
        let mut flown = new_engine(kind, &scene).unwrap();
        for e in [&mut stepped, &mut flown] {
            e.reset(&start).unwrap();
            e.step().unwrap();
        }
        assert!(flown.own_flight(), "{kind:?} {mode:?}");
        let mut s = flown.state();
        assert!(flown.own_flight_start(&s), "{kind:?} {mode:?}");
        let mut n = 0;
        while let Some(next) = flown.own_flight_step(&s) {
            stepped.step().unwrap();
            assert_eq!(stepped.state(), next, "{kind:?} {mode:?}: flown step {n}");
            s = next;
            n += 1;
        }
        // Up 5 cm and down to a few cm over the floor.
        assert!(n > 300, "{kind:?} {mode:?}: {n} steps flown");
        flown.set_state(&s).unwrap();
        let mut bounced = false;
        for k in 0..400 {
            stepped.step().unwrap();
            flown.step().unwrap();
            let (a, b) = (stepped.state(), flown.state());
            assert_eq!(a, b, "{kind:?} {mode:?}: step {k} after the flight");
            bounced |= k > 0 && a.linear_velocity.y > 0.0;
        }
        assert!(bounced, "{kind:?} {mode:?}: no bounce in the window");
    }
}

#[test]
fn a_flight_handed_back_leaves_rapiers_world_as_its_steps_would() {
    // Beyond the die's state: the contact pairs Rapier's broad phase makes (their timing
    // follows its tree leaf, which the flight mirrors and hands back), the sleep timer and
    // the sleeping flag, step after step through a flight, the landing and the bounces.
    let starts = |planar: bool| BodyState {
        position: Vector3::new(0.0, 0.4, 0.0),
        rotation: if planar {
            UnitQuaternion::from_euler_angles(0.0, 0.0, 0.7)
        } else {
            UnitQuaternion::from_euler_angles(0.3, 0.9, 0.2)
        },
        linear_velocity: Vector3::new(0.3, 0.5, 0.0),
        angular_velocity: if planar {
            Vector3::new(0.0, 0.0, 30.0)
        } else {
            Vector3::new(5.0, -3.0, 30.0)
        },
        sleeping: false,
    };
    // Walks `e` with its own flight where it may, `reference` stepping; compares each step.
    fn compare<E: Engine>(
        what: &str,
        mut e: E,
        mut reference: E,
        start: &BodyState,
        view: impl Fn(&E) -> (usize, f64, bool),
    ) {
        e.reset(start).unwrap();
        reference.reset(start).unwrap();
        let (mut flown, mut flying, mut behind) = (0, false, false);
        let mut s = e.state();
        for k in 0..3000 {
            if !flying {
                flying = e.own_flight_start(&s);
            }
            let mut next = None;
            if flying {
                next = e.own_flight_step(&s);
                if next.is_none() {
                    flying = false;
                    if behind {
                        e.set_state(&s).unwrap();
                    }
                }
            }
            behind = next.is_some();
            s = match next {
                Some(n) => {
                    flown += 1;
                    n
                }
                None => {
                    e.step().unwrap();
                    e.state()
                }
            };
            reference.step().unwrap();
            assert_eq!(s, reference.state(), "{what}: step {k}");
            if !behind {
                assert_eq!(view(&e), view(&reference), "{what}: step {k}");
            }
        }
        assert!(flown > 150, "{what}: {flown} flown");
    }
    for mode in [Mode::ThreeD, Mode::TwoD] {
        let scene = scene(mode);
        let start = starts(mode == Mode::TwoD);
        compare(
            &format!("rapier3d {mode:?}"),
            Rapier3d::new(&scene).unwrap(),
            Rapier3d::new(&scene).unwrap(),
            &start,
            |e| e.die_world().unwrap(),
        );
    }
    let scene = scene(Mode::TwoD);
    compare(
        "rapier2d",
        Rapier2d::new(&scene).unwrap(),
        Rapier2d::new(&scene).unwrap(),
        &starts(true),
        |e| e.die_world().unwrap(),
    );
}

/// A made die's inertia, as Rapier's body holds it in world axes, is the one dicephys computed
/// (`MassProps`), turned by the die's orientation, to 1e-12: for dice whose principal moments
/// lie in any order along the body's axes (a thick coin's axis the smallest, a prism's, a cube
/// loaded along x, a block loaded along z) as for those in ascending order. Before the die's
/// collider carried its mass properties itself, Rapier's re-diagonalised sum turned the axes
/// of the first kind wrongly: 13 % off for the thick coin, 130 % for the prism, 8 % for the
/// cube loaded along x, 34 % for the loaded block; 3e-16 for the others.
#[test]
fn a_made_dies_inertia_in_rapier_is_the_one_computed() {
    use dicephys::model::mass::{Features, MassProps};
    let mut cases: Vec<(String, Scene)> = Vec::new();
    for (name, shape) in [
        (
            "coin:30,30",
            dicephys::model::shape::coin(30.0, 30.0).unwrap(),
        ),
        (
            "coin:24,2",
            dicephys::model::shape::coin(24.0, 2.0).unwrap(),
        ),
        (
            "prism:6,10,40",
            dicephys::model::shape::named("prism:6,10,40", None).unwrap(),
        ),
        ("d20", dicephys::model::shape::named("d20", None).unwrap()),
        ("d4", dicephys::model::shape::named("d4", None).unwrap()),
    ] {
        cases.push((name.into(), Scene::paper_shape(shape, Mode::ThreeD)));
    }
    for (block, com) in [
        ("16x16x16", [2e-3, 0.0, 0.0]),
        ("16x16x16", [0.0, 0.0, 2e-3]),
        ("16x16x16", [1e-3, 1e-3, 0.0]),
        ("20x16x12", [0.0, 0.0, 1e-3]),
    ] {
        let mut s = Scene::paper(block.parse().unwrap(), Mode::ThreeD);
        s.features = Features {
            com: Some(com),
            ..Default::default()
        };
        cases.push((format!("{block} loaded {com:?}"), s));
    }
    for (name, scene) in cases {
        let mp = MassProps::of(&scene).unwrap();
        let mut e = Rapier3d::new(&scene).unwrap();
        e.reset(&BodyState {
            position: Vector3::new(0.0, 1.0, 0.0),
            rotation: UnitQuaternion::from_euler_angles(0.3, -0.7, 1.1),
            linear_velocity: Vector3::zeros(),
            angular_velocity: Vector3::zeros(),
            sleeping: false,
        })
        .unwrap();
        e.step().unwrap();
        let got = e.world_inverse_inertia().unwrap();
        let r = e.state().rotation.to_rotation_matrix().into_inner()
            * mp.principal.to_rotation_matrix().into_inner();
        let want =
            r * nalgebra::Matrix3::from_diagonal(&mp.moments.map(|m| 1.0 / m)) * r.transpose();
        let err = (got - want).norm() / want.norm();
        assert!(err < 1e-12, "{name}: Rapier's inertia {err:.2e} off");
    }
}
