//! Dice as they are made: a centre of mass off the centre (`--com`), drilled pips (`--pips`),
//! rounded edges (`--edge-radius`) and a die file (`--die`, read through a cap and named when
//! it cannot be read), on real Bullet and Rapier.

use crate::helpers::{bin, dicephys, exit_within, json, scratch, stderr, Scratch};
use dicephys::engine::{new_engine, EngineKind};
use dicephys::model::die::up_in_body;
use dicephys::model::faces::Layout;
use dicephys::model::mass::{Features, PipShape, Pips};
use dicephys::model::scene::{Mode, Scene};
use dicephys::model::state::BodyState;
use nalgebra::{UnitQuaternion, Vector3};
use std::path::Path;

fn faces(v: &serde_json::Value) -> [f64; 6] {
    std::array::from_fn(|k| v["faces"][(k + 1).to_string()].as_f64().unwrap())
}

/// `--com 0,0,-2` on a 16 mm cube (a weight 2 mm toward face 6), thrown in a tumble: face 1
/// comes up more often than face 6 by more than 5σ, and the four side faces, which the
/// weight's axis leaves equal by symmetry, are equal within error: Pearson's χ² of the four
/// against their mean is under 16.27 (3 degrees of freedom, p = 0.001). 6,000 throws on
/// Bullet, 1,500 on Rapier; seed fixed.
#[test]
fn a_weight_toward_six_brings_one_up_and_leaves_the_sides_equal_on_both_engines() {
    for (engine, rolls) in [("bullet", "6000"), ("rapier", "1500")] {
        let v = json(&dicephys(&[
            "roll", "--block", "16x16x16", "--throw", "tumble", "--com", "0,0,-2", "--rolls",
            rolls, "--seed", "5", "--engine", engine, "--json",
        ]));
        let f = faces(&v);
        let n: f64 = f.iter().sum();
        let (p1, p6) = (f[0] / n, f[5] / n);
        // The difference of two multinomial shares: var = (p1 + p6 − (p1 − p6)²)/n.
        let sigma = ((p1 + p6 - (p1 - p6).powi(2)) / n).sqrt();
        assert!(
            p1 - p6 > 5.0 * sigma,
            "{engine}: face 1 {p1:.4} against face 6 {p6:.4} (σ {sigma:.4})"
        );
        let sides = &f[1..5];
        let mean = sides.iter().sum::<f64>() / 4.0;
        let chi2: f64 = sides.iter().map(|x| (x - mean).powi(2) / mean).sum();
        assert!(chi2 < 16.27, "{engine}: sides {sides:?}, χ² {chi2:.2}");
    }
}

/// The exact early stop and the walk of every step give each throw the same face, and so do
/// the flight flown outside the engine and the engine's own steps, for a weighted, a rounded
/// and a drilled die and all three at once: `--faithful` (DicePhys's rest rule, every step
/// stepped) against the default (the certificate, flight flown), throw for throw. 600 throws
/// each on Bullet, 120 on Rapier.
#[test]
fn the_early_stop_and_every_step_agree_face_for_face_for_made_dice() {
    let dir = Scratch::new("made-agree");
    for (engine, rolls) in [("bullet", "600"), ("rapier", "120")] {
        for die in [
            &["--com", "1,-1,-2"][..],
            &["--edge-radius", "1.5"],
            &["--pips", "3,1"],
            &["--com", "0.5,0,-1", "--edge-radius", "1", "--pips", "2.5,1"],
        ] {
            let face_of = |extra: &[&str], name: &str| {
                let csv = dir.join(name);
                let args = [
                    &[
                        "roll",
                        "--block",
                        "16x16x16",
                        "--throw",
                        "tumble",
                        "--rolls",
                        rolls,
                        "--seed",
                        "9",
                        "--engine",
                        engine,
                        "--json",
                        "--per-roll",
                    ][..],
                    &[csv.to_str().unwrap()],
                    die,
                    extra,
                ]
                .concat();
                json(&dicephys(&args));
                let text = std::fs::read_to_string(&csv).unwrap();
                text.lines()
                    .skip(1)
                    .map(|l| l.rsplit(',').next().unwrap().to_string())
                    .collect::<Vec<_>>()
            };
            let fast = face_of(&[], "fast.csv");
            let every = face_of(&["--faithful"], "every.csv");
            assert_eq!(fast.len(), rolls.parse::<usize>().unwrap());
            assert!(fast.iter().all(|f| !f.is_empty()), "{engine} {die:?}");
            let differ: Vec<usize> = (0..fast.len()).filter(|&i| fast[i] != every[i]).collect();
            assert!(
                differ.is_empty(),
                "{engine} {die:?}: throws {differ:?} differ"
            );
        }
    }
}

