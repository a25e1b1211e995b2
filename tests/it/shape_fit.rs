//! `fit` and `predict` of a die of any shape: counts by `face_<label>`, a loaded d20's centre
//! of mass recovered from its simulated faces (with the coverage its 2σ region states), its
//! prediction beside a fresh roll at the truth, what cannot be fitted refused in one line, and
//! a Ctrl-C in the likelihood ratio's scale honoured at once.

use super::helpers::{bin, dicephys, interrupt_after, json, Scratch};

/// The d20's labels in its faces' order, as `roll --json` gives them.
fn d20_labels() -> Vec<String> {
    let v = json(&dicephys(&[
        "roll", "--shape", "d20", "--rolls", "1", "--json",
    ]));
    v["shape"]["faces"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["label"].as_str().unwrap().to_string())
        .collect()
}

/// A counts file of one row on felt: `counts` by label, written in reverse order (the fit reads
/// columns by label, not by place).
fn counts_file(dir: &Scratch, labels: &[String], counts: &[u64]) -> String {
    let path = dir.join("d20.csv");
    let head: Vec<String> = labels.iter().rev().map(|l| format!("face_{l}")).collect();
    let row: Vec<String> = counts.iter().rev().map(u64::to_string).collect();
    std::fs::write(
        &path,
        format!(
            "label,surface,{}\nloaded,felt,{}\n",
            head.join(","),
            row.join(",")
        ),
    )
    .unwrap();
    path.display().to_string()
}

/// The fit's small, coarse design (as the block recovery's in `fit.rs`): a degree-2 surrogate
/// over the centre of mass's three components, 24 points × 200 rolls, two passes, dt = 1/250.
const SMALL: [&str; 12] = [
    "--shape",
    "d20",
    "--free",
    "com_x,com_y,com_z",
    "--points",
    "24",
    "--degree",
    "2",
    "--max-degree",
    "2",
    "--rolls",
    "200",
];

#[test]
fn a_loaded_d20s_centre_of_mass_is_recovered_from_its_faces_with_the_stated_coverage() {
    // 6 fixed-seed repetitions: 4,000 throws of a d20 whose centre of mass is 0.5, −0.3,
    // −1.0 mm off centre, counted by face and fitted back with their own simulations. The joint
    // 2σ region is stated to hold the truth 95.45 % of the time: the test asks 5 of 6 (below 5
    // has probability 2.7 % if the statement is true; a region that held it 70 % of the time
    // fails 58 % of the time). Measured at 10 repetitions: 10 of 10, the truth's Δ(−2 ln L)
    // averaging 3.9 (χ²₃'s mean is 3); each component's 2σ interval 9 of 10. It was 10 (8 of
    // 10: 0.9 % and 62 %), the suite's longest test: 6 keep its power. The mean of 6 Δ is
    // 3 ± 1 where the statement holds: below 6 is 3σ.
    let dir = Scratch::new("shape-fit-recover");
    let labels = d20_labels();
    let csv = counts_file(&dir, &labels, &[200; 20]);
    let out = dicephys(
        &[
            &["fit", "--data", &csv][..],
            &SMALL,
            &[
                "--dt",
                "1/250",
                "--recover",
                "com_x=0.5,com_y=-0.3,com_z=-1",
                "--repeats",
                "6",
                "--seed",
                "11",
                "--out",
                dir.to_str().unwrap(),
                "--json",
            ],
        ]
        .concat(),
    );
    let r = json(&out);
    let reps = r["repetitions"].as_array().unwrap();
    assert_eq!(reps.len(), 6);
    let covered = reps.iter().filter(|x| x["covered"] == true).count();
    assert!(covered >= 5, "{covered} of 6 covered: {r}");
    let mean: f64 = reps
        .iter()
        .map(|x| x["truth_delta"].as_f64().unwrap())
        .sum::<f64>()
        / 6.0;
    assert!(mean < 6.0, "the truth's mean Δ {mean}");
    assert_eq!(r["names"][2], "com_z[die]");
}

