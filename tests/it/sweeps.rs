//! The sweeps at tiny size (their JSON and figures) and stopped by Ctrl-C, and the failure
//! detectors on failures made on purpose.

use super::helpers::{interrupted, scratch, stderr, Scratch, ENDLESS_ROLLS};
use dicephys::engine::{new_engine, EngineKind};
use dicephys::model::scene::{Floor, Mode, Scene};
use dicephys::model::state::BodyState;
use dicephys::model::throws::{ThrowKind, ThrowRanges, Throws};
use dicephys::sim::roll::{roll, run_from, Failure, Fate, RollConfig};
use nalgebra::{UnitQuaternion, Vector3};
use std::path::Path;

/// A command's `--json` document (the shared runner, its failure the test's).
fn dicephys(args: &[&str]) -> serde_json::Value {
    super::helpers::json(&super::helpers::dicephys(args))
}

fn out_dir(name: &str) -> Scratch {
    Scratch::absent(&format!("sweeps-{name}"))
}

fn has_keys(v: &serde_json::Value, keys: &[&str]) {
    for k in keys {
        assert!(v.get(k).is_some(), "missing key {k} in {v}");
    }
}

fn svg(dir: &Path, stem: &str) {
    let text = std::fs::read_to_string(dir.join(format!("{stem}.svg"))).expect("the SVG");
    assert!(text.contains("<svg"), "{stem}.svg is not an SVG");
    assert!(dir.join(format!("{stem}.png")).exists(), "{stem}.png");
}

#[test]
fn converge_at_tiny_size() {
    let dir = out_dir("converge");
    let v = dicephys(&[
        "converge",
        "--blocks",
        "140x24x20",
        "--dts",
        "1/1000,1/2000",
        "--engines",
        "bullet",
        "--rolls",
        "20",
        "--threads",
        "1",
        "--out",
        dir.to_str().unwrap(),
        "--json",
    ]);
    has_keys(
        &v,
        &[
            "settle", "rolls", "dts", "cells", "claims", "resolved", "verdict",
        ],
    );
    let cells = v["cells"].as_array().unwrap();
    assert_eq!(cells.len(), 4, "1 block × 1 engine × 2 modes × 2 dts");
    for c in cells {
        has_keys(
            c,
            &[
                "block",
                "engine",
                "mode",
                "dt",
                "ratio",
                "ratio_err",
                "steps_per_roll",
                "cpu_s_per_roll",
                "departure",
                "departure_err",
                "energy_gain",
            ],
        );
    }
    // dt = 1/1000 against 1/2000, in 3D and 2D; 20 rolls cannot resolve 1 %.
    let claims = v["claims"].as_array().unwrap();
    assert_eq!(claims.len(), 2);
    assert_eq!(v["resolved"], false);
    assert!(claims[0]["rolls_needed"].as_u64().unwrap() > 20);
    let verdict = v["verdict"].as_str().unwrap();
    assert!(
        verdict.starts_with("Not resolved") || verdict.starts_with("Decided"),
        "{verdict}"
    );
    // The claim at 2σ: yes inside ±1 % once 2σ ≤ 1 %, no once the interval clears ±1 %.
    use dicephys::studies::converge::decide;
    assert_eq!(decide(0.005, 0.002), Some(true));
    assert_eq!(decide(-0.02, 0.004), Some(false));
    assert_eq!(decide(0.2, 0.05), Some(false));
    assert_eq!(decide(0.005, 0.01), None);
    assert_eq!(decide(0.03, 0.015), None);
    svg(&dir, "converge");
    assert!(dir.join("converge.json").exists() && dir.join("report.md").exists());
}

/// The tiny trade-off: Bullet and Rapier at 1/250 against Bullet at 1/1000, no ladder.
fn tradeoff_tiny(dir: &Path, precision: &str, budget: &str) -> serde_json::Value {
    dicephys(&[
        "tradeoff",
        "--dts",
        "1/250",
        "--rapier-dts",
        "1/250",
        "--reference-dt",
        "1/1000",
        "--ladder",
        "none",
        "--precision",
        precision,
        "--budget",
        budget,
        "--reference-budget",
        "20",
        "--threads",
        "2",
        "--out",
        dir.to_str().unwrap(),
        "--json",
    ])
}

