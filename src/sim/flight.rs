//! Free flight in closed form. Between bounces the die only falls and turns; an engine spends
//! hundreds of steps per roll on that. Out of contact, Bullet (without the gyroscopic term)
//! advances a body by symplectic Euler under gravity alone: v ← v + g·dt, x ← x + v·dt, and
//! the orientation by the exponential map of the (constant) angular velocity,
//! q ← exp(½ω·dt)·q. That is cheap to do here, so the roll steps the die itself while it is
//! out of contact and hands the state back to the engine when it lands: the same trajectory
//! to rounding, far fewer engine steps.
//!
//! When is a Bullet step pure flight? Its collision pass runs on the state before the step.
//! On DicePhys's box floor, the box-box test (btBoxBoxDetector, a separating-axis test) makes
//! a contact point only where the boxes overlap, and the points Bullet keeps from earlier
//! steps are dropped once farther than the contact breaking threshold. So a step taken while
//! Bullet holds no contact point (`Engine::contact_free`) from a state clear of the floor
//! adds none: the flight may start there (`may_start`) and lasts for every step taken from a
//! state clear of the floor (`next`). The plane floor is different: Bullet's convex-plane
//! test reports points up to the breaking threshold (≤ 2 cm) away, and again for the die
//! turned by up to that much at its rim, so there "clear" means 5 cm up. Bullet's sleeping
//! timer is the one other thing such a step changes: it resets while the die moves faster
//! than the sleeping thresholds, so flight is only taken at such speeds and the engine's
//! `set_state` resets the timer, as those steps would have.
//!
//! Rapier's flight is not this one (substeps, the gyroscopic pass, a linearised rotation): it
//! is flown by the engine itself, in Rust, operation for operation as its solver would
//! (`Engine::own_flight`; `engine::rapier3d::Flight` says when a Rapier step is pure flight),
//! and the roll walks and jumps it as it does this one (`roll::jump_own`).

use crate::model::die::DieBody;
use crate::model::scene::{Floor, Scene};
use crate::model::state::BodyState;
use crate::sim::rest::{RestDetector, REST_WINDOW};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};

/// Bullet's clamp on the rotation per step (ANGULAR_MOTION_THRESHOLD = π/4).
const MAX_ANGLE_PER_STEP: f64 = 0.25 * std::f64::consts::PI;

/// On the box floor a state is clear of it when its lowest point is this far above it. The
/// box-box test needs only > 0; this allows for rounding in the 10 km floor box's coordinates.
pub const CLEAR: f64 = 1e-6;

/// On the plane floor: beyond the breaking threshold (0.02 m at most) and the convex-plane
/// test's perturbation (as much again), with room to spare.
pub const CLEAR_OF_PLANE: f64 = 0.05;

/// Bullet's default sleeping thresholds (btRigidBodyConstructionInfo): a step resets the
/// deactivation timer when |v| ≥ 0.8 m/s or |ω| ≥ 1 rad/s. Kept with 1 % to spare.
const LINEAR_SLEEPING_THRESHOLD: f64 = 0.8 * 1.01;
const ANGULAR_SLEEPING_THRESHOLD: f64 = 1.0 * 1.01;

/// Free flight as Bullet integrates it out of contact: what a flown step needs of the scene.
#[derive(Clone, Debug)]
pub struct Flight {
    /// The time step, s.
    pub dt: f64,
    /// Gravity's magnitude, m/s², along −y.
    pub gravity: f64,
    /// The die: its lowest point, reach, and how the engine's body is turned from its axes
    /// (`DieBody::turn`: the body state flown, `next` and `jump`, is the engine's,
    /// `Engine::body_state`, turned back into the die's by `to_die`).
    pub die: DieBody,
    /// How far above the floor the die's lowest point must be for a step to be pure flight
    /// (`CLEAR` or `CLEAR_OF_PLANE`).
    pub clear: f64,
}

impl Flight {
    /// The flight of a scene's die: its time step, gravity, half sides, and the clearance its
    /// floor needs.
    pub fn of(scene: &Scene) -> Flight {
        Flight::of_die(scene, DieBody::of(scene))
    }