#[test]
fn a_fitted_d20_predicts_its_faces_as_a_fresh_roll_at_the_fitted_centre_gives_them() {
    // 6,000 throws at a centre of mass 0, 0, −1.5 mm (faces near +z come up about twice as
    // often as those near −z), fitted, then predicted at 8 posterior draws × 1,500 rolls;
    // beside 12,000 fresh throws at the fitted centre of mass (another seed), every face within
    // 4 combined standard errors, and the faces' χ² on 19 below its 0.1 % point (43.8). (How
    // near the fitted centre comes to the truth is the recovery's test, above.) Every roll at
    // dt = 1/250, as the recovery's: the prediction and the fresh roll share the step, and the
    // test took 84 s at dt = 1/1000, the suite's third-longest.
    let dir = Scratch::new("shape-fit-predict");
    let labels = d20_labels();
    let roll_at = |com: &str, seed: &str, rolls: &str| {
        let v = json(&dicephys(&[
            "roll", "--shape", "d20", "--com", com, "--rolls", rolls, "--seed", seed, "--dt",
            "1/250", "--json",
        ]));
        let f = v["shape"]["faces"].as_array().unwrap().clone();
        let got: Vec<String> = f
            .iter()
            .map(|x| x["label"].as_str().unwrap().to_string())
            .collect();
        assert_eq!(got, labels);
        f.iter()
            .map(|x| x["count"].as_u64().unwrap())
            .collect::<Vec<u64>>()
    };
    let csv = counts_file(&dir, &labels, &roll_at("0,0,-1.5", "3", "6000"));
    let out = dir.join("fit");
    let o = dicephys(
        &[
            &["fit", "--data", &csv][..],
            &SMALL,
            &[
                "--dt",
                "1/250",
                "--seed",
                "5",
                "--out",
                out.to_str().unwrap(),
                "--json",
            ],
        ]
        .concat(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let fit = json(&o);
    let params = fit["estimate"]["params"].as_array().unwrap();
    let fitted: Vec<String> = params
        .iter()
        .map(|p| p["value"].as_f64().unwrap().to_string())
        .collect();
    assert_eq!(params[2]["name"], "com_z[die]");
    let fit_json = out.join("fit.json");
    let p = json(&dicephys(&[
        "predict",
        "--fit",
        fit_json.to_str().unwrap(),
        "--draws",
        "8",
        "--rolls",
        "1500",
        "--json",
    ]));
    assert_eq!(p["shape"], "d20");
    let got: Vec<String> = p["labels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l.as_str().unwrap().to_string())
        .collect();
    assert_eq!(got, labels);
    assert!(p.get("ratio").is_none() && p["p"].as_array().unwrap().is_empty());
    let fresh = roll_at(&fitted.join(","), "4", "12000");
    let n: u64 = fresh.iter().sum();
    let mut chi2 = 0.0;
    for (k, f) in p["faces"].as_array().unwrap().iter().enumerate() {
        let (v, e) = (f["value"].as_f64().unwrap(), f["err"].as_f64().unwrap());
        let q = fresh[k] as f64 / n as f64;
        let z = (q - v) / (e * e + q * (1.0 - q) / n as f64).sqrt();
        assert!(z.abs() < 4.0, "face {}: {q} against {v} ± {e}", labels[k]);
        chi2 += z * z;
    }
    assert!(chi2 < 43.8, "χ² {chi2} on 19");
    // Issue 71.2: a block (or another die) from the d20's fit is another die thrown by the
    // same hand on the same table; the fitted d20's centre of mass is not carried to it, so a
    // cube comes out fair (each side within 4σ of 1/3).
    let p = json(&dicephys(&[
        "predict",
        "--fit",
        fit_json.to_str().unwrap(),
        "--block",
        "16x16x16",
        "--draws",
        "4",
        "--rolls",
        "1500",
        "--json",
    ]));
    assert_eq!(p["other_die"], "the block 16x16x16");
    for side in p["p"].as_array().unwrap() {
        let (v, e) = (
            side["value"].as_f64().unwrap(),
            side["err"].as_f64().unwrap(),
        );
        assert!((v - 1.0 / 3.0).abs() < 4.0 * e.max(0.006), "{side}");
    }
}

#[test]
fn another_die_from_a_calibration_is_scored_against_its_counts_beside_the_baselines() {
    // A d4 fitted (its centre of mass free) on a tumble; a d6 predicted from it and held
    // against 600 throws of a fresh fair d6 roll (seed 7): the prediction's and the default
    // scene's log scores within a few nats of each other (both near fair), the quasi-static
    // theory's (exactly 1/6 each) given, and every score's parts present.
    let dir = Scratch::new("shape-fit-other-die");
    let d4 = dir.join("d4.csv");
    std::fs::write(
        &d4,
        "label,surface,face_1,face_2,face_3,face_4\nd,MDF,60,60,60,60\n",
    )
    .unwrap();
    let out = dir.join("fit");
    json(&dicephys(&[
        "fit",
        "--data",
        d4.to_str().unwrap(),
        "--shape",
        "d4",
        "--free",
        "com_z",
        "--points",
        "8",
        "--point-rolls",
        "100",
        "--degree",
        "1",
        "--no-refine",
        "--dt",
        "1/250",
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]));
    let fresh = json(&dicephys(&[
        "roll", "--shape", "d6", "--rolls", "600", "--seed", "7", "--json",
    ]));
    let faces = fresh["shape"]["faces"].as_array().unwrap();
    let header: Vec<String> = faces
        .iter()
        .map(|f| format!("face_{}", f["label"].as_str().unwrap()))
        .collect();
    let counts: Vec<String> = faces.iter().map(|f| f["count"].to_string()).collect();
    let d6 = dir.join("d6.csv");
    std::fs::write(
        &d6,
        format!(
            "label,surface,{}\nfresh,MDF,{}\n",
            header.join(","),
            counts.join(",")
        ),
    )
    .unwrap();
    let p = json(&dicephys(&[
        "predict",
        "--fit",
        out.join("fit.json").to_str().unwrap(),
        "--shape",
        "d6",
        "--counts",
        d6.to_str().unwrap(),
        "--draws",
        "4",
        "--rolls",
        "500",
        "--json",
    ]));
    assert_eq!(p["other_die"], "d6");
    let s = &p["tests"][0]["scores"];
    for kind in ["prediction", "default_scene", "quasi_static"] {
        for key in ["log_score", "chi2", "sharpness", "within_two_sigma"] {
            assert!(s[kind][key].is_number(), "{kind}.{key}: {s}");
        }
    }
    assert_eq!(s["prediction"]["dof"], 5);
    let (pred, base) = (
        s["prediction"]["log_score"].as_f64().unwrap(),
        s["default_scene"]["log_score"].as_f64().unwrap(),
    );
    assert!((pred - base).abs() < 5.0, "{pred} {base}");
}

#[test]
fn a_fit_of_blocks_refuses_to_predict_a_die_of_any_shape_in_one_line() {
    // The paper's or a hand's throw spins a die about its long axis; a d6 shape has none.
    let dir = Scratch::new("shape-fit-blocks-refuse");
    let blocks = dir.join("blocks.csv");
    std::fs::write(
        &blocks,
        "label,surface,length_mm,breadth_mm,width_mm,mode,length_vertical,breadth_vertical,\
         width_vertical\na,MDF,140,24,20,3d,5,200,400\nb,MDF,100,43.9,43.2,3d,10,300,290\n",
    )
    .unwrap();
    let bout = dir.join("bfit");
    json(&dicephys(&[
        "fit",
        "--data",
        blocks.to_str().unwrap(),
        "--free",
        "e",
        "--points",
        "6",
        "--point-rolls",
        "60",
        "--degree",
        "1",
        "--no-refine",
        "--dt",
        "1/250",
        "--out",
        bout.to_str().unwrap(),
        "--json",
    ]));
    let o = dicephys(&[
        "predict",
        "--fit",
        bout.join("fit.json").to_str().unwrap(),
        "--shape",
        "d6",
    ]);
    let e = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(
        e.contains("a fit of blocks predicts blocks") && e.lines().count() == 1,
        "{e}"
    );
}

#[test]
fn what_a_shapes_fit_cannot_read_is_refused_in_one_line() {
    let dir = Scratch::new("shape-fit-bad");
    let labels = d20_labels();
    let csv = counts_file(&dir, &labels, &[10; 20]);
    let sides = dir.join("sides.csv");
    std::fs::write(
        &sides,
        "label,surface,length_mm,breadth_mm,width_mm,mode,length_vertical,breadth_vertical,width_vertical\na,felt,16,16,16,3d,1,2,3\n",
    )
    .unwrap();
    let coin = dir.join("coin.csv");
    std::fs::write(&coin, "label,surface,face_heads,face_tails\nc,felt,10,10\n").unwrap();
    let cases: [(Vec<&str>, &[&str]); 5] = [
        // Labelled counts without the die they count.
        (
            vec!["fit", "--data", &csv, "--free", "e"],
            &["counts the faces of a die of any shape", "--shape"],
        ),
        // A die of any shape counted by a block's sides.
        (
            vec!["fit", "--data", sides.to_str().unwrap(), "--shape", "d20"],
            &["--data", "d20 is counted by its faces"],
        ),
        // Faces that are not the die's.
        (
            vec![
                "fit",
                "--data",
                coin.to_str().unwrap(),
                "--shape",
                "coin:24,8",
            ],
            &["--data", "missing face_edge"],
        ),
        // No hand for a die without a long axis.
        (
            vec!["fit", "--data", &csv, "--shape", "d20", "--free", "e,kappa"],
            &["--free kappa", "tumble"],
        ),
        (
            vec!["fit", "--data", &csv, "--shape", "d20", "--kappa", "30"],
            &["--kappa 30", "tumble"],
        ),
    ];
    for (args, says) in cases {
        let o = dicephys(&args);
        let e = String::from_utf8_lossy(&o.stderr).into_owned();
        assert_eq!(o.status.code(), Some(2), "{args:?}: {e}");
        assert_eq!(e.trim_end().lines().count(), 1, "{args:?}: {e}");
        for s in says {
            assert!(e.contains(s), "{args:?}: wanted '{s}' in {e}");
        }
    }
}

#[test]
fn a_fit_simulates_a_die_of_any_shape_as_roll_does_throw_for_throw() {
    // The fit's design and `predict` roll through `Method::spec`; `roll` through the command
    // line's scene. On the same keyed throws the two give the same faces, roll for roll.
    use dicephys::calibration::params::{Fixed, FixedThrow, Method};
    use dicephys::run::runner::Runner;
    use dicephys::run::stop::Stop;
    let shape = dicephys::model::shape::named("d20", None).unwrap();
    let [x, y, z] = shape.bounding_box();
    let block = dicephys::model::block::Block {
        breadth: x,
        width: y,
        length: z,
    };
    let method = Method {
        engine: dicephys::engine::EngineKind::Bullet,
        dt: 1e-3,
        max_steps: dicephys::sim::roll::DEFAULT_MAX_STEPS,
        die: dicephys::model::die::Die {
            shape: Some(std::sync::Arc::new(shape)),
            ..Default::default()
        },
        dice: Vec::new(),
    };
    let values = Fixed {
        throw: FixedThrow::Tumble,
        com: [Some(0.5), Some(-0.3), Some(-1.5)],
        ..Fixed::default()
    };
    let spec = method.spec(block, dicephys::model::scene::Mode::ThreeD, &values, 3, 600);
    spec.validate(false).unwrap();
    let done = Runner::new(2, Stop::new())
        .run(&spec, None, &mut |_| Ok(()))
        .unwrap();
    let v = json(&dicephys(&[
        "roll",
        "--shape",
        "d20",
        "--com",
        "0.5,-0.3,-1.5",
        "--rolls",
        "600",
        "--seed",
        "3",
        "--json",
    ]));
    let cli: Vec<u64> = v["shape"]["faces"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["count"].as_u64().unwrap())
        .collect();
    let mut fit = done.tally.faces.clone();
    fit.resize(20, 0);
    assert_eq!(fit, cli);
}

/// Issue 69.11: a Ctrl-C in the likelihood ratio's scale (the bootstrap: 200 data sets, each a
/// d20's surrogate fitted again, then a search) ends the fit at once, exit 130 and no
/// fit.json. Before, every set left after the stop still fitted its surrogate again: at this
/// design's degree 3 (380 coefficients) 3.1–6.0 s to end, where it now ends within a Newton
/// step (12–15 ms; at the default design, degree 2, 1.6–2.5 s before and 4–36 ms after). The
/// signal follows the stage's own line, so the run is long by construction; the bound, 1 s,
/// is the promise, 60 times what it takes here and a third of what it took. That the
/// same command then finishes is `fit.rs`'s `ctrl_c_in_the_estimate_stops_a_fit_at_once_and_it_resumes`.
#[test]
fn ctrl_c_in_the_likelihood_ratios_scale_ends_a_d20_fit_at_once() {
    use std::process::Stdio;
    let dir = Scratch::new("shape-fit-stop");
    let csv = dir.join("d20.csv");
    let head: Vec<String> = (1..=20).map(|k| format!("face_{k}")).collect();
    // The guide's suspect d20 (docs/guide.md, a fit of a die of any shape).
    std::fs::write(
        &csv,
        format!(
            "label,surface,{}\nsuspect d20,MDF,427,505,361,457,411,296,356,275,232,365,250,\
             323,246,202,238,231,193,244,195,193\n",
            head.join(",")
        ),
    )
    .unwrap();
    let out = dir.join("out");
    let child = bin()
        .args(["fit", "--data", csv.to_str().unwrap(), "--shape", "d20"])
        .args([
            "--free",
            "com_x,com_y,com_z",
            "--points",
            "40",
            "--rolls",
            "100",
        ])
        .args([
            "--degree",
            "3",
            "--max-degree",
            "3",
            "--dt",
            "1/250",
            "--out",
        ])
        .arg(&out)
        .env("DICEPHYS_PROGRESS_SECS", "0")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let (code, seen, waited) = interrupt_after(child, "fit: the likelihood ratio's scale");
    assert_eq!(code, Some(130), "{seen}");
    assert!(
        waited < std::time::Duration::from_secs(1),
        "stopped after {waited:?}"
    );
    assert!(!out.join("fit.json").exists());
}

#[test]
fn a_fits_step_cap_left_at_its_default_is_the_dies_as_rolls_is() {
    // `roll` caps a die of any shape at 200,000 steps unless asked (`roll::default_max_steps`);
    // a fit of one took DicePhys's 20,000,000, so a rounded die rocking for ever was simulated
    // for 20,000 s a roll. Now a fit takes the die's cap too; a block's stays DicePhys's and a
    // cap given is kept.
    use dicephys::calibration::data;
    use dicephys::calibration::request::FitRequest;
    use dicephys::sim::roll::{DEFAULT_MAX_STEPS, SHAPE_MAX_STEPS};
    let labels = d20_labels();
    let d20 = format!(
        "label,surface,{}\nd,felt,{}\n",
        labels
            .iter()
            .map(|l| format!("face_{l}"))
            .collect::<Vec<_>>()
            .join(","),
        vec!["10"; 20].join(",")
    );
    let cap = |rows: &str, shape: Option<&str>, asked: u64| {
        let req = FitRequest {
            rows: data::parse(rows, "counts.csv").unwrap(),
            max_steps: asked,
            die: dicephys::run::request::DieRequest {
                shape: shape.map(String::from),
                ..Default::default()
            },
            ..FitRequest::default()
        };
        req.config().unwrap().method.max_steps
    };
    assert_eq!(cap(&d20, Some("d20"), DEFAULT_MAX_STEPS), SHAPE_MAX_STEPS);
    assert_eq!(cap(&d20, Some("d20"), 5_000), 5_000);
    let block = "label,surface,length_mm,breadth_mm,width_mm,mode,length_vertical,\
                 breadth_vertical,width_vertical\na,felt,140,24,20,3d,0,200,400\n";
    assert_eq!(cap(block, None, DEFAULT_MAX_STEPS), DEFAULT_MAX_STEPS);
}
