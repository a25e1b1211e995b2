//! `fit` of several dice at once (issue 71.1 and 71.4): a `die` column names each row's die, a
//! shape or a die file beside the counts file; the surface's parameters are shared across the
//! dice, each die keeps its own geometry, each die is left out in turn, and what a row's die
//! cannot be is refused in one line.

use super::helpers::{dicephys, json, refused, Scratch};

/// A small, coarse fit (a degree-1 surrogate, 8 points × 60 rolls, dt = 1/250, one pass) of
/// `csv` with `free` free, as JSON; `extra` after it.
fn fit(csv: &std::path::Path, free: &str, out: &Scratch, extra: &[&str]) -> std::process::Output {
    let mut a = vec![
        "fit",
        "--data",
        csv.to_str().unwrap(),
        "--free",
        free,
        "--points",
        "8",
        "--point-rolls",
        "60",
        "--degree",
        "1",
        "--no-refine",
        "--dt",
        "1/250",
        "--threads",
        "1",
        "--seed",
        "7",
        "--out",
        out.to_str().unwrap(),
        "--json",
    ];
    a.extend(extra);
    dicephys(&a)
}

const HEAD: &str = "label,surface,die,face_1,face_2,face_3,face_4,face_5,face_6,face_7,face_8";

#[test]
fn a_d6_and_a_d8_share_the_surface_and_each_is_predicted_from_the_other() {
    let dir = Scratch::new("dice-two");
    let csv = dir.join("dice.csv");
    std::fs::write(
        &csv,
        format!(
            "{HEAD}\ncube,felt,d6,170,162,171,165,168,164,,\n\
             octahedron,felt,d8,126,118,131,122,125,127,120,131\n"
        ),
    )
    .unwrap();
    let out = Scratch::absent("dice-two-out");
    let v = json(&fit(&csv, "e,mu", &out, &[]));
    // One e and one μ for the felt, whichever die was thrown on it.
    let params: Vec<String> = v["params"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            format!(
                "{}[{}]",
                p["kind"].as_str().unwrap(),
                p["group"].as_str().unwrap()
            )
        })
        .collect();
    assert_eq!(params, ["e[felt]", "mu[felt]"], "{v}");
    // Each die its own design, its own outcomes, its own geometry.
    let designs = v["designs"].as_array().unwrap();
    let dice: Vec<&str> = designs.iter().map(|d| d["die"].as_str().unwrap()).collect();
    assert_eq!(dice, ["d6", "d8"]);
    let outcomes = |d: &serde_json::Value| d["points"][0]["counts"].as_array().unwrap().len();
    assert_eq!((outcomes(&designs[0]), outcomes(&designs[1])), (6, 8));
    assert_ne!(designs[0]["block"], designs[1]["block"]);
    let rows = v["config"]["rows"].as_array().unwrap();
    assert_eq!(rows[0]["labels"].as_array().unwrap().len(), 6);
    assert_eq!(rows[1]["counts"].as_array().unwrap().len(), 8);
    assert_eq!(
        v["estimate"]["dof"], 10,
        "6 − 1 + 8 − 1 counts less 2 parameters"
    );
    for p in v["estimate"]["params"].as_array().unwrap() {
        assert!(p["value"].as_f64().unwrap().is_finite(), "{p}");
    }
    // Leave one die out: each die predicted by a fit of the other, scored beside the baselines.
    let loo = v["loo"].as_array().unwrap();
    assert_eq!(loo.len(), 2, "{v}");
    assert_eq!(loo[1]["die"], "d8");
    let per_die = v["loo_dice"].as_array().unwrap();
    assert_eq!(per_die.len(), 2);
    assert_eq!(per_die[0]["die"], "d6");
    assert_eq!(per_die[0]["rows"][0], "cube");
    for d in per_die {
        for kind in ["prediction", "default_scene", "quasi_static"] {
            let s = d["scores"][kind]["log_score"].as_f64();
            assert!(s.is_some_and(|s| s.is_finite() && s < 0.0), "{kind}: {d}");
        }
    }
    let total = v["loo_scores"]["prediction"]["log_score"].as_f64().unwrap();
    let sum: f64 = per_die
        .iter()
        .map(|d| d["scores"]["prediction"]["log_score"].as_f64().unwrap())
        .sum();
    assert!((total - sum).abs() < 1e-9, "{total} {sum}");
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(report.contains("leave one die out"), "{report}");
    // Faces have no ratio: no "Ratios within 1σ: 0 of 0".
    assert!(!report.contains("Ratios within"), "{report}");
    assert!(
        report.contains("| row | surface | outcomes | log score |"),
        "{report}"
    );
}