/// The rotation that puts the face of direction `d` (+x, −x, +y, −y, +z, −z) on the floor.
fn face_down(d: usize) -> UnitQuaternion<f64> {
    let mut n = Vector3::zeros();
    n[d / 2] = if d.is_multiple_of(2) { 1.0 } else { -1.0 };
    UnitQuaternion::rotation_between(&n, &-Vector3::y()).unwrap_or_else(|| {
        UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI)
    })
}

/// A made die released at rest on any face stays on it, on both engines: after 1.5 s its
/// up direction is still that face's opposite within 5e-3 rad (Rapier's soft contact leaves
/// a rounded, weighted die leaning 3e-3 rad) and its centre of mass has
/// moved less than 0.2 mm (Rapier's die sinks about 0.07 mm into its contact, Bullet's
/// rounded die settles by up to 0.1 mm). For a weighted, rounded and drilled die whose principal frame is
/// turned off the body axes (the pips of 2 and 3 are diagonal).
#[test]
fn a_made_die_released_at_rest_on_a_face_stays_there() {
    let mut scene = Scene::paper("16x16x16".parse().unwrap(), Mode::ThreeD);
    scene.features = Features {
        com: Some([0.001, -0.0005, -0.002]),
        pips: Some(Pips {
            diameter: 0.003,
            depth: 0.001,
            shape: PipShape::Cap,
            fill_density: 0.0,
            spacing: 0.25,
        }),
        edge_radius: 0.0015,
        layout: Layout::Right,
        ..Default::default()
    };
    scene.validate(false).unwrap();
    let die = dicephys::model::die::DieBody::of(&scene);
    for kind in [EngineKind::Bullet, EngineKind::Rapier] {
        let mut engine = new_engine(kind, &scene).unwrap();
        for d in 0..6 {
            let rotation = face_down(d);
            let at_zero = BodyState {
                position: Vector3::zeros(),
                rotation,
                linear_velocity: Vector3::zeros(),
                angular_velocity: Vector3::zeros(),
                sleeping: false,
            };
            let start = BodyState {
                position: Vector3::new(0.0, -die.lowest_point(&at_zero), 0.0),
                ..at_zero
            };
            engine.reset(&start).unwrap();
            for _ in 0..1500 {
                engine.step().unwrap();
            }
            let end = engine.state();
            let up = up_in_body(&end.rotation);
            let mut want = Vector3::zeros();
            want[d / 2] = if d.is_multiple_of(2) { -1.0 } else { 1.0 };
            assert!(
                up.angle(&want) < 5e-3,
                "{kind:?} face {d}: up {up:?} (angle {})",
                up.angle(&want)
            );
            assert!(
                (end.position - start.position).norm() < 2e-4,
                "{kind:?} face {d}: moved {:?}",
                end.position - start.position
            );
        }
    }
}

