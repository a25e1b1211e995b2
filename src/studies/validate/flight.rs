//! Free flight against the exact motion: a tumbling die falls for a long time, far from the
//! floor, and its energy and angular momentum are watched step by step.
//!
//! The exact motion keeps the translational energy ½m|v|² + mgy, the rotational energy
//! ½ω·Iω and the angular momentum L = Iω (world axes). Every engine here moves the centre by
//! symplectic Euler, v ← v − g·dt then y ← y + v·dt, which loses exactly ½mg²dt² a step
//! (ΔE = ½m(v'² − v²) + mg·v'·dt with v' = v − g·dt), so ½mg²dt·T over a flight of time T:
//! a known loss, linear in dt (`sim::roll::ENERGY_GAIN_TOLERANCE`'s comment). The rotation is
//! where they differ: without the gyroscopic term (Bullet as the paper ran it, and the fast
//! flight that copies it) ω stays constant in world axes, which is exact only for a spin about
//! a principal axis (the paper's throw); a tumbling die's L and ½ω·Iω then change at every dt.
//! Bullet's implicit gyroscopic term (its `bullet3` preset) and Rapier's explicit one turn ω as
//! L requires, with an error that falls with dt.

use crate::engine::{new_engine, EngineKind};
use crate::error::Result;
use crate::model::block::Block;
use crate::model::die::DieShape;
use crate::model::scene::{Mode, Preset, Scene};
use crate::model::state::BodyState;
use crate::model::throws::{haar_quaternion, unit_vector};
use crate::sim::flight::Flight;
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use serde::Serialize;

/// What integrates the flight.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Integrator {
    /// Bullet with the `dicephys281` preset: no gyroscopic term, as the paper ran it.
    Bullet,
    /// Bullet with the `bullet3` preset: its implicit gyroscopic term on.
    BulletGyroscopic,
    /// Rapier (rapier3d), which keeps the gyroscopic term (explicit).
    Rapier,
    /// dicephys's own closed-form flight (`sim::flight::Flight`), Bullet's without the term.
    FastFlight,
}

impl Integrator {
    /// The integrator's name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Integrator::Bullet => "bullet",
            Integrator::BulletGyroscopic => "bullet (bullet3 preset)",
            Integrator::Rapier => "rapier",
            Integrator::FastFlight => "fast flight",
        }
    }

    /// True if it keeps the gyroscopic term (so L should be conserved).
    pub fn gyroscopic(self) -> bool {
        matches!(self, Integrator::BulletGyroscopic | Integrator::Rapier)
    }

    /// The integrators that stand for the engines asked for: Bullet brings its two presets
    /// and the fast flight that copies it.
    pub fn for_engines(engines: &[EngineKind]) -> Vec<Integrator> {
        let mut v = Vec::new();
        if engines.contains(&EngineKind::Bullet) {
            v.extend([
                Integrator::Bullet,
                Integrator::FastFlight,
                Integrator::BulletGyroscopic,
            ]);
        }
        if engines
            .iter()
            .any(|e| matches!(e, EngineKind::Rapier | EngineKind::RapierLocked))
        {
            v.push(Integrator::Rapier);
        }
        v
    }
}

/// One flight: an integrator at one time step.
#[derive(Clone, Debug, Serialize)]
pub struct FlightRun {
    /// What integrated it.
    pub integrator: Integrator,
    /// The time step, s.
    pub dt: f64,
    /// Steps flown (the flight's time over dt, rounded).
    pub steps: u64,
    /// Symplectic Euler steps the integrator takes per step: Rapier's solver substeps (its
    /// `num_solver_iterations`, 4), else 1.
    pub substeps: u64,
    /// The translational energy lost over the flight, J.
    pub translational_loss_j: f64,
    /// Symplectic Euler's loss, ½mg²(dt/n)² a substep, n substeps a step, over the flight, J.
    pub symplectic_loss_j: f64,
    /// The largest |½ω·Iω/(its start) − 1| over the flight.
    pub rotational_energy_drift: f64,
    /// The largest |L − L₀|/|L₀| over the flight (world axes).
    pub angular_momentum_drift: f64,
}