/// A cube as a mesh: its facets numbered 1 to 6 by their order.
fn cube_obj() -> String {
    super::shapes::cube_obj(16.0)
}

#[test]
fn a_rows_die_file_is_found_beside_the_counts_file_and_a_missing_one_is_named() {
    let dir = Scratch::new("dice-file");
    let sub = dir.join("counted");
    std::fs::create_dir(&sub).unwrap();
    std::fs::write(sub.join("cube.obj"), cube_obj()).unwrap();
    let csv = sub.join("dice.csv");
    // Run from elsewhere (the tests' directory): the file is found beside the CSV.
    std::fs::write(
        &csv,
        "label,surface,die,face_1,face_2,face_3,face_4,face_5,face_6,face_7,face_8\n\
         printed,felt,cube.obj,70,62,71,65,68,64,,\n\
         bought,felt,d8,26,18,31,22,25,27,20,31\n",
    )
    .unwrap();
    let out = Scratch::absent("dice-file-out");
    let v = json(&fit(&csv, "e", &out, &[]));
    let die = v["config"]["rows"][0]["die"].as_str().unwrap();
    assert!(die.ends_with("counted/cube.obj"), "{die}");
    let block = &v["designs"][0]["block"];
    assert!(
        (block["length"].as_f64().unwrap() - 0.016).abs() < 1e-9,
        "{block}"
    );
    // The same file named where there is none: one line, naming the row and the file.
    std::fs::write(
        &csv,
        "label,surface,die,face_1,face_2,face_3,face_4,face_5,face_6\n\
         printed,felt,gone.obj,70,62,71,65,68,64\n",
    )
    .unwrap();
    let out = Scratch::absent("dice-file-gone");
    refused(&fit(&csv, "e", &out, &[]), 2, "row 'printed': its die '");
    let o = fit(&csv, "e", &out, &[]);
    assert!(super::helpers::stderr(&o).contains("counted/gone.obj"));
}

#[test]
fn what_a_rows_die_cannot_be_is_refused_in_one_line() {
    let dir = Scratch::new("dice-refused");
    let csv = dir.join("dice.csv");
    let out = Scratch::absent("dice-refused-out");
    let cases = [
        // An unknown shape.
        (
            format!("{HEAD}\na,felt,d7,1,2,3,4,5,6,7,8\n"),
            "e",
            "row 'a': its die 'd7'",
        ),
        // A count in a column that is not the row's die's face.
        (
            format!("{HEAD}\na,felt,d6,1,2,3,4,5,6,,9\nb,felt,d8,1,2,3,4,5,6,7,8\n"),
            "e",
            "not its faces: face_8",
        ),
        // A face of the die left empty.
        (
            format!("{HEAD}\na,felt,d8,1,2,3,4,5,6,7,\n"),
            "e",
            "missing face_8",
        ),
        // A die file that is not there (a TOML).
        (
            format!("{HEAD}\na,felt,dice/v9.toml,1,2,3,4,5,6,7,8\n"),
            "e",
            "v9.toml",
        ),
        // A row of no die, with no die on the command line.
        (
            format!("{HEAD}\na,felt,,1,2,3,4,5,6,,\nb,felt,d8,1,2,3,4,5,6,7,8\n"),
            "e",
            "give the die",
        ),
        // One die's own parameter, with two dice.
        (
            format!("{HEAD}\na,felt,d6,1,2,3,4,5,6,,\nb,felt,d8,1,2,3,4,5,6,7,8\n"),
            "e,com_x",
            "is one die's own, and the rows name 2 dice (d6, d8)",
        ),
    ];
    for (text, free, says) in cases {
        std::fs::write(&csv, text).unwrap();
        refused(&fit(&csv, free, &out, &[]), 2, says);
    }
}

