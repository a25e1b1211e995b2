//! Dice of any shape (`--shape`, a mesh `--die`): the named dice fair in a tumble on both
//! engines, a cube given as a mesh the built-in d6, a coin's three outcomes, bad meshes and
//! bad combinations refused in one line, and a shaped run resumed, sharded and merged bit for
//! bit. Each statistical check states its tolerance in standard errors at a fixed seed.

use super::helpers::{bin, dicephys, json, Scratch};

/// `roll` of a die of any shape as JSON.
fn roll(args: &[&str]) -> serde_json::Value {
    json(&dicephys(
        &[&["roll", "--json", "--seed", "1"][..], args].concat(),
    ))
}

/// The JSON's outcomes: (label, count) in the die's order.
fn faces(v: &serde_json::Value) -> Vec<(String, u64)> {
    v["shape"]["faces"]
        .as_array()
        .expect("a shape's faces")
        .iter()
        .map(|f| {
            (
                f["label"].as_str().unwrap().to_string(),
                f["count"].as_u64().unwrap(),
            )
        })
        .collect()
}

/// Every face within `tol` standard errors of 1/N and the χ² against a fair die not rejected
/// at 0.001; the labels those the convention gives.
fn fair(v: &serde_json::Value, labels: &[&str], tol: f64) {
    let f = faces(v);
    let mut got: Vec<&str> = f.iter().map(|(l, _)| l.as_str()).collect();
    got.sort_by_key(|l| l.parse::<u32>().unwrap_or(u32::MAX));
    assert_eq!(got, labels, "{}", v["shape"]);
    for face in v["shape"]["faces"].as_array().unwrap() {
        let z = face["z_fair"].as_f64().unwrap();
        assert!(
            z.abs() < tol,
            "face {face} is {z:.1}σ from 1/N: {}",
            v["shape"]
        );
    }
    let p = v["shape"]["p_value"].as_f64().unwrap();
    assert!(p > 0.001, "χ² p {p}: {}", v["shape"]);
    // Few rolls end leaning or unsettled.
    let settled = v["counts"]["face"].as_u64().unwrap();
    assert!(
        settled * 100 >= 98 * v["rolls"].as_u64().unwrap(),
        "{}",
        v["counts"]
    );
}

fn numbers(n: u32) -> Vec<String> {
    (1..=n).map(|k| k.to_string()).collect()
}

#[test]
fn the_named_dice_come_up_fair_in_a_tumble_on_bullet() {
    // 1,200 rolls a die: 1/N known to about ±0.006 (a d4's ±0.0125): 4σ each (six dice,
    // up to 20 faces each, so a 3σ bound would fail by chance about one run in four).
    for (name, n) in [
        ("d4", 4),
        ("d6", 6),
        ("d8", 8),
        ("d10", 10),
        ("d12", 12),
        ("d20", 20),
    ] {
        let v = roll(&["--shape", name, "--rolls", "1200"]);
        let labels = numbers(n);
        let labels: Vec<&str> = labels.iter().map(String::as_str).collect();
        fair(&v, &labels, 4.0);
        assert_eq!(v["spec"]["throws"]["style"], "tumble", "{name}");
    }
}

#[test]
fn a_d20_comes_up_fair_on_rapier() {
    let v = roll(&["--shape", "d20", "--rolls", "600", "--engine", "rapier"]);
    let labels = numbers(20);
    let labels: Vec<&str> = labels.iter().map(String::as_str).collect();
    fair(&v, &labels, 4.0);
}

/// A cube of side `s` mm as an OBJ mesh: eight corners, six quads, counter-clockwise seen
/// from outside.
pub(crate) fn cube_obj(s: f64) -> String {
    let h = s / 2.0;
    let mut t = String::from("# a cube\n");
    for k in 0..8 {
        let c = |bit: usize| if k >> bit & 1 == 1 { h } else { -h };
        t += &format!("v {} {} {}\n", c(0), c(1), c(2));
    }
    // Corners numbered from 1: bit 0 x, bit 1 y, bit 2 z.
    for f in [
        "1 3 4 2", // -z
        "5 6 8 7", // +z
        "1 2 6 5", // -y
        "3 7 8 4", // +y
        "1 5 7 3", // -x
        "2 4 8 6", // +x
    ] {
        t += &format!("f {f}\n");
    }
    t
}