    /// `of`, given the scene's die (`DieBody::of`) already made.
    pub fn of_die(scene: &Scene, die: DieBody) -> Flight {
        // A rounded die, or one of any shape, meets the floor through Bullet's convex test
        // (GJK), which, as the plane's, reports points up to the breaking threshold away.
        let clear = match scene.floor {
            Floor::Box if die.radius == 0.0 && die.convex.is_none() => CLEAR,
            _ => CLEAR_OF_PLANE,
        };
        Flight {
            dt: scene.dt,
            gravity: scene.gravity,
            die,
            clear,
        }
    }

    /// Height of the die's lowest point above the floor (`DieBody::lowest_point`: for the
    /// centred sharp block y − Σ hᵢ |(Rᵀ ŷ)ᵢ|).
    #[inline]
    pub fn lowest_point(&self, s: &BodyState) -> f64 {
        self.die.lowest_point(s)
    }

    /// The die's state from a flown body state (the engine's `state` from its `body_state`).
    #[inline]
    pub fn to_die(&self, body: &BodyState) -> BodyState {
        if !self.die.turn.turned() {
            return *body;
        }
        BodyState {
            rotation: self.die.turn.to_die(&body.rotation),
            ..*body
        }
    }

    /// The lowest point of a flown body state. Every flown step asks it: the body not turned
    /// (every die but a made one off its principal axes) takes it inline, straight from the
    /// body state, and only a turned body pays for the call that turns it first.
    #[inline(always)]
    fn body_lowest(&self, body: &BodyState) -> f64 {
        if self.die.turn.turned() {
            self.turned_lowest(body)
        } else {
            self.lowest_point(body)
        }
    }

    /// `body_lowest` of a turned body: its die's state first (`to_die`).
    #[inline(never)]
    fn turned_lowest(&self, body: &BodyState) -> f64 {
        self.lowest_point(&self.to_die(body))
    }

    /// True if a flight may start from `s`, the state after the engine's last step: the die
    /// is clear of the floor and the engine holds no contact point (`contact_free`, asked
    /// only when the first holds).
    pub fn may_start(&self, s: &BodyState, contact_free: impl FnOnce() -> bool) -> bool {
        self.lowest_point(s) > self.clear && contact_free()
    }

    /// The rotation one step applies, as Bullet's `integrateTransform` builds it.
    pub fn step_rotation(&self, w: &Vector3<f64>) -> UnitQuaternion<f64> {
        let dt = self.dt;
        let mut angle = w.norm();
        if angle * dt > MAX_ANGLE_PER_STEP {
            angle = MAX_ANGLE_PER_STEP / dt;
        }
        let axis = if angle < 0.001 {
            // Taylor expansion of sin(½θ dt)/θ, as Bullet.
            w * (0.5 * dt - dt * dt * dt * 0.020833333333 * angle * angle)
        } else {
            w * ((0.5 * angle * dt).sin() / angle)
        };
        UnitQuaternion::new_normalize(Quaternion::new(
            (0.5 * angle * dt).cos(),
            axis.x,
            axis.y,
            axis.z,
        ))
    }

    /// One engine step of free flight; `dq` is `step_rotation` of the angular velocity.
    pub fn step(&self, s: &BodyState, dq: &UnitQuaternion<f64>) -> BodyState {
        let mut v = s.linear_velocity;
        v.y -= self.gravity * self.dt;
        BodyState {
            position: s.position + v * self.dt,
            rotation: UnitQuaternion::new_normalize(dq.into_inner() * s.rotation.into_inner()),
            linear_velocity: v,
            angular_velocity: s.angular_velocity,
            sleeping: false,
        }
    }