impl FlightRun {
    /// Measured over predicted translational loss: 1 for symplectic Euler.
    pub fn loss_ratio(&self) -> f64 {
        self.translational_loss_j / self.symplectic_loss_j
    }
}

/// The die flown: the scene's block in 3D, 30 m up, a fixed generic tumble: orientation and
/// spin axis not along any body axis, so that the gyroscopic term matters.
pub fn start(spin: f64) -> BodyState {
    let [w, i, j, k] = haar_quaternion(0.3, 0.6, 0.9);
    let axis = Vector3::from(unit_vector(0.8, 0.15));
    BodyState {
        position: Vector3::new(0.0, 30.0, 0.0),
        rotation: UnitQuaternion::new_normalize(Quaternion::new(w, i, j, k)),
        linear_velocity: Vector3::new(0.3, 0.5, -0.2),
        angular_velocity: spin * axis,
        sleeping: false,
    }
}

/// The paper's scene for `block` in 3D at time step `dt`, with Bullet's `preset`.
fn scene(block: Block, dt: f64, preset: Preset) -> Scene {
    let mut s = Scene::paper(block, Mode::ThreeD);
    s.dt = dt;
    s.preset = preset;
    s
}

/// Flies `block` for `time` seconds at `dt` with `integrator`, spinning at `spin` rad/s.
pub fn fly(
    integrator: Integrator,
    block: Block,
    dt: f64,
    time: f64,
    spin: f64,
) -> Result<FlightRun> {
    let preset = match integrator {
        Integrator::BulletGyroscopic => Preset::Bullet3,
        _ => Preset::Dicephys281,
    };
    let scene = scene(block, dt, preset);
    let die = DieShape::of(&scene);
    let steps = (time / dt).round().max(1.0) as u64;
    let s0 = start(spin);
    let rot = |s: &BodyState| {
        die.kinetic(&BodyState {
            linear_velocity: Vector3::zeros(),
            ..*s
        })
    };
    let trans = |s: &BodyState| die.energy(s) - rot(s);
    let momentum = |s: &BodyState| {
        let wb = s.rotation.inverse_transform_vector(&s.angular_velocity);
        s.rotation * die.inertia.component_mul(&wb)
    };
    let (e0, r0, l0) = (trans(&s0), rot(&s0), momentum(&s0));
    let substeps = match integrator {
        Integrator::Rapier => crate::engine::rapier3d::substeps() as u64,
        _ => 1,
    };
    let h = dt / substeps as f64;
    let mut run = FlightRun {
        integrator,
        dt,
        steps,
        substeps,
        translational_loss_j: 0.0,
        symplectic_loss_j: (steps * substeps) as f64 * 0.5 * die.mass * die.gravity.powi(2) * h * h,
        rotational_energy_drift: 0.0,
        angular_momentum_drift: 0.0,
    };
    let mut watch = |s: &BodyState| {
        run.rotational_energy_drift = run.rotational_energy_drift.max((rot(s) / r0 - 1.0).abs());
        run.angular_momentum_drift = run
            .angular_momentum_drift
            .max((momentum(s) - l0).norm() / l0.norm());
    };
    let last = match integrator {
        Integrator::FastFlight => {
            let f = Flight::of(&scene);
            let dq = f.step_rotation(&s0.angular_velocity);
            let mut s = s0;
            for _ in 0..steps {
                s = f.step(&s, &dq);
                watch(&s);
            }
            s
        }
        _ => {
            let kind = match integrator {
                Integrator::Rapier => EngineKind::Rapier,
                _ => EngineKind::Bullet,
            };
            let mut e = new_engine(kind, &scene)?;
            e.reset(&s0)?;
            for _ in 0..steps {
                e.step()?;
                watch(&e.state());
            }
            e.state()
        }
    };
    run.translational_loss_j = e0 - trans(&last);
    Ok(run)
}
