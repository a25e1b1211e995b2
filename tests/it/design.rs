//! `dicephys design` (issue 73, its first part): the value of one feature of a die that gives
//! the target's probabilities, found by rolling and checked at a fresh seed; the same at any
//! thread count; an unreachable target answered, not refused; bad targets refused in one line.
//! A named target (`2d6`, `binomial:N`) set over a die's labels, a fit's calibration as the
//! scene (`--fit`), and `--out`'s files and figure.

use super::helpers::{dicephys, json, refused, stderr, Scratch};

/// `design` of a 16 mm cube's centre of mass along z for `target`, with `extra`, as JSON.
fn loaded_d6(target: &str, extra: &[&str]) -> serde_json::Value {
    let mut a = vec![
        "design",
        "--block",
        "16x16x16",
        "--free",
        "com_z",
        "--range",
        "com_z=-3:0",
        "--target",
        target,
        "--seed",
        "1",
    ];
    a.extend(extra);
    a.push("--json");
    json(&dicephys(&a))
}

/// A d6 whose 1 comes up one time in four: its centre of mass moved towards the 6 (−z, the
/// 1 being on +z). At seed 1 the design is −1.33 mm (95 %: −1.49 to −1.25), and 20,000
/// fresh throws give P(1) 0.2455 ± 0.0030. The check's share must lie within 0.02 of 1/4:
/// its own 4σ (0.012) and the reach of the design's interval (P(1) moves 0.09 a mm, the
/// interval's half-width 0.12 mm: 0.011). The same design on one thread and on two.
#[test]
fn a_loaded_d6_is_designed_to_its_target_and_checked_at_a_fresh_seed() {
    let one = loaded_d6("1=1/4,rest=3/4", &["--threads", "1"]);
    let v = one["value"].as_f64().unwrap();
    let [a, b] = [0, 1].map(|k| one["interval"][k].as_f64().unwrap());
    assert!(a <= v && v <= b, "{v} in [{a}, {b}]");
    assert!(
        (-2.0..-0.8).contains(&v),
        "the weight towards the 6: {v} mm"
    );
    assert_eq!(one["outcomes"], serde_json::json!(["1", "rest"]));
    let p = one["check"]["p"][0].as_f64().unwrap();
    assert!((p - 0.25).abs() < 0.02, "the check's P(1) {p}");
    assert_eq!(one["reachable"], true);
    assert!(
        one["check"]["seed"] != one["scans"][0]["seed"]
            && one["check"]["seed"] != one["scans"][1]["seed"],
        "the check's throws are fresh"
    );
    // Its quasi-static share, beside: the same weight, released at rest.
    let qs = one["quasi_static"][0].as_f64().unwrap();
    assert!(qs > 1.0 / 6.0 && qs < 0.25, "{qs}");
    let two = loaded_d6("1=1/4,rest=3/4", &["--threads", "2"]);
    assert_eq!(one["value"], two["value"]);
    assert_eq!(one["check"], two["check"]);
}

/// P(1) = 0.9 is beyond any centre of mass within 3 mm (at −3 mm it is about 0.42): the
/// answer says so, exit 0, with the closest design, near the range's end.
#[test]
fn an_unreachable_target_is_an_answer_with_the_closest_design() {
    let v = loaded_d6(
        "1=0.9,rest=0.1",
        &["--rolls", "300", "--check-rolls", "1000", "--threads", "1"],
    );
    assert_eq!(v["reachable"], false, "{v}");
    let verdict = v["verdict"].as_str().unwrap();
    assert!(
        verdict.starts_with("unreachable in this family: the closest design is com_z = "),
        "{verdict}"
    );
    assert!(v["value"].as_f64().unwrap() < -2.5, "{}", v["value"]);
}

/// The three-way coin, coarsely (5 values × 150 throws a scan, 600 to check): its thickness
/// within 8.5–12 mm of a 24 mm coin (the default tumble's, measured by hand at 10.2–10.4 mm,
/// docs/results/shapes.md; the quasi-static theory's 8.5).
#[test]
fn a_three_way_coins_thickness_is_found_in_a_coarse_design() {
    let v = json(&dicephys(&[
        "design",
        "--shape",
        "coin:24,10",
        "--free",
        "thickness",
        "--range",
        "thickness=6:14",
        "--target",
        "heads=1/3,tails=1/3,edge=1/3",
        "--rolls",
        "150",
        "--points",
        "5",
        "--check-rolls",
        "600",
        "--threads",
        "1",
        "--seed",
        "1",
        "--json",
    ]));
    let h = v["value"].as_f64().unwrap();
    assert!((8.5..12.0).contains(&h), "{h} mm");
    assert_eq!(v["scans"].as_array().unwrap().len(), 2);
    assert_eq!(v["check"]["n"], 600);
}