/// A die file gives the same die as the flags (the same rolls: faces and steps, throw for
/// throw in total); the flags given beside it override it.
#[test]
fn a_die_file_is_the_flags() {
    let dir = Scratch::new("die-file");
    let file = dir.join("die.toml");
    std::fs::write(
        &file,
        "com = [0.0, 0.0, -1.5]\nedge_radius = 1.0\n[pips]\ndiameter = 3.0\ndepth = 1.0\n",
    )
    .unwrap();
    let base = [
        "roll", "--block", "16x16x16", "--throw", "tumble", "--rolls", "300", "--seed", "2",
        "--json",
    ];
    let flags = json(&dicephys(
        &[
            &base[..],
            &["--com", "0,0,-1.5", "--edge-radius", "1", "--pips", "3,1"],
        ]
        .concat(),
    ));
    let filed = json(&dicephys(
        &[&base[..], &["--die", file.to_str().unwrap()]].concat(),
    ));
    assert_eq!(flags["steps_total"], filed["steps_total"]);
    assert_eq!(flags["faces"], filed["faces"]);
    let overridden = json(&dicephys(
        &[
            &base[..],
            &["--die", file.to_str().unwrap(), "--com", "0,0,0"],
        ]
        .concat(),
    ));
    assert_ne!(overridden["steps_total"], filed["steps_total"]);
}

/// A die file's face map numbers the same rolls otherwise: a plain cube whose map swaps 1
/// and 2 (1 on +x, 2 on +z) shows as face 1 what the western die shows as 2, throw for throw;
/// `--layout` given beside it wins. An insert is a weight: a 4 mm tungsten cube 4 mm toward
/// face 6 (the centre 0.77 mm down) brings 1 up more often than 6 by more than 5σ on 3,000
/// throws (σ of the difference of the two shares √((p₁ + p₆)/n) ≈ 0.011 against about 0.08).
#[test]
fn a_die_files_face_map_and_insert_are_the_die() {
    let dir = Scratch::new("die-map");
    let map = dir.join("map.toml");
    std::fs::write(
        &map,
        "[faces]\n\"+x\" = 1\n\"-x\" = 5\n\"+y\" = 3\n\"-y\" = 4\n\"+z\" = 2\n\"-z\" = 6\n",
    )
    .unwrap();
    let base = [
        "roll", "--block", "16x16x16", "--throw", "tumble", "--rolls", "600", "--seed", "3",
        "--json",
    ];
    let right = json(&dicephys(&base));
    let mapped = json(&dicephys(
        &[&base[..], &["--die", map.to_str().unwrap()]].concat(),
    ));
    assert_eq!(right["steps_total"], mapped["steps_total"]);
    assert_eq!(right["faces"]["2"], mapped["faces"]["1"]);
    assert_eq!(right["faces"]["1"], mapped["faces"]["2"]);
    assert_eq!(right["faces"]["6"], mapped["faces"]["6"]);
    let flagged = json(&dicephys(
        &[
            &base[..],
            &["--die", map.to_str().unwrap(), "--layout", "right"],
        ]
        .concat(),
    ));
    assert_eq!(right["faces"], flagged["faces"]);

    let insert = dir.join("insert.toml");
    std::fs::write(
        &insert,
        "[insert]\nsize = [4.0, 4.0, 4.0]\ncentre = [0.0, 0.0, -4.0]\ndensity = 19300.0\n",
    )
    .unwrap();
    let v = json(&dicephys(&[
        "roll",
        "--block",
        "16x16x16",
        "--throw",
        "tumble",
        "--rolls",
        "3000",
        "--seed",
        "4",
        "--die",
        insert.to_str().unwrap(),
        "--json",
    ]));
    let f = faces(&v);
    let n: f64 = f.iter().sum();
    let (p1, p6) = (f[0] / n, f[5] / n);
    let sigma = ((p1 + p6) / n).sqrt();
    assert!(p1 - p6 > 5.0 * sigma, "p1 {p1:.4} p6 {p6:.4} σ {sigma:.4}");
}