/// Pearson's χ² of two count vectors against their common proportions, on k − 1 degrees of
/// freedom.
fn two_sample_chi2(a: &[u64], b: &[u64]) -> f64 {
    let (na, nb) = (a.iter().sum::<u64>() as f64, b.iter().sum::<u64>() as f64);
    a.iter()
        .zip(b)
        .map(|(&x, &y)| {
            let p = (x + y) as f64 / (na + nb);
            let (ea, eb) = (p * na, p * nb);
            if p == 0.0 {
                0.0
            } else {
                (x as f64 - ea).powi(2) / ea + (y as f64 - eb).powi(2) / eb
            }
        })
        .sum()
}

#[test]
fn a_cube_given_as_a_mesh_rolls_as_the_built_in_d6_on_both_engines() {
    let dir = Scratch::new("shape-obj");
    let obj = dir.join("cube.obj");
    std::fs::write(&obj, cube_obj(16.0)).unwrap();
    for (engine, rolls) in [("bullet", "1200"), ("rapier", "400")] {
        let mesh = roll(&[
            "--die",
            obj.to_str().unwrap(),
            "--rolls",
            rolls,
            "--engine",
            engine,
        ]);
        let d6 = roll(&["--shape", "d6", "--rolls", rolls, "--engine", engine]);
        // The mesh ran on the general hull path, and says which die it was.
        assert!(
            mesh["shape"]["shape"]
                .as_str()
                .unwrap()
                .starts_with("cube.obj"),
            "{}",
            mesh["shape"]
        );
        assert!(mesh["spec"]["scene"]["shape"]["solid"]["hull"].is_object());
        let counts = |v: &serde_json::Value| {
            let mut f: Vec<u64> = faces(v).iter().map(|(_, c)| *c).collect();
            f.sort();
            f
        };
        // The mesh's facets are numbered by its own order, the d6's by its layout: compare
        // the sorted counts, and each a fair die within 4σ.
        let (a, b) = (counts(&mesh), counts(&d6));
        assert_eq!(a.len(), 6);
        let chi2 = two_sample_chi2(&a, &b);
        // χ²₅ exceeds 20.5 with probability 0.001.
        assert!(
            chi2 < 20.5,
            "{engine}: mesh {a:?} against d6 {b:?}: χ² {chi2:.1}"
        );
        for (_, f) in [&mesh, &d6].iter().map(|v| ((), v)) {
            for face in f["shape"]["faces"].as_array().unwrap() {
                assert!(
                    face["z_fair"].as_f64().unwrap().abs() < 4.0,
                    "{engine}: {face}"
                );
            }
        }
    }
}