#[test]
fn what_a_design_cannot_be_is_refused_in_one_line() {
    let coin = ["--shape", "coin:24,10", "--free", "thickness"];
    for (extra, says) in [
        (
            vec![
                "--range",
                "thickness=6:14",
                "--target",
                "heads=0.5,tails=0.6",
            ],
            "sum to 1.100000, not 1",
        ),
        (
            vec!["--range", "thickness=6:14", "--target", "top=1/2,rest=1/2"],
            "the die has no face top",
        ),
        (
            vec![
                "--range",
                "thickness=6:14",
                "--target",
                "heads=1/2,tails=1/2",
            ],
            "the target leaves out edge",
        ),
        (
            vec!["--range", "com_z=6:14", "--target", "heads=1/2,rest=1/2"],
            "the range is --free's, thickness",
        ),
        (
            vec![
                "--range",
                "thickness=14:6",
                "--target",
                "heads=1/2,rest=1/2",
            ],
            "LO < HI",
        ),
        (
            vec!["--range", "thickness=6:14", "--target", "uniform"],
            "give each label's probability",
        ),
    ] {
        let mut a = vec!["design"];
        a.extend(coin);
        a.extend(extra);
        refused(&dicephys(&a), 2, says);
    }
    // A feature the die has not.
    refused(
        &dicephys(&[
            "design",
            "--block",
            "16x16x16",
            "--free",
            "thickness",
            "--range",
            "thickness=6:14",
            "--target",
            "1=1/2,rest=1/2",
        ]),
        2,
        "the die is not a coin",
    );
}

/// The 2d6 hendecahedron V1 (tests/data) as docs/results/real-dice/v1.toml labels it, each
/// mirror pair one class (2|12 … 6|8, 7 alone): its die file, written into `dir`.
pub fn v1_classes(dir: &Scratch) -> String {
    let classes = [
        ([0.0, 0.149676, -0.988735], "7"),
        ([-0.0, -0.73689, 0.676013], "6|8"),
        ([0.0, 0.830748, 0.556648], "6|8"),
        ([-0.693193, -0.69034, -0.207157], "5|9"),
        ([0.693193, -0.69034, -0.207157], "5|9"),
        ([-0.729108, 0.675868, -0.107723], "4|10"),
        ([0.729108, 0.675868, -0.107723], "4|10"),
        ([-0.989859, 0.078844, 0.118164], "3|11"),
        ([0.989859, 0.078844, 0.118164], "3|11"),
        ([0.571414, 0.023049, 0.820338], "2|12"),
        ([-0.571414, 0.023049, 0.820338], "2|12"),
    ];
    v1_labelled(dir, "v1.toml", &classes)
}

/// V1 (tests/data) at 24 mm, read down, its resting facets labelled by `labels` (outward
/// normal, label): a die file `name` written into `dir`.
fn v1_labelled(dir: &Scratch, name: &str, labels: &[([f64; 3], &str)]) -> String {
    let labels: Vec<String> = labels
        .iter()
        .map(|(n, l)| {
            format!(
                "  {{ normal = [{}, {}, {}], label = \"{l}\" }},",
                n[0], n[1], n[2]
            )
        })
        .collect();
    let path = dir.join(name);
    std::fs::write(
        &path,
        format!(
            "mesh = \"{}/tests/data/hendecahedron_v1.obj\"\nscale = 14.821972\nreads = \"down\"\n\
             labels = [\n{}\n]\n",
            env!("CARGO_MANIFEST_DIR"),
            labels.join("\n")
        ),
    )
    .unwrap();
    path.display().to_string()
}

/// A fit of a 16 mm cube's faces on felt (1,000 throws, near fair), its μ free and e held at
/// 0.9 (far from the default scene's 0.5), one small pass at dt = 1/250: its fit.json.
pub fn cube_fit(dir: &Scratch) -> String {
    cube_fit_with(dir, &[])
}