/// Bad dice: one line on stderr naming what is wrong, exit 2, nothing on stdout.
#[test]
fn bad_dice_are_refused_in_one_line() {
    let dir = Scratch::new("bad-dice");
    let unknown = dir.join("unknown.toml");
    std::fs::write(&unknown, "com = [0.0, 0.0, 1.0]\nweight = 3\n").unwrap();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["--com", "0,0,9"], "--com"),
        (vec!["--com", "0,0"], "--com"),
        (vec!["--edge-radius", "8"], "--edge-radius"),
        (vec!["--edge-radius", "-1"], "--edge-radius"),
        (vec!["--pips", "4.5,1"], "overlap"),
        (vec!["--pips", "3,2"], "depth"),
        (vec!["--pips", "3,1", "--2d"], "3D"),
        (vec!["--die", unknown.to_str().unwrap()], "weight"),
        // Reliability round 5, class G: values printed as given, not as their rounding.
        (
            vec!["--edge-radius", "8.0000001"],
            "--edge-radius 8.0000001:",
        ),
        (vec!["--com", "1e308,0,0"], "--com 1e308,0,0:"),
        (
            vec!["--friction", "1e300"],
            "--friction 1e300: must be in [0, 10]",
        ),
        (
            vec!["--vary", "com_z=0:9:3"],
            "--vary com_z=9: must lie inside",
        ),
    ];
    let files = [
        (
            "twice.toml",
            "[faces]\n\"+x\" = 1\n\"-x\" = 1\n\"+y\" = 3\n\"-y\" = 4\n\"+z\" = 2\n\"-z\" = 6\n",
            "each number once",
        ),
        (
            "both.toml",
            "layout = \"left\"\n[faces]\n\"+x\" = 1\n",
            "not both",
        ),
        (
            "outside.toml",
            "[insert]\nsize = [4.0, 4.0, 4.0]\ncentre = [0.0, 0.0, -7.0]\ndensity = 19300.0\n",
            "insert.centre",
        ),
        (
            "insert-key.toml",
            "[insert]\nsize = [4.0, 4.0, 4.0]\ncentre = [0.0, 0.0, 0.0]\ndensity = 1.0\nmass = 2\n",
            "mass",
        ),
        (
            "inertia.toml",
            "inertia = [100.0, 100.0, 300.0, 0.0, 0.0, 0.0]\n",
            "inertia",
        ),
        // Reliability round 5, class E: moments no die of this mass and size can have.
        (
            "tiny-inertia.toml",
            "inertia = [1e-30, 1e-30, 1e-30, 0.0, 0.0, 0.0]\n",
            "no die of this mass and size",
        ),
        (
            "huge-inertia.toml",
            "inertia = [1e30, 1e30, 1e30, 0.0, 0.0, 0.0]\n",
            "no die of this mass and size",
        ),
        // Class G: a die file's values named by the file and its key, not as flags.
        (
            "com.toml",
            "com = [0.0, 0.0, 8.0]\n",
            "com.toml: com 0,0,8: must lie inside",
        ),
        (
            "density.toml",
            "density = 0\n",
            "density.toml: density 0: must be in",
        ),
        (
            "deep.toml",
            "[pips]\ndiameter = 3.0\ndepth = 9.0\n",
            "deep.toml: pips.depth 9:",
        ),
    ];
    let paths: Vec<String> = files
        .iter()
        .map(|(name, text, _)| {
            let p = dir.join(name);
            std::fs::write(&p, text).unwrap();
            p.to_str().unwrap().to_string()
        })
        .collect();
    let cases: Vec<(Vec<&str>, &str)> = cases
        .into_iter()
        .chain(
            paths
                .iter()
                .zip(&files)
                .map(|(p, f)| (vec!["--die", p.as_str()], f.2)),
        )
        .collect();
    for (extra, says) in cases {
        refused_in_one_line(&extra, says);
    }
}