/// Checkpoint directories under a sweep's --out.
fn cells(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir.join("checkpoint"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn tradeoff_resolves_to_the_precision_or_says_what_it_needs() {
    let dir = out_dir("tradeoff");
    let v = tradeoff_tiny(&dir, "30", "20");
    has_keys(
        &v,
        &[
            "block",
            "precision",
            "budget_s",
            "planned_cpu_s",
            "precision_in_an_hour",
            "modes",
        ],
    );
    assert_eq!(v["precision"].as_f64().unwrap(), 0.3);
    let modes = v["modes"].as_array().unwrap();
    assert_eq!(modes.len(), 2);
    for m in modes {
        has_keys(
            m,
            &[
                "mode",
                "reference",
                "checks",
                "rows",
                "pareto_front",
                "cheapest_within",
                "note",
            ],
        );
        // The reference: 2σ of its own ratio within half the precision.
        let rf = &m["reference"];
        assert!(rf["resolved"].as_bool().unwrap());
        assert!(
            2.0 * rf["ratio_err"].as_f64().unwrap() / rf["ratio"].as_f64().unwrap() <= 0.15 * 1.02
        );
        let rows = m["rows"].as_array().unwrap();
        assert_eq!(rows.len(), if m["mode"] == "3d" { 8 } else { 12 });
        for r in rows {
            let rolls = r["rolls"].as_u64().unwrap();
            assert!(rolls >= 1000 && rolls % 1000 == 0, "{r}");
            let err = r["error_err"].as_f64().unwrap();
            // Resolved means 2σ within the precision; otherwise the rolls it would need.
            assert_eq!(r["resolved"].as_bool().unwrap(), 2.0 * err <= 0.3, "{r}");
            if !r["resolved"].as_bool().unwrap() {
                assert!(r["rolls_needed"].as_u64().unwrap() > rolls, "{r}");
            }
        }
        // The front: resolved methods only, cheapest first, each closer than the one before.
        let front: Vec<&serde_json::Value> = m["pareto_front"]
            .as_array()
            .unwrap()
            .iter()
            .map(|n| rows.iter().find(|r| r["method"] == *n).unwrap())
            .collect();
        assert!(!front.is_empty());
        for w in front.windows(2) {
            assert!(w[0]["cpu_s_per_1000"].as_f64() <= w[1]["cpu_s_per_1000"].as_f64());
            assert!(w[0]["error"].as_f64().unwrap().abs() > w[1]["error"].as_f64().unwrap().abs());
        }
        assert!(front.iter().all(|r| r["resolved"].as_bool().unwrap()));
    }
    svg(&dir, "tradeoff");
    // A finer precision adds rounds to the same streams: no new checkpoint, the same prefix;
    // a budget of 1 CPU s leaves the dearer methods unresolved, with the rolls they need.
    let before = cells(&dir);
    let w = tradeoff_tiny(&dir, "12", "1");
    assert_eq!(cells(&dir), before);
    let mut open = 0;
    let mut more = 0;
    for (m, n) in modes.iter().zip(w["modes"].as_array().unwrap()) {
        for (r, s) in m["rows"]
            .as_array()
            .unwrap()
            .iter()
            .zip(n["rows"].as_array().unwrap())
        {
            assert!(s["rolls"].as_u64() >= r["rolls"].as_u64(), "{s}");
            more += (s["rolls"].as_u64() > r["rolls"].as_u64()) as u32;
            let err = s["error_err"].as_f64().unwrap();
            assert_eq!(s["resolved"].as_bool().unwrap(), 2.0 * err <= 0.12, "{s}");
            if !s["resolved"].as_bool().unwrap() {
                open += 1;
                assert!(
                    s["rolls_needed"].as_u64().unwrap() > s["rolls"].as_u64().unwrap(),
                    "{s}"
                );
                assert!(!n["pareto_front"].as_array().unwrap().contains(&s["method"]));
            }
        }
    }
    assert!(
        more > 0 && open > 0,
        "rounds added: {more}, left open: {open}"
    );
    // And the same command again reads every roll back: the same counts. (CPU is a
    // measurement: a chunk's stored cost and the live one differ by the writing.)
    let again = tradeoff_tiny(&dir, "12", "1");
    let counts = |v: &serde_json::Value| -> Vec<(serde_json::Value, serde_json::Value)> {
        v["modes"]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(|m| m["rows"].as_array().unwrap().clone())
            .map(|r| (r["rolls"].clone(), r["ratio"].clone()))
            .collect()
    };
    assert_eq!(counts(&again), counts(&w));
}

/// Two blocks, 3D only, at the coarsest steps (a pilot of a few CPU seconds): each block has
/// its own reference and methods, and the summary across them is what their rows say.
#[test]
fn tradeoff_on_several_blocks_sums_up_each_method_across_them() {
    let dir = out_dir("tradeoff-blocks");
    let v = dicephys(&[
        "tradeoff",
        "--blocks",
        "140x24x20,140x30x10",
        "--modes",
        "3d",
        "--dts",
        "1/10,1/20",
        "--rapier-dts",
        "1/10",
        "--reference-dt",
        "1/40",
        "--max-steps",
        "2000",
        "--ladder",
        "none",
        "--precision",
        "60",
        "--budget",
        "2",
        "--reference-budget",
        "2",
        "--threads",
        "2",
        "--out",
        dir.to_str().unwrap(),
        "--json",
    ]);
    let p = v["precision"].as_f64().unwrap();
    let blocks = v["per_block"].as_array().unwrap();
    assert_eq!(blocks.len(), 2);
    assert_eq!(blocks[1]["block"], "140x30x10");
    let rows = |b: usize| -> Vec<serde_json::Value> {
        let modes = blocks[b]["modes"].as_array().unwrap();
        assert_eq!(modes.len(), 1, "3d only");
        assert_eq!(modes[0]["mode"], "3d");
        modes[0]["rows"].as_array().unwrap().clone()
    };
    let (r0, r1) = (rows(0), rows(1));
    // Each block its own reference: other counts, the same throws.
    assert_ne!(
        blocks[0]["modes"][0]["reference"]["ratio"],
        blocks[1]["modes"][0]["reference"]["ratio"]
    );
    let across = v["across"].as_array().unwrap();
    assert_eq!(across.len(), 1);
    let methods = across[0]["methods"].as_array().unwrap();
    assert_eq!(methods.len(), r0.len());
    // null: not a number (a ratio with no width-vertical throws, which these steps give).
    let f = |r: &serde_json::Value, k: &str| r[k].as_f64().unwrap_or(f64::NAN);
    let size = |r: &serde_json::Value| {
        let e = f(r, "error").abs();
        if e.is_nan() {
            f64::INFINITY
        } else {
            e
        }
    };
    let within = |r: &serde_json::Value| {
        r["resolved"].as_bool().unwrap()
            && r["failed"].as_u64().unwrap() + r["unconverged"].as_u64().unwrap()
                <= r["rolls"].as_u64().unwrap() / 100
            && f(r, "error").abs() <= p
    };
    let mut cheapest: Option<(f64, String)> = None;
    for (m, (a, b)) in methods.iter().zip(r0.iter().zip(&r1)) {
        assert_eq!(m["method"], a["method"]);
        // The worst is the larger |departure| of the two (a tie: the later block's), with its
        // own error.
        let worst = if size(a) > size(b) { a } else { b };
        assert_eq!(m["worst_error"], worst["error"], "{m}");
        assert_eq!(m["worst_error_err"], worst["error_err"], "{m}");
        let both = within(a) && within(b);
        assert_eq!(m["within_everywhere"].as_bool().unwrap(), both, "{m}");
        let cost = (f(a, "cpu_s_per_1000") + f(b, "cpu_s_per_1000")) / 2.0;
        assert!((f(m, "cpu_s_per_1000") - cost).abs() <= 1e-9 * cost, "{m}");
        if both && cheapest.as_ref().is_none_or(|c| cost < c.0) {
            cheapest = Some((cost, m["method"].as_str().unwrap().to_string()));
        }
    }
    assert_eq!(
        across[0]["cheapest_everywhere"].as_str(),
        cheapest.as_ref().map(|c| c.1.as_str())
    );
    let md = std::fs::read_to_string(dir.join("report.md")).unwrap();
    assert!(md.contains("## 3d across the blocks") && md.contains("## 140x30x10"));
    // The figure: a panel per block, and its key names every method (its name without the
    // mode, the same number in every panel).
    svg(&dir, "tradeoff");
    let fig = std::fs::read_to_string(dir.join("tradeoff.svg")).unwrap();
    for b in ["140x24x20", "140x30x10"] {
        assert!(fig.contains(b), "no panel for {b}");
    }
    for r in &r0 {
        let name = r["method"].as_str().unwrap().replacen(" 3d ", " ", 1);
        // A text element's content is a line of its own.
        assert!(
            fig.lines().any(|l| l.trim() == name),
            "the key lacks {name}"
        );
    }
}

#[test]
fn converge_with_a_precision_rolls_each_claim_in_rounds() {
    let dir = out_dir("converge-precision");
    let v = dicephys(&[
        "converge",
        "--blocks",
        "140x24x20",
        "--dts",
        "1/1000,1/2000",
        "--engines",
        "bullet",
        "--fast",
        "--precision",
        "40",
        "--threads",
        "2",
        "--out",
        dir.to_str().unwrap(),
        "--json",
    ]);
    let claims = v["claims"].as_array().unwrap();
    assert_eq!(claims.len(), 2);
    for c in claims {
        // 1 % is the claim, whatever precision the cells were rolled to: at 40 % it is open,
        // and the rolls that would close it are said.
        assert!(!c["resolved"].as_bool().unwrap(), "{c}");
        assert!(c["rolls_needed"].as_u64().unwrap() > 10_000, "{c}");
        assert!(c["rolls"][0].as_u64().unwrap() >= 1000, "{c}");
    }
    for cell in v["cells"].as_array().unwrap() {
        let resolved = cell["resolved"].as_bool().unwrap();
        if cell["dt"].as_f64().unwrap() > 0.0006 {
            assert_eq!(
                resolved,
                2.0 * cell["departure_err"].as_f64().unwrap() <= 0.4,
                "{cell}"
            );
        }
    }
    let verdict = v["verdict"].as_str().unwrap();
    assert!(
        verdict.starts_with("Not resolved") || verdict.starts_with("Decided"),
        "{verdict}"
    );
    // The claim at 2σ: yes inside ±1 % once 2σ ≤ 1 %, no once the interval clears ±1 %.
    use dicephys::studies::converge::decide;
    assert_eq!(decide(0.005, 0.002), Some(true));
    assert_eq!(decide(-0.02, 0.004), Some(false));
    assert_eq!(decide(0.2, 0.05), Some(false));
    assert_eq!(decide(0.005, 0.01), None);
    assert_eq!(decide(0.03, 0.015), None);
}

#[test]
fn tradeoff_refuses_a_bad_precision() {
    for bad in ["0", "-1", "100", "x%"] {
        let arg = format!("--precision={bad}");
        let out = super::helpers::dicephys(&["tradeoff", &arg, "--out", "/tmp/never-made"]);
        assert!(!out.status.success(), "{bad}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("precision"), "{bad}: {err}");
    }
}

#[test]
fn pairing_cancels_the_noise_of_a_lever_at_one_step_and_not_across_steps() {
    // Bullet 3D at 1 ms, DicePhys's rule stepped against the exact levers: the same throws end
    // alike, so the departure's paired error is a small part of the independent one; against
    // 1/250 s they decorrelate and pairing gains nothing (within a tenth).
    use dicephys::run::runner::Runner;
    use dicephys::studies::departure::paired_departure;
    use dicephys::studies::stream::Stream;
    use dicephys::studies::Study;
    let study = Study {
        runner: Runner::new(2, dicephys::run::stop::Stop::default()),
        checkpoint: None,
    };
    let block = dicephys::model::block::Block::from_mm(140.0, 24.0, 20.0).unwrap();
    let stream = |dt: f64, fast: bool| {
        let mut scene = Scene::paper(block, Mode::ThreeD);
        scene.dt = dt;
        let roll = RollConfig {
            rule: if fast {
                dicephys::sim::roll::Rule::Certificate
            } else {
                dicephys::sim::roll::Rule::Dicephys
            },
            fast_flight: fast,
            ..RollConfig::default()
        };
        let mut s = Stream::new(EngineKind::Bullet, scene, roll, 2385);
        s.extend(1, &study, &|_| {}).unwrap();
        s
    };
    let faithful = stream(0.001, false);
    let fast = stream(0.001, true);
    let coarse = stream(0.004, true);
    let same = paired_departure(&fast, &faithful);
    assert!(same.agreement > 0.95, "{same:?}");
    assert!(same.err < 0.3 * same.err_unpaired, "{same:?}");
    let other = paired_departure(&coarse, &faithful);
    assert!(other.agreement < 0.7, "{other:?}");
    assert!(
        (other.err / other.err_unpaired - 1.0).abs() < 0.1,
        "{other:?}"
    );
    // A stream against itself departs by exactly 0, with no error.
    let own = paired_departure(&fast, &fast);
    assert!(own.value == 0.0 && own.err < 1e-6, "{own:?}");
}

#[test]
fn stability_at_tiny_size() {
    let dir = out_dir("stability");
    let v = dicephys(&[
        "stability",
        "--engines",
        "bullet",
        "--dts",
        "1/1000,1/30",
        "--restitutions",
        "0,0.95",
        "--frictions",
        "0.29",
        "--blocks",
        "140x24x20",
        "--rolls",
        "10",
        "--threads",
        "1",
        "--out",
        dir.to_str().unwrap(),
        "--json",
    ]);
    has_keys(
        &v,
        &[
            "rolls",
            "max_steps",
            "energy_gain_tolerance",
            "cells",
            "findings",
        ],
    );
    let cells = v["cells"].as_array().unwrap();
    // Per mode: a 2 × 2 grid, one friction, one block.
    assert_eq!(cells.len(), 2 * (4 + 1 + 1));
    for c in cells {
        has_keys(
            c,
            &[
                "sweep",
                "engine",
                "mode",
                "dt",
                "restitution",
                "friction",
                "unconverged",
                "unknown",
                "non_finite",
                "tunnelled",
                "energy_gain",
            ],
        );
    }
    for kind in [
        "unconverged",
        "unknown",
        "non_finite",
        "tunnelled",
        "energy_gain",
    ] {
        svg(&dir, &format!("stability_{kind}"));
    }
}

fn scene(engine_floor: Floor, dt: f64, e: f64) -> Scene {
    let mut s = Scene::paper("140x24x20".parse().unwrap(), Mode::ThreeD);
    s.floor = engine_floor;
    s.dt = dt;
    s.restitution = e;
    s
}

const CAP: RollConfig = RollConfig {
    max_steps: 20_000,
    rule: dicephys::sim::roll::Rule::Dicephys,
    margin: dicephys::sim::roll::DEFAULT_MARGIN,
    audit: false,
    fast_flight: false,
};

#[test]
fn a_time_step_too_large_for_the_fall_is_flagged_as_tunnelling() {
    // dt = 0.1 s, the die 0.2 m up falling at 5 m/s: one step carries it 0.5 m, through the
    // floor's top face before any contact is seen.
    let sc = scene(Floor::Plane, 0.1, 0.5);
    let start = BodyState {
        position: Vector3::new(0.0, 0.2, 0.0),
        rotation: UnitQuaternion::identity(),
        linear_velocity: Vector3::new(0.0, -5.0, 0.0),
        angular_velocity: Vector3::zeros(),
        sleeping: false,
    };
    let mut engine = new_engine(EngineKind::Bullet, &sc).unwrap();
    let end = run_from(engine.as_mut(), &sc, &start, &CAP, |_, _| {});
    assert_eq!(end.fate, Fate::Failed(Failure::Tunnelled));
    assert_eq!(Failure::Tunnelled.name(), "tunnelled");
    // The same throw at the paper's dt lands on DicePhys's box floor. (Not on Bullet's plane:
    // there a flat landing at 5 m/s sinks through in four steps even at dt = 1 ms.)
    let sc = scene(Floor::Box, 0.001, 0.5);
    let mut engine = new_engine(EngineKind::Bullet, &sc).unwrap();
    let end = run_from(engine.as_mut(), &sc, &start, &CAP, |_, _| {});
    assert!(matches!(end.fate, Fate::Settled(_)), "{:?}", end.fate);
}

#[test]
fn a_restitution_above_one_is_flagged_as_energy_gain() {
    let throws = Throws::new(ThrowKind::Keyed, 7, ThrowRanges::default(), 0);
    let short = RollConfig {
        max_steps: 3_000,
        ..CAP
    };
    for kind in [EngineKind::Bullet, EngineKind::Rapier] {
        let pumped = scene(Floor::Box, 0.001, 1.5);
        let mut engine = new_engine(kind, &pumped).unwrap();
        for i in 0..3 {
            let r = roll(engine.as_mut(), &pumped, &throws.get(i), &short);
            assert!(r.energy_gain, "{kind} throw {i}: e = 1.5 not flagged");
        }
        // The paper's e = 0.5 gains nothing.
        let paper = scene(Floor::Box, 0.001, 0.5);
        let mut engine = new_engine(kind, &paper).unwrap();
        for i in 0..5 {
            let r = roll(engine.as_mut(), &paper, &throws.get(i), &CAP);
            assert!(!r.energy_gain, "{kind} throw {i}: e = 0.5 flagged");
        }
    }
}

#[test]
fn roll_json_counts_energy_gain() {
    let v = dicephys(&[
        "roll",
        "--block",
        "140x24x20",
        "--rolls",
        "5",
        "--restitution",
        "1.5",
        "--allow-restitution-above-one",
        "--max-steps",
        "3000",
        "--json",
    ]);
    assert_eq!(v["energy_gain"], 5);
    assert_eq!(v["energy_gain_tolerance"], 0.01);
}

/// `stability` with a floor `thickness` m thick: its JSON.
fn stability_cell_at_1_30(name: &str, thickness: &str) -> serde_json::Value {
    let dir = out_dir(name);
    dicephys(&[
        "stability",
        "--engines",
        "bullet",
        "--dts",
        "1/30",
        "--restitutions",
        "0.5",
        "--frictions",
        "0.29",
        "--blocks",
        "140x24x20",
        "--rolls",
        "40",
        "--threads",
        "1",
        "--floor-thickness",
        thickness,
        "--out",
        dir.to_str().unwrap(),
        "--json",
    ])
}

#[test]
fn stability_counts_dips_apart_and_tunnelling_only_through_a_thin_floor() {
    // dt = 1/30: nearly every roll's centre dips under the floor's top face. On DicePhys's
    // 100 m floor Bullet pushes every one back out (measured at 100 rolls: 98 % dipped in 3D,
    // 0 tunnelled); through a 2 cm table top most go (90 %).
    let thick = stability_cell_at_1_30("stability-thick", "100");
    let thin = stability_cell_at_1_30("stability-thin", "0.02");
    has_keys(
        &thick,
        &["floor_thickness", "fraction_err_max", "zero_below_95"],
    );
    // 40 rolls: a fraction's error at most 0.5/√40, a 0 below 1 − 0.05^(1/40) at 95 %.
    assert!((thick["fraction_err_max"].as_f64().unwrap() - 0.5 / 40f64.sqrt()).abs() < 1e-12);
    assert!((thick["zero_below_95"].as_f64().unwrap() - 0.0722).abs() < 1e-3);
    let grid = |v: &serde_json::Value, mode: &str| -> serde_json::Value {
        v["cells"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["sweep"] == "dt_restitution" && c["mode"] == mode)
            .unwrap()
            .clone()
    };
    for mode in ["3d", "2d"] {
        let (a, b) = (grid(&thick, mode), grid(&thin, mode));
        has_keys(&a, &["dipped", "fraction_err_max", "zero_below_95"]);
        assert!(a["dipped"].as_f64().unwrap() > 0.8, "{mode}: {a}");
        assert_eq!(a["tunnelled"], 0.0, "{mode}: {a}");
        assert!(b["tunnelled"].as_f64().unwrap() > 0.5, "{mode}: {b}");
    }
}

#[test]
fn a_sweep_stops_with_exit_130() {
    let d = scratch("sweep");
    let out = interrupted(
        &[
            "converge",
            "--blocks",
            "140x24x20",
            "--dts",
            "1/1000",
            "--engines",
            "bullet",
            "--rolls",
            ENDLESS_ROLLS,
            "--out",
            d.to_str().unwrap(),
        ],
        libc::SIGINT,
        1500,
    );
    assert_eq!(out.status.code(), Some(130), "{}", stderr(&out));
}

#[test]
fn a_roll_forced_non_finite_is_counted_as_failed() {
    let scene = Scene::paper("140x24x20".parse().unwrap(), Mode::ThreeD);
    let mut e = new_engine(EngineKind::Bullet, &scene).unwrap();
    let start = BodyState {
        position: Vector3::new(0.0, 0.3, 0.0),
        rotation: UnitQuaternion::identity(),
        linear_velocity: Vector3::new(f64::NAN, 0.0, 0.0),
        angular_velocity: Vector3::new(0.0, 0.0, 50.0),
        sleeping: false,
    };
    let end = run_from(
        e.as_mut(),
        &scene,
        &start,
        &RollConfig::default(),
        |_, _| {},
    );
    assert_eq!(end.fate, Fate::Failed(Failure::NonFinite));
    // The world is still usable for the next throw.
    let ok = BodyState {
        linear_velocity: Vector3::zeros(),
        ..start
    };
    let end = run_from(e.as_mut(), &scene, &ok, &RollConfig::default(), |_, _| {});
    assert!(matches!(end.fate, Fate::Settled(_)));
}
