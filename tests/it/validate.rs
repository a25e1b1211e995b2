//! `validate`'s cases at small, fixed-seed sizes on the real engines, with tolerances in
//! standard errors; the throw styles and the damping they rest on; the command line, Ctrl-C in
//! its free-flight stage included.
//!
//! Tolerance: |z| ≤ 4 standard errors of the closed form's binomial error √(p(1−p)/n) (the
//! command's own verdict is 3; the seeds are fixed, so these are exact regressions, and 4
//! leaves room for an engine upgrade's rounding to move a few dice).

use super::helpers::{bin, dicephys, exit_within, json, scratch, Scratch};
use dicephys::engine::{new_engine, EngineKind};
use dicephys::model::block::{Block, Side};
use dicephys::model::scene::{Mode, Scene};
use dicephys::model::state::BodyState;
use dicephys::model::throws::ThrowStyle;
use dicephys::report::validate::{Config, Integrator, LimitCell};
use dicephys::run::runner::Runner;
use dicephys::run::spec::{RunSpec, ThrowSpec};
use dicephys::run::stop::Stop;
use dicephys::studies::validate::flight::fly;
use dicephys::studies::validate::limits::{limit_roll, limit_scene, measure_limit};
use dicephys::studies::validate::LIMIT_MAX_STEPS;
use dicephys::studies::Study;
use dicephys::theory;
use nalgebra::{UnitQuaternion, Vector3};

/// The tolerance, in standard errors.
const Z_MAX: f64 = 4.0;

fn block(s: &str) -> Block {
    s.parse().unwrap()
}

fn study() -> Study<'static> {
    Study {
        runner: Runner::new(2, Stop::new()),
        checkpoint: None,
    }
}

fn cell(engine: EngineKind, b: &str, mode: Mode, damped: bool, rolls: u64) -> LimitCell {
    let cfg = Config::default();
    let spec = RunSpec {
        engine,
        scene: limit_scene(&cfg, block(b), mode, damped),
        throws: ThrowSpec::keyed_style(17, ThrowStyle::Rest),
        roll: limit_roll(LIMIT_MAX_STEPS),
        rolls,
        shard: None,
    };
    measure_limit(&spec, &study()).unwrap()
}

/// z of k in n against the closed form p.
fn z(k: u64, n: u64, p: f64) -> f64 {
    (k as f64 / n as f64 - p) / (p * (1.0 - p) / n as f64).sqrt()
}

#[test]
fn released_at_rest_in_2d_a_die_lands_as_inelask_says() {
    for engine in [EngineKind::Bullet, EngineKind::Rapier] {
        for b in ["140x24x20", "140x30x10"] {
            let c = cell(engine, b, Mode::TwoD, true, 300);
            let f = c.faces();
            let p = theory::no_bounce_2d(block(b).r()).breadth_vertical;
            assert_eq!(f.total() + c.unknown + c.failed, 300, "{engine} {b}");
            assert_eq!(c.failed, 0, "{engine} {b}");
            let zb = z(f.breadth, f.total(), p);
            assert!(zb.abs() <= Z_MAX, "{engine} {b}: z {zb}");
            // Throw by throw: every die ends on the face whose angle it started over.
            assert!(
                c.ended_where_started as f64 >= 0.99 * c.ended_on_a_face as f64,
                "{engine} {b}: {} of {}",
                c.ended_where_started,
                c.ended_on_a_face
            );
        }
    }
}

#[test]
fn at_e_0_lifting_the_damping_changes_no_outcome_in_2d() {
    // A 2D die released at rest never holds more energy than its edge-balance height, and
    // each inelastic impact takes some: momentum alone cannot carry it over the next edge.
    for engine in [EngineKind::Bullet, EngineKind::Rapier] {
        let damped = cell(engine, "140x22x13", Mode::TwoD, true, 200);
        let free = cell(engine, "140x22x13", Mode::TwoD, false, 200);
        assert!(free.same_outcome(&damped) >= 0.99, "{engine}");
        let p = theory::no_bounce_2d(block("140x22x13").r()).breadth_vertical;
        let f = free.faces();
        assert!(z(f.breadth, f.total(), p).abs() <= Z_MAX, "{engine}");
    }
}