/// `cube_fit` with `extra` flags (`--throw tumble`).
fn cube_fit_with(dir: &Scratch, extra: &[&str]) -> String {
    let csv = dir.join("cube.csv");
    std::fs::write(
        &csv,
        "label,surface,length_mm,breadth_mm,width_mm,mode,face_1,face_2,face_3,face_4,face_5,\
         face_6\nd,felt,16,16,16,3d,170,160,170,165,170,165\n",
    )
    .unwrap();
    let out = dir.join("fit");
    json(&dicephys(
        &[
            "fit",
            "--data",
            csv.to_str().unwrap(),
            "--free",
            "mu",
            "--restitution",
            "0.9",
            "--points",
            "6",
            "--rolls",
            "100",
            "--degree",
            "1",
            "--no-refine",
            "--dt",
            "1/250",
            "--seed",
            "1",
            "--threads",
            "1",
            "--out",
            out.to_str().unwrap(),
            "--json",
        ]
        .iter()
        .chain(extra)
        .copied()
        .collect::<Vec<_>>(),
    ));
    out.join("fit.json").display().to_string()
}

/// `--target 2d6` on V1 labelled by class: the target is 2d6's law gathered by class (6|8:
/// 10/36), the outcomes the die's labels. V1 thrown misses its own design (issue 73: 3|11
/// 0.054 against 0.111 at 20,000 throws), and moving its centre of mass along z by up to 1 mm
/// does not mend that: the check's P(3|11) must lie more than 4 binomial σ (about 0.03 at
/// 1,000 throws) below 1/9; measured at seed 1, 0.056 ± 0.007. With --out, the document, the
/// report and the figure are written beside each other.
#[test]
fn a_named_target_is_set_over_the_dies_labels_each_class_gathered() {
    let dir = Scratch::new("design-2d6");
    let die = v1_classes(&dir);
    let out = dir.join("out");
    let v = json(&dicephys(&[
        "design",
        "--die",
        &die,
        "--free",
        "com_z",
        "--range",
        "com_z=-1:1",
        "--target",
        "2d6",
        "--rolls",
        "200",
        "--points",
        "5",
        "--check-rolls",
        "1000",
        "--seed",
        "1",
        "--threads",
        "2",
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]));
    assert_eq!(v["config"]["named_target"], "2d6");
    let want = |label: &str| -> f64 {
        label
            .split('|')
            .map(|s| {
                let s: f64 = s.parse().unwrap();
                (6.0 - (s - 7.0).abs()) / 36.0
            })
            .sum()
    };
    let target = v["config"]["target"].as_array().unwrap();
    assert_eq!(target.len(), 6, "{target:?}");
    for (k, t) in target.iter().enumerate() {
        let label = t[0].as_str().unwrap();
        assert_eq!(v["outcomes"][k], label);
        assert!((t[1].as_f64().unwrap() - want(label)).abs() < 1e-12, "{t}");
    }
    let k = target.iter().position(|t| t[0] == "3|11").unwrap();
    let (p, err) = (
        v["check"]["p"][k].as_f64().unwrap(),
        v["check"]["err"][k].as_f64().unwrap(),
    );
    assert_eq!(v["check"]["n"], 1000);
    assert!(p < 1.0 / 9.0 - 4.0 * err, "P(3|11) {p} ± {err}");
    // --out: the same document, the report and the figure beside it.
    let written: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("design.json")).unwrap()).unwrap();
    assert_eq!(written, v);
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(
        report.contains("target: 2d6") && report.contains("design.svg"),
        "{report}"
    );
    let svg = std::fs::read_to_string(out.join("design.svg")).unwrap();
    assert!(
        svg.contains("3|11") && svg.contains("target"),
        "the figure names its outcomes"
    );
    assert!(out.join("design.png").is_file());
}