    /// Free flight jumped: takes the steps `next` would take from `s`, at most `max`, while
    /// each one is pure flight and reaches a state clear of the floor; the rest rule's window
    /// (`rest`) is left as if each state had been pushed to it (the rule is not asked).
    /// Returns how many steps were taken and leaves `s` at the last state reached. The caller
    /// bounds `max` by what its checks allow (`roll::run`): here nothing is checked.
    ///
    /// Each step is `step` itself, so the states are bit for bit those of walking the flight
    /// with `next`: a closed form (x₀ + v₀t − ½gt², exp(½ωt)q₀) would differ from the
    /// stepped recurrence by rounding, and a die landing 1e-15 m elsewhere can tip the other
    /// way. What jumping saves is everything else a walked step costs (the rest rule's sums,
    /// the certificate, the dip and failure checks), and most of the lowest-point tests: a
    /// state whose centre is higher than the box's farthest reach above the clearance is
    /// clear whatever its orientation.
    pub fn jump(
        &self,
        s: &mut BodyState,
        dq: &UnitQuaternion<f64>,
        max: u64,
        rest: &mut RestDetector,
    ) -> u64 {
        if max == 0 || self.body_lowest(s) <= self.clear {
            return 0;
        }
        // ω is constant in flight, so whether it keeps the die awake is decided once (the
        // same norm of the same vector that `next` takes).
        let spinning = s.angular_velocity.norm() >= ANGULAR_SLEEPING_THRESHOLD;
        // How far below its centre the die can reach: |h| in any orientation; in 2D (turning
        // about z, which keeps the quaternion's i and j exactly 0) the cross-section's
        // half diagonal. With room for rounding.
        let (q, d) = (s.rotation.quaternion(), dq.quaternion());
        let planar = q.i == 0.0 && q.j == 0.0 && d.i == 0.0 && d.j == 0.0;
        let reach = self.die.reach(planar) * (1.0 + 1e-9);
        // Flight changes only the vertical velocity (x, z and ω are copied), so the last
        // states' velocities are kept as that one number.
        let mut vy = [0.0; REST_WINDOW];
        // The loop is made twice, its landing test inline for a body not turned (every die
        // but a made one off its principal axes: the plain roll's every jumped step is here).
        let leg = Leg {
            dq,
            max,
            spinning,
            reach,
        };
        let n = if self.die.turn.turned() {
            self.fly(s, &leg, &mut vy, |b| self.turned_lowest(b))
        } else {
            self.fly(s, &leg, &mut vy, |b| self.lowest_point(b))
        };
        // The window keeps the last ten: the earlier states only move its count on.
        let first = n.saturating_sub(REST_WINDOW as u64);
        rest.skip(first);
        let mut at = *s;
        for k in first..n {
            at.linear_velocity.y = vy[(k % REST_WINDOW as u64) as usize];
            rest.record(&at);
        }
        n
    }

    /// `jump`'s steps: from `s`, at most `leg.max`, while each is awake (`leg.spinning`, or
    /// fast enough) and its state clear of the floor (`lowest`, asked only where the centre is
    /// within `leg.reach` of it); each state's vertical velocity kept in `vy` by step number
    /// modulo `REST_WINDOW`. Leaves `s` at the last state reached; returns how many.
    ///
    /// The state stepped is a local, written back once at the end, and its slot in `vy`
    /// counts round by itself: every jumped step passes here, and so the loop keeps the
    /// state in registers.
    #[inline(always)]
    fn fly(
        &self,
        s: &mut BodyState,
        leg: &Leg,
        vy: &mut [f64; REST_WINDOW],
        lowest: impl Fn(&BodyState) -> f64,
    ) -> u64 {
        let Leg {
            dq,
            max,
            spinning,
            reach,
        } = *leg;
        let mut at = *s;
        let (mut n, mut slot) = (0u64, 0);
        while n < max {
            let next = self.step(&at, dq);
            if !(spinning || next.linear_velocity.norm() >= LINEAR_SLEEPING_THRESHOLD) {
                break;
            }
            // The step that lands is left to the walk, with every check a landing can fire.
            if next.position.y - reach <= self.clear && lowest(&next) <= self.clear {
                break;
            }
            at = next;
            vy[slot] = at.linear_velocity.y;
            slot = if slot + 1 == REST_WINDOW { 0 } else { slot + 1 };
            n += 1;
        }
        *s = at;
        n
    }