#[test]
fn released_at_rest_in_3d_a_die_lands_on_the_solid_angle_it_started_in() {
    for engine in [EngineKind::Bullet, EngineKind::Rapier] {
        for b in ["20x20x20", "30x20x10"] {
            let c = cell(engine, b, Mode::ThreeD, true, 200);
            let f = c.faces();
            let (p, _) = theory::simpson_3d(&block(b));
            for (o, want) in [
                (Side::Breadth, p.breadth_vertical),
                (Side::Width, p.width_vertical),
                (Side::Length, p.length_vertical),
            ] {
                let zz = z(f.of(o), f.total(), want);
                assert!(zz.abs() <= Z_MAX, "{engine} {b} {o:?}: z {zz}");
            }
            assert!(
                c.ended_where_started as f64 >= 0.97 * c.ended_on_a_face as f64,
                "{engine} {b}: {} of {}",
                c.ended_where_started,
                c.ended_on_a_face
            );
            if engine == EngineKind::Rapier {
                // Rapier brings every die to rest; Bullet lets some creep on their face for
                // ever with its sleeping off (counted on that face, and reported).
                assert_eq!(c.moving_at_cap.total(), 0, "{b}");
            }
        }
    }
}

#[test]
fn free_flight_loses_symplectic_eulers_energy_and_keeps_l_only_with_the_gyroscopic_term() {
    let b = block("140x24x20");
    for i in [
        Integrator::Bullet,
        Integrator::FastFlight,
        Integrator::BulletGyroscopic,
        Integrator::Rapier,
    ] {
        let coarse = fly(i, b, 1.0 / 250.0, 2.0, 40.0).unwrap();
        let fine = fly(i, b, 1.0 / 1000.0, 2.0, 40.0).unwrap();
        for r in [&coarse, &fine] {
            // ½mg²(dt/n)² a substep, to rounding.
            assert!(
                (r.loss_ratio() - 1.0).abs() < 1e-6,
                "{i:?}: {}",
                r.loss_ratio()
            );
        }
        if i.gyroscopic() {
            // L conserved up to an error that falls with dt.
            assert!(
                fine.angular_momentum_drift < 0.5 * coarse.angular_momentum_drift,
                "{i:?}"
            );
        } else {
            // ω held constant: the rotational energy exactly, L not at all, at any dt.
            assert!(fine.rotational_energy_drift < 1e-12, "{i:?}");
            assert!(fine.angular_momentum_drift > 0.1, "{i:?}");
            assert!(
                (fine.angular_momentum_drift / coarse.angular_momentum_drift - 1.0).abs() < 0.01
            );
        }
    }
    let rapier = fly(Integrator::Rapier, b, 1.0 / 1000.0, 2.0, 40.0).unwrap();
    assert_eq!(rapier.substeps, 4);
    assert!(rapier.angular_momentum_drift < 0.01);
}

#[test]
fn damping_slows_both_engines_by_the_same_rate_in_flight() {
    // A die far above the floor, spinning about a principal axis: its horizontal velocity and
    // its spin decay as e^(−λt) in both engines.
    for (engine, mode) in [
        (EngineKind::Bullet, Mode::ThreeD),
        (EngineKind::Rapier, Mode::ThreeD),
        (EngineKind::Bullet, Mode::TwoD),
        (EngineKind::Rapier, Mode::TwoD),
    ] {
        let mut scene = Scene::paper(block("140x24x20"), mode);
        scene.linear_damping = 5.0;
        scene.angular_damping = 20.0;
        let mut e = new_engine(engine, &scene).unwrap();
        e.reset(&BodyState {
            position: Vector3::new(0.0, 50.0, 0.0),
            rotation: UnitQuaternion::identity(),
            linear_velocity: Vector3::new(1.0, 0.0, 0.0),
            angular_velocity: Vector3::new(0.0, 0.0, 10.0),
            sleeping: false,
        })
        .unwrap();
        for _ in 0..500 {
            e.step().unwrap();
        }
        let s = e.state();
        let t = 500.0 * scene.dt;
        assert!(
            (s.linear_velocity.x / (-5.0 * t).exp() - 1.0).abs() < 1e-3,
            "{engine} {mode:?}: {}",
            s.linear_velocity.x
        );
        assert!(
            (s.angular_velocity.z / (10.0 * (-20.0 * t).exp()) - 1.0).abs() < 1e-3,
            "{engine} {mode:?}: {}",
            s.angular_velocity.z
        );
    }
}