/// `--fit`: the design is made in the fit's calibrated scene and throw (its e held at 0.9, its
/// μ fitted, its paper throw and dt = 1/250), with the design's own die, and says so in its
/// JSON and its text. The loaded d6 (P(1) = 1/4) designed there: its check's P(1) within 4σ
/// of 1/4, σ the check's binomial error and the design's own together (4,000 throws, seed 1;
/// measured: com_z −0.99 mm, P(1) 0.274 ± 0.007 (± 0.010), 2.0σ).
#[test]
fn a_design_under_a_fits_calibration_takes_its_values_and_says_so() {
    let dir = Scratch::new("design-fit");
    let fit = cube_fit(&dir);
    let fitted: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&fit).unwrap()).unwrap();
    let mu = fitted["estimate"]["params"][0]["value"].as_f64().unwrap();
    let args = |json_: bool| {
        let mut a = vec![
            "design",
            "--block",
            "16x16x16",
            "--free",
            "com_z",
            "--range",
            "com_z=-3:0",
            "--target",
            "1=1/4,rest=3/4",
            "--fit",
            &fit,
            "--rolls",
            "1000",
            "--points",
            "5",
            "--check-rolls",
            "4000",
            "--seed",
            "1",
            "--threads",
            "2",
        ];
        if json_ {
            a.push("--json");
        }
        dicephys(&a)
    };
    let v = json(&args(true));
    let c = &v["config"]["calibration"];
    assert_eq!(c["fit"], fit.as_str());
    assert_eq!(c["surface"], "felt");
    assert_eq!(c["values"]["e"], 0.9);
    assert_eq!(c["values"]["mu"].as_f64().unwrap(), mu);
    let scene = &v["config"]["spec"]["scene"];
    assert_eq!(scene["restitution"], 0.9);
    assert_eq!(scene["friction"].as_f64().unwrap(), mu);
    assert_eq!(scene["dt"], 0.004);
    let (p, err, own) = (
        v["check"]["p"][0].as_f64().unwrap(),
        v["check"]["err"][0].as_f64().unwrap(),
        v["check"]["design_err"][0].as_f64().unwrap(),
    );
    assert!(
        (p - 0.25).abs() < 4.0 * err.hypot(own),
        "P(1) {p} ± {err} (± {own})"
    );
    let text = String::from_utf8(args(false).stdout).unwrap();
    assert!(
        text.contains(&format!("the calibration of {fit} (surface felt")),
        "{text}"
    );
}

#[test]
fn what_a_named_target_or_a_fit_cannot_be_is_refused_in_one_line() {
    let design = |die: &[&str], extra: &[&str]| {
        let mut a = vec!["design"];
        a.extend(die);
        a.extend(extra);
        dicephys(&a)
    };
    let d6 = [
        "--block",
        "16x16x16",
        "--free",
        "com_z",
        "--range",
        "com_z=-3:0",
    ];
    let coin = [
        "--shape",
        "coin:24,10",
        "--free",
        "thickness",
        "--range",
        "thickness=6:14",
    ];
    refused(
        &design(&d6, &["--target", "2d6"]),
        2,
        "this die's labels are 1, 2, 3, 4, 5, 6: '1' is not among them",
    );
    refused(
        &design(&coin, &["--target", "binomial:2"]),
        2,
        "this die's labels are edge, heads, tails: 'heads' is not among them",
    );
    refused(
        &design(&coin, &["--target", "binomial:0"]),
        2,
        "write binomial:N",
    );
    let dir = Scratch::new("design-fit-refused");
    let fit = cube_fit(&dir);
    refused(
        &design(
            &d6,
            &[
                "--target",
                "1=1/4,rest=3/4",
                "--fit",
                &fit,
                "--friction",
                "0.3",
            ],
        ),
        2,
        "cannot be used with '--friction",
    );
    // The fit threw blocks with the paper's spin about a long axis; a coin has none.
    let o = design(
        &coin,
        &["--target", "heads=1/3,tails=1/3,edge=1/3", "--fit", &fit],
    );
    refused(&o, 2, "a fit of blocks predicts blocks");
    assert!(
        stderr(&o).contains(&format!("--fit {fit}")),
        "{}",
        stderr(&o)
    );
    refused(
        &design(
            &d6,
            &[
                "--target",
                "1=1/4,rest=3/4",
                "--fit",
                &fit,
                "--surface",
                "ice",
            ],
        ),
        2,
        "surface 'ice' is not in the fit",
    );
}

/// V1 with a number on every resting facet, as docs/results/real-dice/v1-numbers.toml labels
/// it (the face towards −x of each mirror pair the smaller; 6 towards −y): its die file,
/// written into `dir`.
pub fn v1_numbers(dir: &Scratch) -> String {
    let numbers = [
        ([0.0, 0.149676, -0.988735], "7"),
        ([-0.0, -0.73689, 0.676013], "6"),
        ([0.0, 0.830748, 0.556648], "8"),
        ([-0.693193, -0.69034, -0.207157], "5"),
        ([0.693193, -0.69034, -0.207157], "9"),
        ([-0.729108, 0.675868, -0.107723], "4"),
        ([0.729108, 0.675868, -0.107723], "10"),
        ([-0.989859, 0.078844, 0.118164], "3"),
        ([0.989859, 0.078844, 0.118164], "11"),
        ([-0.571414, 0.023049, 0.820338], "2"),
        ([0.571414, 0.023049, 0.820338], "12"),
    ];
    v1_labelled(dir, "v1-numbers.toml", &numbers)
}