#[test]
fn a_coin_lands_heads_tails_or_on_its_edge() {
    let v = roll(&["--shape", "coin:24,2", "--rolls", "600"]);
    let f = faces(&v);
    let labels: Vec<&str> = f.iter().map(|(l, _)| l.as_str()).collect();
    assert_eq!(labels, ["heads", "tails", "edge"]);
    let (h, t) = (f[0].1 as f64, f[1].1 as f64);
    // Heads and tails alike within 4σ of their difference; a thin coin rarely on its edge.
    let z = (h - t) / (h + t).sqrt();
    assert!(z.abs() < 4.0, "heads {h} tails {t}");
    assert!(f[2].1 * 20 < 600, "edge {}", f[2].1);
    // A coin as thick as it is wide stands on its edge most often (and a cylinder rolling
    // on its side may roll on to the cap: `roll::SHAPE_MAX_STEPS`, counted unconverged).
    let v = roll(&["--shape", "coin:10,10", "--rolls", "60"]);
    let f = faces(&v);
    assert!(f[2].1 > f[0].1 + f[1].1, "{}", v["shape"]);
    assert_eq!(v["spec"]["roll"]["max_steps"], 200_000);
    // With a little rolling resistance (0.05 mm) every thick coin stops, on Bullet and on
    // Rapier (its couple after each step); the arbiter has none, and says so.
    let v = roll(&[
        "--shape",
        "coin:24,12",
        "--rolls",
        "100",
        "--rolling-resistance",
        "0.05",
    ]);
    assert_eq!(v["unconverged"], 0, "{}", v["shape"]);
    assert_eq!(v["spec"]["scene"]["rolling_resistance"], 5e-5);
    let v = roll(&[
        "--shape",
        "coin:24,12",
        "--rolls",
        "40",
        "--engine",
        "rapier",
        "--rolling-resistance",
        "0.05",
    ]);
    assert_eq!(v["unconverged"], 0, "rapier: {}", v["shape"]);
    // Without it (a coin on Bullet is given 0.05 mm unless told: issue 69), `roll` and
    // `fair` say before rolling that a coin may never stop.
    for command in ["roll", "fair"] {
        let out = dicephys(&[
            command,
            "--shape",
            "coin:24,2",
            "--rolls",
            "2",
            "--rolling-resistance",
            "0",
            "--json",
        ]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("--rolling-resistance 0.05"),
            "{command}: {err}"
        );
    }
    refused(
        &[
            "roll",
            "--shape",
            "coin:24,12",
            "--engine",
            "moreau",
            "--rolling-resistance",
            "0.05",
        ],
        &[
            "--rolling-resistance 0.05",
            "moreau has no rolling resistance",
        ],
    );
}