/// A 16 mm cube with `extra` refused: exit 2, nothing on stdout, one line on stderr saying
/// `says` (`--vary` is `fair`'s, the rest `roll`'s).
fn refused_in_one_line(extra: &[&str], says: &str) {
    let command = if extra[0] == "--vary" { "fair" } else { "roll" };
    let args = [
        &[command, "--block", "16x16x16", "--rolls", "10", "--json"][..],
        extra,
    ]
    .concat();
    let out = dicephys(&args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{extra:?}: {err}");
    assert!(out.stdout.is_empty(), "{extra:?}");
    assert_eq!(err.trim_end().lines().count(), 1, "{extra:?}: {err}");
    assert!(err.contains(says), "{extra:?}: {err}");
}

/// Where is its weight? Face counts of a cube loaded 1 mm toward face 6 (6,000 throws in a
/// tumble, `roll --com 0,0,-1`) fitted with the centre of mass free on all three axes: each
/// parameter's 2σ profile interval holds its truth (x 0, y 0, z −1 mm), and z's excludes 0
/// (the weight is found). Then a small recovery check on z alone, three repetitions of fresh
/// counts and designs at fixed seeds: each fitted z within 0.3 mm of the truth (about 4σ:
/// their spread is about 0.07 mm), each truth inside its joint 2σ region.
/// The die found is predicted on another surface (`predict --contact`).
/// The coverage itself is measured at scale in docs/results/dice.md.
#[test]
fn a_fit_of_face_counts_finds_where_the_weight_sits() {
    let dir = Scratch::new("weight");
    let v = json(&dicephys(&[
        "roll", "--block", "16x16x16", "--throw", "tumble", "--com", "0,0,-1", "--rolls", "6000",
        "--seed", "5", "--json",
    ]));
    let f = faces(&v);
    let csv = dir.join("counts.csv");
    std::fs::write(
        &csv,
        format!(
            "label,surface,length_mm,breadth_mm,width_mm,mode,face_1,face_2,face_3,face_4,face_5,face_6\n\
             suspect,MDF,16,16,16,3d,{}\n",
            f.map(|c| c.to_string()).join(",")
        ),
    )
    .unwrap();
    let data = csv.to_str().unwrap();
    let out = dir.join("fit");
    let fit = json(&dicephys(&[
        "fit",
        "--data",
        data,
        "--free",
        "com_x,com_y,com_z",
        "--kappa",
        "0",
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]));
    let params = fit["estimate"]["params"].as_array().unwrap();
    for (p, truth) in params.iter().zip([0.0, 0.0, -1.0]) {
        let [lo, hi] = [0, 1].map(|i| p["two_sigma"][i].as_f64().unwrap());
        assert!(lo <= truth && truth <= hi, "{}: {lo}..{hi}", p["name"]);
    }
    assert!(
        params[2]["two_sigma"][1].as_f64().unwrap() < 0.0,
        "{}",
        params[2]
    );
    // The die found on MDF, predicted on felt (e 0.2, μ 0.6): each face, 1 still up more.
    let felt = json(&dicephys(&[
        "predict",
        "--fit",
        out.join("fit.json").to_str().unwrap(),
        "--block",
        "16x16x16",
        "--contact",
        "0.2,0.6",
        "--draws",
        "3",
        "--rolls",
        "1000",
        "--json",
    ]));
    assert_eq!(felt["surface"], "e 0.2, μ 0.6");
    let p = |k: usize| felt["faces"][k]["value"].as_f64().unwrap();
    assert!(p(0) > p(5), "{}", felt["faces"]);
    let rec = json(&dicephys(&[
        "fit",
        "--data",
        data,
        "--free",
        "com_z",
        "--kappa",
        "0",
        "--recover",
        "com_z=-1",
        "--repeats",
        "3",
        "--out",
        dir.join("rec").to_str().unwrap(),
        "--json",
    ]));
    for r in rec["repetitions"].as_array().unwrap() {
        let z = r["values"][0].as_f64().unwrap();
        assert!((z + 1.0).abs() < 0.3, "recovered com_z {z}");
        assert_eq!(r["covered"], true, "{r}");
    }
}

/// Reliability round 5, class D: a `--die` file is read through the capped reader and named:
/// missing, a directory, not text, endless (/dev/zero) or a pipe no one writes to.
#[test]
fn a_die_file_is_read_capped_and_named() {
    let d = scratch("die-read");
    let refused = |die: &std::path::Path, says: &str| {
        let o = bin()
            .args(["roll", "--rolls", "1", "--block", "16x16x16", "--die"])
            .arg(die)
            .output()
            .unwrap();
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{}: {e}", die.display());
        assert_eq!(e.trim_end().lines().count(), 1, "{e}");
        assert!(
            e.contains("--die") && e.contains(says),
            "{}: {e}",
            die.display()
        );
    };
    refused(&d.join("missing.toml"), "No such file");
    refused(&d, "directory");
    std::fs::write(d.join("binary.toml"), [0xff, 0xfe, 0x00, 0x80]).unwrap();
    refused(&d.join("binary.toml"), "not a text file");
    refused(Path::new("/dev/zero"), "larger than 1 MiB");
    // A named pipe with no writer: SIGTERM ends the wait (exit 130).
    let fifo = d.join("die.toml");
    let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    let mut child = bin()
        .args(["roll", "--block", "16x16x16", "--die"])
        .arg(&fifo)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(500));
    unsafe { libc::kill(child.id() as i32, libc::SIGTERM) };
    let status = exit_within(&mut child, 5, "a --die pipe held off SIGTERM");
    assert_eq!(status.code(), Some(130));
}