    /// The state one step after `s` if that step is pure flight (`s` clear of the floor, the
    /// die fast enough that the step resets the sleeping timer); `None` if the engine must
    /// take it.
    pub fn next(&self, s: &BodyState, dq: &UnitQuaternion<f64>) -> Option<BodyState> {
        if self.body_lowest(s) <= self.clear {
            return None;
        }
        let next = self.step(s, dq);
        let awake = next.linear_velocity.norm() >= LINEAR_SLEEPING_THRESHOLD
            || next.angular_velocity.norm() >= ANGULAR_SLEEPING_THRESHOLD;
        // A non-finite state ends the roll as a failure in the roll's own check.
        awake.then_some(next)
    }
}

/// What a jump's loop holds fixed over its steps (`Flight::jump`, `Flight::fly`): the step's
/// rotation, the most steps it may take, whether ω alone keeps the die awake, and how far
/// below its centre the die can reach.
#[derive(Clone, Copy)]
struct Leg<'a> {
    dq: &'a UnitQuaternion<f64>,
    max: u64,
    spinning: bool,
    reach: f64,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::{new_engine, EngineKind};
    use crate::model::scene::Mode;

    /// Free flight from `s` (which `may_start`) as the roll flies it, at most `max` steps;
    /// the state and the number of steps taken.
    fn coast(f: &Flight, s: &BodyState, max: u64) -> (BodyState, u64) {
        let dq = f.step_rotation(&s.angular_velocity);
        let mut now = *s;
        let mut n = 0;
        while n < max {
            match f.next(&now, &dq) {
                Some(next) => now = next,
                None => break,
            }
            n += 1;
        }
        (now, n)
    }

    #[test]
    fn coasting_matches_bullet_stepping() {
        for mode in [Mode::ThreeD, Mode::TwoD] {
            let scene = Scene::paper("140x24x20".parse().unwrap(), mode);
            let flight = Flight::of(&scene);
            let start = BodyState {
                position: Vector3::new(0.0, 0.5, 0.0),
                rotation: UnitQuaternion::from_euler_angles(0.3, 0.0, 0.2),
                linear_velocity: Vector3::new(0.1, 1.0, 0.0),
                angular_velocity: if mode == Mode::TwoD {
                    Vector3::new(0.0, 0.0, 120.0)
                } else {
                    Vector3::new(5.0, -3.0, 120.0)
                },
                sleeping: false,
            };
            let mut e = new_engine(EngineKind::Bullet, &scene).unwrap();
            e.reset(&start).unwrap();
            let (coasted, n) = coast(&flight, &start, 200);
            assert_eq!(n, 200);
            for _ in 0..n {
                e.step().unwrap();
            }
            let stepped = e.state();
            assert!(
                (coasted.position - stepped.position).norm() < 1e-9,
                "{mode:?} position"
            );
            assert!(
                (coasted.linear_velocity - stepped.linear_velocity).norm() < 1e-9,
                "{mode:?} velocity"
            );
            assert!(
                coasted.rotation.angle_to(&stepped.rotation) < 1e-9,
                "{mode:?} rotation"
            );
        }
    }

    #[test]
    fn a_flight_handed_back_at_the_floor_bounces_as_if_stepped() {
        // Coast a tumbling die down to the floor, hand the state to Bullet, and let it bounce:
        // the same to rounding as Bullet stepping all the way. This needs `set_state` to leave
        // the body as a step does (the world inertia tensor for the new orientation) and the
        // flight to end where Bullet's first contact forms.
        for mode in [Mode::ThreeD, Mode::TwoD] {
            let scene = Scene::paper("140x24x20".parse().unwrap(), mode);
            let flight = Flight::of(&scene);
            let start = BodyState {
                position: Vector3::new(0.0, 0.2, 0.0),
                // In 2D the 1 m deep box turns about z only.
                rotation: if mode == Mode::TwoD {
                    UnitQuaternion::from_euler_angles(0.0, 0.0, 0.2)
                } else {
                    UnitQuaternion::from_euler_angles(0.3, 0.0, 0.2)
                },
                linear_velocity: Vector3::new(0.1, 0.0, 0.0),
                angular_velocity: if mode == Mode::TwoD {
                    Vector3::new(0.0, 0.0, 40.0)
                } else {
                    Vector3::new(5.0, -3.0, 40.0)
                },
                sleeping: false,
            };
            let mut stepped = new_engine(EngineKind::Bullet, &scene).unwrap();
            stepped.reset(&start).unwrap();
            let mut flown = new_engine(EngineKind::Bullet, &scene).unwrap();
            flown.reset(&start).unwrap();
            assert!(flight.may_start(&start, || flown.contact_free()));
            let (landing, n) = coast(&flight, &start, 10_000);
            assert!(
                n > 100 && flight.lowest_point(&landing) <= CLEAR,
                "{mode:?}"
            );
            flown.set_state(&landing).unwrap();
            for _ in 0..n {
                stepped.step().unwrap();
            }
            let mut bounced = false;
            for _ in 0..60 {
                stepped.step().unwrap();
                flown.step().unwrap();
                let (a, b) = (stepped.state(), flown.state());
                bounced |= a.linear_velocity.y > 0.0;
                assert!(
                    (a.position - b.position).norm() < 1e-9
                        && (a.linear_velocity - b.linear_velocity).norm() < 1e-7
                        && (a.angular_velocity - b.angular_velocity).norm() < 1e-6
                        && a.rotation.angle_to(&b.rotation) < 1e-9,
                    "{mode:?}: {a:?} against {b:?}"
                );
            }
            assert!(bounced, "{mode:?}: no bounce in the window");
        }
    }

    /// A die drilled with pips has its body turned off its axes; the flight flies Bullet's own
    /// body state, so 100 flown steps are Bullet's 100 steps to rounding (as
    /// `coasting_matches_bullet_stepping` for the plain die: Bullet adds gravity as a force
    /// times the inverse mass), and the die's state turned back from it is the one Bullet
    /// reports for its own.
    #[test]
    fn a_turned_body_flies_as_bullet_steps_it() {
        let mut scene = Scene::paper("16x16x16".parse().unwrap(), Mode::ThreeD);
        scene.features.pips = Some(crate::model::mass::Pips {
            diameter: 0.003,
            depth: 0.001,
            shape: crate::model::mass::PipShape::Cap,
            fill_density: 0.0,
            spacing: 0.25,
        });
        let f = Flight::of(&scene);
        assert!(f.die.turn.turned());
        let start = BodyState {
            position: Vector3::new(0.0, 0.5, 0.0),
            rotation: UnitQuaternion::from_euler_angles(0.3, 0.1, 0.2),
            linear_velocity: Vector3::new(0.1, 0.5, 0.0),
            angular_velocity: Vector3::new(5.0, -3.0, 120.0),
            sleeping: false,
        };
        let mut engine = new_engine(EngineKind::Bullet, &scene).unwrap();
        engine.reset(&start).unwrap();
        let dq = f.step_rotation(&start.angular_velocity);
        let mut body = engine.body_state();
        for _ in 0..100 {
            body = f.next(&body, &dq).expect("in flight");
            engine.step().unwrap();
        }
        let close = |a: &BodyState, b: &BodyState| {
            (a.position - b.position).norm() < 1e-12
                && (a.linear_velocity - b.linear_velocity).norm() < 1e-12
                && a.angular_velocity == b.angular_velocity
                && a.rotation.angle_to(&b.rotation) < 1e-12
        };
        assert!(close(&engine.body_state(), &body), "{body:?}");
        let die = engine.state();
        assert!(close(&die, &f.to_die(&body)), "{die:?}");
        // The die's axes, not the body's: turned by the principal frame.
        assert!(die.rotation.angle_to(&body.rotation) > 1e-6);
        assert_eq!(
            die.rotation,
            f.die.turn.to_die(&engine.body_state().rotation)
        );
    }

    #[test]
    fn a_jump_reaches_the_states_of_the_walk_bit_for_bit() {
        for mode in [Mode::ThreeD, Mode::TwoD] {
            let scene = Scene::paper("140x24x20".parse().unwrap(), mode);
            let f = Flight::of(&scene);
            let start = BodyState {
                position: Vector3::new(0.0, 0.4, 0.0),
                rotation: if mode == Mode::TwoD {
                    UnitQuaternion::from_euler_angles(0.0, 0.0, 0.2)
                } else {
                    UnitQuaternion::from_euler_angles(0.3, 0.1, 0.2)
                },
                linear_velocity: Vector3::new(0.1, 0.5, 0.0),
                angular_velocity: if mode == Mode::TwoD {
                    Vector3::new(0.0, 0.0, 120.0)
                } else {
                    Vector3::new(5.0, -3.0, 120.0)
                },
                sleeping: false,
            };
            let dq = f.step_rotation(&start.angular_velocity);
            let (walked, n) = coast(&f, &start, 10_000);
            let mut jumped = start;
            let mut rest = RestDetector::default();
            let k = f.jump(&mut jumped, &dq, 10_000, &mut rest);
            // The jump stops one step short of the walk: the landing step is the walk's.
            assert_eq!(k, n - 1, "{mode:?}");
            assert_eq!(f.next(&jumped, &dq), Some(walked), "{mode:?}");
            // It leaves the rest rule's window as pushing every state would.
            let mut pushed = RestDetector::default();
            let mut t = start;
            for _ in 0..k {
                t = f.next(&t, &dq).unwrap();
                pushed.push(&t);
            }
            assert_eq!(format!("{rest:?}"), format!("{pushed:?}"), "{mode:?}");
            // A cap is a cap.
            let mut s = start;
            assert_eq!(f.jump(&mut s, &dq, 7, &mut RestDetector::default()), 7);
            assert_eq!(s, coast(&f, &start, 7).0);
        }
    }

    #[test]
    fn flight_starts_clear_of_the_floor_and_of_contacts() {
        let scene = Scene::paper("140x24x20".parse().unwrap(), Mode::ThreeD);
        let flight = Flight::of(&scene);
        // Flat on its 20 mm side: lowest point 10 mm below the centre.
        let at = |y: f64, vy: f64| BodyState {
            position: Vector3::new(0.0, y, 0.0),
            rotation: UnitQuaternion::identity(),
            linear_velocity: Vector3::new(0.0, vy, 0.0),
            angular_velocity: Vector3::zeros(),
            sleeping: false,
        };
        assert!(!flight.may_start(&at(0.0305, -1.0), || false));
        assert!(flight.may_start(&at(0.0105, -1.0), || true));
        assert!(!flight.may_start(&at(0.0099, -1.0), || true));
        // Falling at 1 m/s from 20.5 mm clear: the last step is taken from a clear state,
        // so the flight ends just inside the floor, where the engine's contact takes over.
        let (end, n) = coast(&flight, &at(0.0305, -1.0), 1000);
        assert!(n > 0 && flight.lowest_point(&end) <= CLEAR);
        assert!(
            flight.lowest_point(&end) > -0.002,
            "{}",
            flight.lowest_point(&end)
        );
        // Slower than the sleeping thresholds: the engine must step (its timer runs).
        assert_eq!(coast(&flight, &at(0.0305, 0.01), 1000).1, 0);
        // Over the plane floor, whose contacts reach up to it, the flight stays 5 cm clear.
        let mut plane = scene.clone();
        plane.floor = crate::model::scene::Floor::Plane;
        let flight = Flight::of(&plane);
        assert!(!flight.may_start(&at(0.0595, -1.0), || true));
        let (end, n) = coast(&flight, &at(0.2, -1.0), 1000);
        assert!(n > 0 && (-0.005..=0.0).contains(&(flight.lowest_point(&end) - CLEAR_OF_PLANE)));
    }
}