/// A design of V1's facets for 2d6, in one small round (300 throws a round and a check): the
/// mirror kept, 30 parameters free, every move within the range, the rounds' and the checks'
/// throws all at rest on a numbered face, the checks by class beside, and the design written
/// as a mesh and a die file that `roll` takes back with the same eleven labels and the same
/// quasi-static shares. (Whether the design hits 2d6 is measured at 20,000 throws on
/// docs/results/design.md, not here.)
#[test]
fn a_meshs_facets_are_designed_and_written_as_a_die_file_roll_takes_back() {
    let dir = Scratch::new("design-facets");
    let die = v1_numbers(&dir);
    let out = dir.join("out");
    let v = json(&dicephys(&[
        "design",
        "--die",
        &die,
        "--free",
        "facets",
        "--range",
        "facets=-2:2",
        "--target",
        "2d6",
        "--rolls",
        "300",
        "--rounds",
        "1",
        "--check-rolls",
        "300",
        "--threads",
        "2",
        "--seed",
        "1",
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]));
    assert_eq!(v["mirror"], true);
    assert_eq!(v["free"], 30);
    assert_eq!(v["outcomes"].as_array().unwrap().len(), 11);
    let rounds = v["rounds"].as_array().unwrap();
    assert_eq!(rounds.len(), 2, "the start and one round");
    for r in rounds {
        assert_eq!(
            r["counts"]
                .as_array()
                .unwrap()
                .iter()
                .map(|c| c.as_u64().unwrap())
                .sum::<u64>(),
            300
        );
    }
    let moved = v["largest_move"].as_f64().unwrap();
    assert!(moved > 0.0 && moved <= 2.0 * 2f64.sqrt(), "{moved}");
    for c in ["check", "start_check"] {
        assert_eq!(v[c]["n"], 300, "{c}");
        assert_eq!(v["by_class"][c]["dof"], 5, "{c}");
    }
    assert_eq!(
        v["by_class"]["classes"],
        serde_json::json!(["2|12", "3|11", "4|10", "5|9", "6|8", "7"])
    );
    // The die file rolls, its labels the design's, its quasi-static shares the design's.
    let toml = out.join("design.toml");
    assert!(out.join("design.obj").exists() && out.join("design.svg").exists());
    let r = json(&dicephys(&[
        "fair",
        "--die",
        toml.to_str().unwrap(),
        "--null",
        "quasi-static",
        "--rolls",
        "50",
        "--threads",
        "1",
        "--json",
    ]));
    let faces = r["fairness"]["faces"].as_array().unwrap();
    assert_eq!(faces.len(), 11);
    let outcomes: Vec<&str> = v["outcomes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|o| o.as_str().unwrap())
        .collect();
    for f in faces {
        let label = f["direction"].as_str().unwrap();
        let k = outcomes.iter().position(|o| *o == label).unwrap();
        let q = v["quasi_static"][k].as_f64().unwrap();
        let null = f["null"].as_f64().unwrap();
        assert!((q - null).abs() < 1e-5, "{label}: {null} against {q}");
    }
}

/// What a design of a die's facets cannot be is refused in one line, exit 2.
#[test]
fn what_a_facets_design_cannot_be_is_refused_in_one_line() {
    let dir = Scratch::new("design-facets-refused");
    let die = v1_numbers(&dir);
    let v1 = ["--die", die.as_str(), "--target", "2d6", "--free", "facets"];
    for (extra, says) in [
        (vec!["--range", "facets=1:2"], "LO ≤ 0 ≤ HI"),
        (
            vec!["--range", "com_z=-2:2"],
            "the range is --free's, facets",
        ),
        (
            vec!["--range", "facets=-2:2", "--points", "5"],
            "rolls rounds (--rounds), not scans",
        ),
        (
            vec!["--range", "facets=-2:2", "--com", "0,0,1"],
            "is of a uniform die",
        ),
        (
            vec!["--range", "facets=-2:2", "--rounds", "0"],
            "from 1 to 20",
        ),
    ] {
        let mut a = vec!["design"];
        a.extend(v1);
        a.extend(extra);
        refused(&dicephys(&a), 2, says);
    }
    for (die, says) in [
        (
            &["--block", "16x16x16"][..],
            "the die has no facets to move",
        ),
        (
            &["--shape", "coin:24,10"][..],
            "only on a mesh or a named polyhedron",
        ),
    ] {
        let mut a = vec!["design"];
        a.extend(die);
        a.extend([
            "--free",
            "facets",
            "--range",
            "facets=-2:2",
            "--target",
            "heads=1/2,rest=1/2",
        ]);
        refused(&dicephys(&a), 2, says);
    }
    refused(
        &dicephys(&[
            "design",
            "--block",
            "16x16x16",
            "--free",
            "com_z",
            "--range",
            "com_z=-3:0",
            "--target",
            "1=1/4,rest=3/4",
            "--rounds",
            "3",
        ]),
        2,
        "only --free facets rolls rounds",
    );
}

/// A coin designed under a fit that measured no rolling resistance (a cube's, thrown in a
/// tumble) keeps the coin's own, 0.05 mm on Bullet, and so does a prediction for it: with the
/// fit's 0, a coin rolling on its rim never stops and every such roll runs to the step cap
/// (unsettled; a design of hours, not seconds).
#[test]
fn a_coin_under_a_fit_without_rolling_resistance_keeps_its_own() {
    let dir = Scratch::new("design-coin-fit");
    let fit_json = std::path::PathBuf::from(cube_fit_with(&dir, &["--throw", "tumble"]));
    let v = json(&dicephys(&[
        "design",
        "--shape",
        "coin:24,10",
        "--free",
        "thickness",
        "--range",
        "thickness=6:14",
        "--target",
        "heads=1/3,tails=1/3,edge=1/3",
        "--fit",
        fit_json.to_str().unwrap(),
        "--rolls",
        "100",
        "--points",
        "3",
        "--check-rolls",
        "200",
        "--threads",
        "2",
        "--seed",
        "1",
        "--json",
    ]));
    assert_eq!(v["config"]["calibration"]["values"]["rolling"], 0.05);
    assert_eq!(v["config"]["spec"]["scene"]["rolling_resistance"], 5e-5);
    assert_eq!(
        v["check"]["n"], 200,
        "every check roll at rest on a face or the edge"
    );
    // `predict` carries the same fit to the coin the same way: every roll comes to rest.
    let p = json(&dicephys(&[
        "predict",
        "--fit",
        fit_json.to_str().unwrap(),
        "--shape",
        "coin:24,10",
        "--draws",
        "2",
        "--rolls",
        "50",
        "--threads",
        "1",
        "--seed",
        "1",
        "--json",
    ]));
    assert_eq!(p["unsettled"], 0);
}

/// A block's breadth and width and a prism's length are families too (issue 73's list): a
/// 16 mm cube's width set so that its ±y faces come up 1/2 of the time (a flatter block; the
/// width lands below 16 mm), and a hexagonal prism's length so that its ends come up 1/4 of the
/// time, each found inside its range; a breadth asked of a prism is refused in one line.
#[test]
fn a_blocks_breadth_and_width_and_a_prisms_length_are_designed() {
    let small = [
        "--rolls",
        "300",
        "--points",
        "4",
        "--check-rolls",
        "400",
        "--threads",
        "2",
        "--seed",
        "1",
        "--json",
    ];
    let width = json(&dicephys(
        &[
            &[
                "design",
                "--block",
                "16x16x16",
                "--free",
                "width",
                "--range",
                "width=8:16",
                "--target",
                "3=1/4,4=1/4,rest=1/2",
            ][..],
            &small,
        ]
        .concat(),
    ));
    let w = width["value"].as_f64().unwrap();
    assert!(w > 8.0 && w < 16.0, "{w}");
    assert_eq!(width["config"]["what"], "width");
    let prism = json(&dicephys(
        &[
            &[
                "design",
                "--shape",
                "prism:6,16,20",
                "--free",
                "length",
                "--range",
                "length=8:40",
                "--target",
                "top=1/8,bottom=1/8,rest=3/4",
            ][..],
            &small,
        ]
        .concat(),
    ));
    let l = prism["value"].as_f64().unwrap();
    assert!(l > 8.0 && l < 40.0, "{l}");
    refused(
        &dicephys(&[
            "design",
            "--shape",
            "prism:6,16,20",
            "--free",
            "breadth",
            "--range",
            "breadth=8:20",
            "--target",
            "top=1/8,bottom=1/8,rest=3/4",
        ]),
        2,
        "the die is not a block",
    );
}