/// Issue 72: a 3D-printed die, `--shell WALL,INFILL`. The designed die V1 (tests/data) at 24 mm
/// with a 1 mm wall and a fifth infill rolls on Bullet, every roll counted on one of its
/// faces; its specification carries the shell (m and a fraction); and a wall as thick as the
/// die, or an infill past 1, is refused naming the flag, in one line.
#[test]
fn a_printed_die_with_a_shell_rolls_on_bullet() {
    let v1 = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/hendecahedron_v1.obj"
    );
    let roll = |shell: &str| {
        dicephys(&[
            "roll",
            "--die",
            v1,
            "--scale",
            "14.821972",
            "--shell",
            shell,
            "--rolls",
            "50",
            "--seed",
            "3",
            "--threads",
            "1",
            "--engine",
            "bullet",
            "--json",
        ])
    };
    let v = json(&roll("1,0.2"));
    let shell = &v["spec"]["scene"]["features"]["shell"];
    assert_eq!(shell["infill"], 0.2, "{shell}");
    assert!(
        (shell["wall"].as_f64().unwrap() - 0.001).abs() < 1e-15,
        "{shell}"
    );
    let counted: u64 = v["shape"]["faces"]
        .as_array()
        .expect("the die's faces")
        .iter()
        .map(|f| f["count"].as_u64().unwrap())
        .sum();
    assert_eq!(counted, 50, "{}", v["shape"]);
    crate::helpers::refused(&roll("9,0.2"), 2, "--shell wall 9");
    crate::helpers::refused(&roll("1,1.5"), 2, "--shell infill 1.5");
    let o = dicephys(&[
        "roll", "--block", "16x16x16", "--shell", "1,0.2", "--pips", "3,1.2", "--rolls", "1",
    ]);
    crate::helpers::refused(&o, 2, "deeper than the shell's wall");
    // A fit's free infill fills the die's wall, or a 1 mm one: too thick for a 1.5 mm die,
    // it is refused naming --free, not a --shell the user never gave; and beside a free
    // centre of mass, which it would only move.
    let dir = Scratch::new("printed-fit");
    let csv = dir.join("tiny.csv");
    std::fs::write(
        &csv,
        "label,surface,length_mm,breadth_mm,width_mm,mode,face_1,face_2,face_3,face_4,face_5,\
         face_6\nd,MDF,1.5,1.5,1.5,3d,30,25,25,25,25,20\n",
    )
    .unwrap();
    let fit = |free: &str| {
        dicephys(&[
            "fit",
            "--data",
            csv.to_str().unwrap(),
            "--kappa",
            "0",
            "--free",
            free,
        ])
    };
    crate::helpers::refused(
        &fit("infill"),
        2,
        "--free infill: fills the die's shell wall, 1 mm",
    );
    crate::helpers::refused(&fit("infill,com_z"), 2, "cannot be told apart");
}