#[test]
fn trace_stops_at_the_step_cap_roll_takes() {
    // Issue 69.10: a thick coin on a floor without rolling resistance rolls on its edge for
    // ever. `roll` caps it at a die of any shape's 200,000 steps; `trace` took DicePhys's
    // 20,000,000 and wrote 301 MB in 10 s. Throw 0 of seed 1 is such a throw.
    let coin = [
        "trace",
        "--shape",
        "coin:24,8.5",
        "--rolling-resistance",
        "0",
        "--seed",
        "1",
        "--index",
        "0",
    ];
    // Rows: the header, then steps 0 to the cap (the last always printed).
    let rows = |out: &std::process::Output| {
        let text = String::from_utf8_lossy(&out.stdout).into_owned();
        let steps: Vec<u64> = text
            .lines()
            .skip(1)
            .map(|l| l.split(',').next().unwrap().parse().unwrap())
            .collect();
        assert!(text.starts_with("step,time_s,"), "{text}");
        steps
    };
    // A cap asked: at most cap + 1 rows, the last the cap's, and stderr says the cap ended it.
    let out = dicephys(&[&coin[..], &["--max-steps", "300"]].concat());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    let steps = rows(&out);
    assert!(steps.len() <= 301, "{} rows", steps.len());
    assert_eq!(steps.last(), Some(&300));
    assert!(
        err.contains("the step cap ended the trace: the die was not at rest after 300 steps"),
        "{err}"
    );
    // None asked: `roll`'s cap for the die, 200,000 steps (every 100,000th row printed, so
    // that the output stays small; the roll takes about a second).
    let out = dicephys(&[&coin[..], &["--every", "100000"]].concat());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert_eq!(rows(&out), [0, 100_000, 200_000], "{err}");
    assert!(
        err.contains("not at rest after 200000 steps (a die of any shape's default"),
        "{err}"
    );
    assert!(
        err.contains("unconverged (showing edge at the cap)"),
        "{err}"
    );
    let roll = json(&dicephys(&[
        "roll",
        "--json",
        "--shape",
        "coin:24,8.5",
        "--rolls",
        "1",
    ]));
    assert_eq!(roll["spec"]["roll"]["max_steps"], 200_000);
    // A die that settles says nothing of the cap.
    let out = dicephys(&["trace", "--shape", "d20", "--seed", "1", "--every", "100"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("settled"), "{err}");
    assert!(!err.contains("step cap"), "{err}");
}

/// One line on stderr, exit 2, containing every one of `says`.
fn refused(args: &[&str], says: &[&str]) {
    let o = dicephys(args);
    let e = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
    assert_eq!(e.trim_end().lines().count(), 1, "{args:?}: {e}");
    for s in says {
        assert!(e.contains(s), "{args:?}: wanted '{s}' in {e}");
    }
}

#[test]
fn bad_meshes_and_combinations_are_refused_in_one_line() {
    let dir = Scratch::new("shape-bad");
    let holed = dir.join("holed.obj");
    // The cube less its +x face: open.
    let text: String = cube_obj(16.0)
        .lines()
        .filter(|l| *l != "f 2 4 8 6")
        .map(|l| format!("{l}\n"))
        .collect();
    std::fs::write(&holed, text).unwrap();
    let h = holed.to_str().unwrap();
    refused(&["roll", "--die", h], &["--die", "closed"]);
    let missing = dir.join("missing.stl");
    refused(&["roll", "--die", missing.to_str().unwrap()], &["--die"]);
    refused(
        &["roll", "--die", dir.to_str().unwrap()],
        &["--die", "directory"],
    );
    let garbage = dir.join("garbage.stl");
    std::fs::write(&garbage, "not a mesh at all").unwrap();
    refused(&["roll", "--die", garbage.to_str().unwrap()], &["--die"]);
    refused(&["roll", "--shape", "d7"], &["--shape"]);
    refused(&["roll", "--shape", "coin:24"], &["--shape"]);
    refused(
        &["roll", "--shape", "d20", "--throw", "paper"],
        &["--throw", "tumble"],
    );
    refused(&["roll", "--shape", "d20", "--2d"], &["--shape", "3D"]);
    refused(&["roll", "--shape", "d20", "--pips", "3,1"], &["pips"]);
    // A convex die takes a rounding (issue 72's fifth round; refused before it), but not
    // past its inradius, and a coin's rim is its own.
    refused(
        &["roll", "--shape", "d20", "--edge-radius", "50"],
        &["--edge-radius", "leaves no die"],
    );
    refused(
        &["roll", "--shape", "coin:24,2", "--edge-radius", "0.5"],
        &["--edge-radius", "coin"],
    );
    refused(
        &["roll", "--shape", "d20", "--com", "0,0,30"],
        &["--com", "inside"],
    );
    refused(
        &["roll", "--shape", "d20", "--block", "16x16x16"],
        &["--block"],
    );
    refused(&["roll", "--size", "20"], &["--size"]);
    refused(&["roll", "--shape", "d20", "--scale", "2"], &["--scale"]);
}

#[test]
fn a_shaped_run_resumes_and_merges_bit_for_bit() {
    let dir = Scratch::new("shape-resume");
    let args = ["--shape", "d8", "--rolls", "2500", "--com", "0,0,-1"];
    let whole = roll(&args);
    let ck = dir.join("ck");
    let first = roll(&[&args[..], &["--checkpoint", ck.to_str().unwrap()]].concat());
    assert_eq!(first["tally"], whole["tally"]);
    // Resumed from its complete checkpoint: every chunk read back, the same tally.
    let again = json(&dicephys(&[
        "roll",
        "--json",
        "--resume",
        ck.to_str().unwrap(),
    ]));
    assert_eq!(again["tally"], whole["tally"]);
    assert_eq!(again["shape"], whole["shape"]);
    // Two shards merged: the unsharded result.
    let mut files = Vec::new();
    for k in 0..2 {
        let v = roll(&[&args[..], &["--shard", &format!("{k}/2")]].concat());
        let f = dir.join(format!("s{k}.json"));
        std::fs::write(&f, v.to_string()).unwrap();
        files.push(f);
    }
    let merged = json(
        &bin()
            .arg("merge")
            .arg("--json")
            .args(&files)
            .output()
            .unwrap(),
    );
    assert_eq!(merged["tally"], whole["tally"]);
    assert_eq!(merged["faces"], whole["faces"]);
}

/// A die of sixteen irregular facets (eight of them resting faces), about 17 mm across: the
/// quasi-static theory's test die (`docs/results/shapes.md`).
pub const IRREGULAR_OBJ: &str = "v 8 0.8 1.6\nv -7.2 1.6 -0.8\nv 0.8 8.8 0\nv 1.6 -8 2.4\n\
v 0 0.8 9.6\nv 0.8 -1.6 -7.6\nv 4.8 5.6 4\nv -4 -4.8 4.8\nv 4.4 -5.2 -4\nv -4.8 4 -4.4\n\
f 1 6 3\nf 1 3 7\nf 1 5 4\nf 1 4 9\nf 1 7 5\nf 1 9 6\nf 2 5 3\nf 2 3 10\nf 2 8 5\nf 2 6 8\n\
f 2 10 6\nf 3 5 7\nf 3 6 10\nf 4 5 8\nf 4 8 6\nf 4 6 9\n";

/// `fair --null quasi-static` for a die of any shape: the exact basins of its rolling beside
/// the counts (a d20's 1/20; a loaded d10's computed, summing to 1), the same in `roll`'s
/// JSON, and `solid-angle` its other name.
#[test]
fn fair_judges_any_die_against_the_quasi_static_theory() {
    let v = json(&dicephys(&[
        "fair",
        "--shape",
        "d20",
        "--null",
        "quasi-static",
        "--rolls",
        "400",
        "--json",
    ]));
    assert_eq!(v["fairness"]["null"], "quasi-static");
    // `--out`: the faces figure and the die map (its hull from two sides) for any die.
    let out = Scratch::new("fair-d20-out");
    let dir = out.path().join("d20");
    let args = ["fair", "--shape", "d20", "--rolls", "200", "--out"];
    assert!(dicephys(&[&args[..], &[dir.to_str().unwrap()]].concat())
        .status
        .success());
    for f in [
        "faces.svg",
        "faces.png",
        "fairness.json",
        "die_map.svg",
        "die_map.png",
    ] {
        assert!(std::fs::metadata(dir.join(f)).unwrap().len() > 1000, "{f}");
    }
    // `--vary` for any die: every face at every value, in the table, the JSON and the figure.
    let vary = dir.with_file_name("d10-vary");
    let args = [
        "fair",
        "--shape",
        "d10",
        "--vary",
        "com_z=0:1:2",
        "--rolls",
        "100",
    ];
    let out = dicephys(&[&args[..], &["--out", vary.to_str().unwrap()]].concat());
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).contains("P(1 … 10, 10 faces)"));
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(vary.join("bias.json")).unwrap()).unwrap();
    assert_eq!(
        doc["points"][1]["fairness"]["faces"]
            .as_array()
            .unwrap()
            .len(),
        10
    );
    assert!(std::fs::metadata(vary.join("bias.svg")).unwrap().len() > 1000);
    let faces = v["fairness"]["faces"].as_array().unwrap();
    assert_eq!(faces.len(), 20);
    for f in faces {
        assert!((f["null"].as_f64().unwrap() - 0.05).abs() < 1e-9, "{f}");
    }
    let args = ["--shape", "d10", "--com", "0,0,-2", "--rolls", "300"];
    let fair = json(&dicephys(
        &[&["fair", "--null", "solid-angle", "--json"][..], &args[..]].concat(),
    ));
    let roll = roll(&args);
    let by_label = |faces: &serde_json::Value, label: &str, value: &str| {
        let mut v: Vec<(String, f64)> = faces
            .as_array()
            .unwrap()
            .iter()
            .map(|f| {
                (
                    f[label].as_str().unwrap().to_string(),
                    f[value].as_f64().unwrap(),
                )
            })
            .collect();
        v.sort_by(|a, b| a.0.cmp(&b.0));
        v
    };
    let theory = by_label(&roll["shape"]["faces"], "label", "quasi_static");
    let q: Vec<f64> = theory.iter().map(|x| x.1).collect();
    assert!((q.iter().sum::<f64>() - 1.0).abs() < 1e-9, "{q:?}");
    // Loaded 2 mm towards the −z point's kites: those five faces down more often.
    assert!(q.iter().cloned().fold(0.0, f64::max) > 0.11, "{q:?}");
    assert_eq!(
        by_label(&fair["fairness"]["faces"], "direction", "null"),
        theory
    );
    assert!(roll["shape"]["against_quasi_static"][0].as_f64().is_some());
}