/// `predict --blocks-file` with a `die` column (issue 71.2): each row's die predicted from the
/// fit as `predict --shape/--die … --counts` predicts it alone, with the same numbers at the
/// same seed; a row of no die, or a die that cannot be had, refused in one line naming it.
#[test]
fn a_file_of_dice_is_predicted_row_by_row_as_each_die_alone() {
    let dir = Scratch::new("dice-predict");
    let csv = dir.join("cube.csv");
    std::fs::write(
        &csv,
        format!("{HEAD}\ncube,felt,d6,170,162,171,165,168,164,,\n"),
    )
    .unwrap();
    let out = Scratch::absent("dice-predict-fit");
    json(&fit(&csv, "e", &out, &[]));
    let fit_json = out.join("fit.json");
    let fit_json = fit_json.to_str().unwrap();
    let dice = dir.join("dice.csv");
    std::fs::write(
        &dice,
        format!("{HEAD}\noctahedron,felt,d8,26,18,31,22,25,27,20,31\ncube2,felt,d6,30,32,29,35,31,33,,\n"),
    )
    .unwrap();
    let pred = dir.join("pred");
    let v = json(&predict(
        fit_json,
        &[
            "--blocks-file",
            dice.to_str().unwrap(),
            "--out",
            pred.to_str().unwrap(),
        ],
    ));
    let rows = v["dice"].as_array().unwrap();
    assert_eq!(rows.len(), 2, "{v}");
    assert_eq!(
        (rows[0]["label"].as_str(), rows[0]["die"].as_str()),
        (Some("octahedron"), Some("d8"))
    );
    assert!(
        v["rows"].as_array().is_none_or(Vec::is_empty),
        "no blocks: {v}"
    );
    // The octahedron alone, as `predict --shape d8 --counts` predicts it.
    let alone_csv = dir.join("d8.csv");
    std::fs::write(
        &alone_csv,
        "label,surface,face_1,face_2,face_3,face_4,face_5,face_6,face_7,face_8\n\
         octahedron,felt,26,18,31,22,25,27,20,31\n",
    )
    .unwrap();
    let alone = json(&predict(
        fit_json,
        &["--shape", "d8", "--counts", alone_csv.to_str().unwrap()],
    ));
    let test = &rows[0]["prediction"]["tests"][0];
    for kind in ["prediction", "default_scene", "quasi_static"] {
        let (x, y) = (
            test["scores"][kind]["log_score"].as_f64().unwrap(),
            alone["tests"][0]["scores"][kind]["log_score"]
                .as_f64()
                .unwrap(),
        );
        assert!((x - y).abs() < 1e-9, "{kind}: {x} in the file, {y} alone");
    }
    assert_eq!(test["predicted"].as_array().unwrap().len(), 8);
    // The total sums both dice's rows.
    let total = v["scores"]["prediction"]["log_score"].as_f64().unwrap();
    let sum: f64 = rows
        .iter()
        .map(|r| {
            r["prediction"]["tests"][0]["scores"]["prediction"]["log_score"]
                .as_f64()
                .unwrap()
        })
        .sum();
    assert!((total - sum).abs() < 1e-9, "{total} {sum}");
    let table = std::fs::read_to_string(pred.join("dice.csv")).unwrap();
    assert_eq!(table.lines().count(), 1 + 8 + 6, "{table}");
    assert!(
        table.starts_with("label,die,outcome,p,p_err,count\noctahedron,d8,face 1,"),
        "{table}"
    );
    let report = std::fs::read_to_string(pred.join("report.md")).unwrap();
    assert!(report.contains("## octahedron (d8)"), "{report}");
    // A row that names no die, and a die that is not one.
    for (row, says) in [
        ("a,felt,,1,2,3,4,5,6,,", "row 'a': names no die"),
        ("a,felt,d7,1,2,3,4,5,6,7,8", "row 'a': die 'd7'"),
    ] {
        std::fs::write(&dice, format!("{HEAD}\n{row}\n")).unwrap();
        let args = [
            "--blocks-file",
            dice.to_str().unwrap(),
            "--out",
            pred.to_str().unwrap(),
        ];
        refused(&predict(fit_json, &args), 2, says);
    }
}

/// `predict --fit FIT` with `extra`, two draws of 40 rolls on one thread, as JSON.
fn predict(fit: &str, extra: &[&str]) -> std::process::Output {
    let mut a = vec!["predict", "--fit", fit];
    a.extend(extra);
    a.extend(["--draws", "2", "--rolls", "40", "--threads", "1", "--json"]);
    dicephys(&a)
}