fn out_dir(name: &str) -> Scratch {
    Scratch::absent(&format!("validate-{name}"))
}

#[test]
fn validate_at_tiny_size_writes_its_table_json_and_figures() {
    let dir = out_dir("tiny");
    let args = [
        "validate",
        "--rolls",
        "60",
        "--trend-rolls",
        "30",
        "--blocks-2d",
        "140x22x13",
        "--blocks-3d",
        "20x20x20",
        "--trend",
        "0:0.1,0.9:1.5",
        "--flight-dts",
        "1/250,1/1000",
        "--threads",
        "1",
        "--out",
        dir.to_str().unwrap(),
        "--json",
    ];
    let v = json(&dicephys(&args));
    for k in [
        "config", "rows", "cells", "flights", "trend", "passed", "failed", "findings", "wall_s",
    ] {
        assert!(v.get(k).is_some(), "missing {k}");
    }
    let rows = v["rows"].as_array().unwrap();
    let count = |case: &str| rows.iter().filter(|r| r["case"] == case).count();
    // 2 engines × 1 block; 3 outcomes × 2 engines; 3 quantities × 4 integrators; 2 × 2.
    assert_eq!(count("2d_no_bounce"), 2);
    assert_eq!(count("2d_momentum"), 2);
    assert_eq!(count("3d_quasi_static"), 6);
    assert_eq!(count("free_flight"), 12);
    assert_eq!(count("trend"), 4);
    for r in rows {
        for k in [
            "case",
            "engine",
            "subject",
            "quantity",
            "closed_form",
            "measured",
            "err",
            "n",
            "z",
            "verdict",
            "note",
        ] {
            assert!(r.get(k).is_some(), "row missing {k}: {r}");
        }
        if r["case"] != "trend" && r["case"] != "free_flight" {
            let z = r["z"].as_f64().unwrap();
            assert!(z.abs() <= Z_MAX, "{r}");
        }
    }
    for stem in [
        "validate_2d",
        "validate_3d",
        "validate_flight",
        "validate_trend",
    ] {
        assert!(dir.join(format!("{stem}.svg")).exists(), "{stem}.svg");
        assert!(dir.join(format!("{stem}.png")).exists(), "{stem}.png");
    }
    let md = std::fs::read_to_string(dir.join("report.md")).unwrap();
    assert!(md.contains("| case | engine |") && md.contains("## Findings"));
    // The cells are kept: the same command again rolls nothing and says the same.
    let again = json(&dicephys(&args));
    assert_eq!(again["rows"], v["rows"]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_input_gets_one_line_and_exit_code_2() {
    let dir = out_dir("bad");
    let out = dir.to_str().unwrap();
    let cases: &[&[&str]] = &[
        &["validate", "--rolls", "0", "--out", out],
        &["validate", "--trend-rolls", "0", "--out", out],
        &["validate", "--engines", "havok", "--out", out],
        &["validate", "--trend", "2:1", "--out", out],
        &["validate", "--trend", "x", "--out", out],
        &["validate", "--resolve", "0", "--out", out],
        &["validate", "--blocks-2d", "0x1x1", "--out", out],
        &["validate", "--flight-dts", "0", "--out", out],
        &["validate", "--engines", "", "--out", out],
        &["roll", "--block", "140x24x20", "--throw", "spin"],
        &[
            "roll",
            "--block",
            "140x24x20",
            "--throw",
            "tumble",
            "--throws",
            "dicephys",
        ],
        &["roll", "--block", "140x24x20", "--linear-damping", "31"],
        &["roll", "--block", "140x24x20", "--angular-damping", "-1"],
        &["roll", "--block", "140x24x20", "--linear-damping", "nan"],
    ];
    for args in cases {
        let o = dicephys(args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
        assert!(o.stdout.is_empty(), "{args:?} printed to stdout");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn tumble_and_rest_throws_roll_on_both_engines_the_same_on_any_thread_count() {
    for style in ["tumble", "rest"] {
        for (engine, mode) in [
            ("bullet", None),
            ("rapier", None),
            ("bullet", Some("--2d")),
            ("rapier", Some("--2d")),
        ] {
            let mut args = vec![
                "roll",
                "--block",
                "30x20x10",
                "--engine",
                engine,
                "--throw",
                style,
                "--rolls",
                "40",
                "--seed",
                "5",
                "--max-steps",
                "20000",
                "--json",
            ];
            args.extend(mode);
            let one = json(&dicephys(&[&args[..], &["--threads", "1"]].concat()));
            let two = json(&dicephys(&[&args[..], &["--threads", "2"]].concat()));
            assert_eq!(one["tally"], two["tally"], "{style} {engine} {mode:?}");
            assert_eq!(one["spec"]["throws"]["style"], style);
            assert_eq!(one["failed_total"], 0, "{style} {engine} {mode:?}");
            assert_eq!(one["outcomes"].is_object(), mode.is_none());
        }
    }
}

#[test]
fn a_default_run_specifies_itself_as_before() {
    // The new scene fields and the throw style are left out at their defaults, so that a
    // default run's specification (and the key its checkpoints carry) are unchanged.
    let v = json(&dicephys(&[
        "roll",
        "--block",
        "140x24x20",
        "--rolls",
        "5",
        "--json",
    ]));
    let spec = v["spec"].to_string();
    for k in ["style", "linear_damping", "angular_damping", "sleeping"] {
        assert!(!spec.contains(k), "{k} in {spec}");
    }
    let v = json(&dicephys(&[
        "roll",
        "--block",
        "140x24x20",
        "--rolls",
        "5",
        "--throw",
        "rest",
        "--linear-damping",
        "30",
        "--angular-damping",
        "30",
        "--no-sleep",
        "--restitution",
        "0",
        "--json",
    ]));
    assert_eq!(v["spec"]["scene"]["linear_damping"], 30.0);
    assert_eq!(v["spec"]["scene"]["sleeping"], false);
    assert_eq!(v["spec"]["throws"]["style"], "rest");
}

#[test]
fn a_tumble_run_resumes_from_its_checkpoint_bit_for_bit() {
    let dir = out_dir("resume");
    let ck = dir.join("ck");
    let base = [
        "roll",
        "--block",
        "30x20x10",
        "--throw",
        "tumble",
        "--rolls",
        "1500",
        "--seed",
        "3",
        "--threads",
        "2",
        "--json",
    ];
    let whole = json(&dicephys(&base));
    let first = json(&dicephys(
        &[&base[..], &["--checkpoint", ck.to_str().unwrap()]].concat(),
    ));
    assert_eq!(first["tally"], whole["tally"]);
    // Drop the second chunk and resume: the style comes back from the checkpoint.
    let second = std::fs::read_dir(&ck)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .find(|p| p.to_string_lossy().contains("chunk-000000001000"))
        .expect("the second chunk");
    std::fs::remove_file(second).unwrap();
    let resumed = json(&dicephys(&[
        "roll",
        "--resume",
        ck.to_str().unwrap(),
        "--json",
    ]));
    assert_eq!(resumed["tally"], whole["tally"]);
    assert_eq!(resumed["spec"]["throws"]["style"], "tumble");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn validate_stops_on_ctrl_c_in_its_free_flight_stage() {
    let d = scratch("validate-int");
    let out = d.join("out");
    let log = d.join("stderr.txt");
    let mut child = bin()
        .args([
            "validate",
            "--engines",
            "bullet",
            "--blocks-2d",
            "140x24x20",
        ])
        .args([
            "--blocks-3d",
            "20x20x20",
            "--trend",
            "none",
            "--rolls",
            "10",
        ])
        .args(["--threads", "1", "--flight-dts", "1e-6", "--out"])
        .arg(&out)
        .stdout(std::process::Stdio::null())
        .stderr(std::fs::File::create(&log).unwrap())
        .spawn()
        .unwrap();
    // The limit cases done (three 3D rows logged), the free flight has begun: 2 s at 1 µs,
    // two million steps an integrator.
    let t = std::time::Instant::now();
    while std::fs::read_to_string(&log)
        .unwrap_or_default()
        .matches("3d_quasi_static")
        .count()
        < 3
    {
        assert!(t.elapsed().as_secs() < 120, "the limit cases never ended");
        assert!(child.try_wait().unwrap().is_none(), "validate ended early");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    unsafe { libc::kill(child.id() as i32, libc::SIGINT) };
    let status = exit_within(
        &mut child,
        5,
        "validate ignored Ctrl-C in its free-flight stage",
    );
    assert_eq!(status.code(), Some(130));
    assert!(
        !out.join("validate.json").exists(),
        "a stopped run wrote its outputs"
    );
}