/// The rest limit: the irregular die released at rest on a floor with e = 0, μ = 1 and the
/// most damping (30/s), made large (×12, 200 mm across) so that the damping overwhelms its
/// swing (√(g/h) ≈ 13/s, h its centre's height at rest) and it rolls down quasi-statically.
/// Every resting face within 4σ of the theory but face 8, which holds the centre of mass only
/// 0.13 mm (×12) inside its edge: the throws its basin sends to it arrive moving and roll on
/// over that edge onto face 2, so faces 2 and 8 together are the theory's. At its own 17 mm
/// size (√(g/h) ≈ 44/s, damping no longer overwhelming) momentum carries the die over every
/// shallow face (4, 5, 7: 0.5-0.75 mm): they get under half their share.
/// docs/results/shapes.md has both at 100,000 throws.
#[test]
fn released_at_rest_a_large_overdamped_die_rolls_down_as_the_theory_says() {
    let dir = Scratch::new("rest-limit");
    let obj = dir.path().join("irregular.obj");
    std::fs::write(&obj, IRREGULAR_OBJ).unwrap();
    let rest = |scale: &str, rolls: &str| {
        let v = roll(&[
            "--die",
            obj.to_str().unwrap(),
            "--scale",
            scale,
            "--throw",
            "rest",
            "--restitution",
            "0",
            "--friction",
            "1",
            "--linear-damping",
            "30",
            "--angular-damping",
            "30",
            "--rolls",
            rolls,
        ]);
        let n: u64 = faces(&v).iter().map(|f| f.1).sum();
        let p = |labels: &[&str]| {
            let f = v["shape"]["faces"].as_array().unwrap();
            let get = |key: &str| -> f64 {
                f.iter()
                    .filter(|x| labels.contains(&x["label"].as_str().unwrap()))
                    .map(|x| x[key].as_f64().unwrap())
                    .sum()
            };
            (get("p"), get("quasi_static"))
        };
        let z = |labels: &[&str]| {
            let (p, q) = p(labels);
            (p - q) / (q * (1.0 - q) / n as f64).sqrt()
        };
        (
            p(&["4", "5", "7"]),
            z(&["2", "8"]),
            p(&["8"]).0,
            labels_z(&v, &z),
        )
    };
    fn labels_z(_: &serde_json::Value, z: &dyn Fn(&[&str]) -> f64) -> Vec<f64> {
        ["1", "3", "4", "5", "6", "7"]
            .iter()
            .map(|l| z(&[l]))
            .collect()
    }
    let (_, z28, p8, zs) = rest("12", "3000");
    assert!(zs.iter().all(|z| z.abs() < 4.0), "{zs:?}");
    assert!(
        z28.abs() < 4.0 && p8 < 0.01,
        "2 and 8: {z28:+.1}σ; 8 alone {p8}"
    );
    let ((p, q), _, _, _) = rest("1", "2000");
    assert!(p < 0.5 * q, "the shallow faces at 19 mm: {p} against {q}");
}
