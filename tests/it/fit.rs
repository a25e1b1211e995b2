//! `fit`, `predict` and the throw family through the binary: a fit recovers known parameters,
//! bad files and values are refused with one line, the same seed gives the same fit on any
//! thread count, and a prediction carries its errors. And the promises every command keeps,
//! kept by `fit`, `fit --recover` and `predict` (issue 34): the directory a fit writes is its
//! alone, a stop is honoured in every stage, `--threads` is the threads used, inputs are read
//! through a cap and checked before anything runs, `fit.json` is sealed, a fit of rolls that
//! did not settle is refused. Each of those probes fails against the binary before its fix
//! (`DICEPHYS_TEST_BIN`, see helpers).

use crate::helpers::{
    bin, dicephys, interrupt_after, json, refused, stderr, timed, wait_at_most, Scratch,
};
use dicephys::calibration::data::DataRow;
use dicephys::calibration::design::DesignSpec;
use dicephys::calibration::estimate::{Identified, Search};
use dicephys::calibration::params::{Fixed, Kind, Method, ModelSpec};
use dicephys::calibration::FitConfig;
use dicephys::engine::EngineKind;
use dicephys::model::scene::Mode;
use dicephys::run::runner::Runner;
use dicephys::run::stop::Stop;
use dicephys::studies::fit::{first_pass, recovery, second_pass, Session};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

const HEAD: &str = "label,surface,length_mm,breadth_mm,width_mm,mode,length_vertical,breadth_vertical,width_vertical\n";

/// Two blocks on one surface: the data's shape for the recovery (their counts are not used).
fn two_blocks(dir: &Scratch) -> String {
    let path = dir.join("counts.csv");
    std::fs::write(
        &path,
        format!("{HEAD}a,felt,140,24,20,3d,0,200,400\nb,felt,100,43.9,43.2,3d,10,300,290\n"),
    )
    .unwrap();
    path.display().to_string()
}

/// `fit --free e` of `csv` into `out`, one pass at dt = 1/250 with `design` (its points,
/// rolls, degree, range): its JSON.
fn fit_e(csv: &str, out: &std::path::Path, design: &[&str]) -> serde_json::Value {
    let head = [
        "fit",
        "--data",
        csv,
        "--free",
        "e",
        "--dt",
        "1/250",
        "--no-refine",
        "--out",
        out.to_str().unwrap(),
        "--json",
    ];
    json(&dicephys(&[&head[..], design].concat()))
}

#[test]
fn the_fit_recovers_known_parameters_in_its_2_sigma_region() {
    // 20 fixed-seed repetitions: counts simulated at e = 0.5, μ = 0.3, κ = 30 in the shape of
    // two rows (600 and 600 throws), fitted back with their own simulations (24 points × 150
    // rolls a block, two passes, dt = 1/250). The joint 2σ region is stated to hold the truth
    // 95.45 % of the time; the test asks ≥ 90 % (18 of 20). Measured: 20 of 20, the truth's
    // Δ(−2 ln L) averaging 2.3 (χ²₃'s mean is 3; a weakly identified κ lowers it).
    let dir = Scratch::new("fit-recover");
    let csv = two_blocks(&dir);
    let out = dicephys(&[
        "fit",
        "--data",
        &csv,
        "--free",
        "e,mu,kappa",
        "--points",
        "24",
        "--degree",
        "2",
        "--rolls",
        "150",
        "--dt",
        "1/250",
        "--recover",
        "e=0.5,mu=0.3,kappa=30",
        "--repeats",
        "20",
        "--seed",
        "11",
        "--out",
        dir.to_str().unwrap(),
        "--json",
    ]);
    let r = json(&out);
    let reps = r["repetitions"].as_array().unwrap();
    assert_eq!(reps.len(), 20);
    let covered = reps.iter().filter(|x| x["covered"] == true).count();
    assert!(covered >= 18, "{covered} of 20 covered: {r}");
    let mean: f64 = reps
        .iter()
        .map(|x| x["truth_delta"].as_f64().unwrap())
        .sum::<f64>()
        / 20.0;
    assert!(mean < 6.0, "the truth's mean Δ {mean}");
    assert!(dir.join("recovery.json").exists());
}

#[test]
fn a_fit_is_the_same_on_one_thread_and_two_and_predicts_with_errors() {
    let dir = Scratch::new("fit-threads");
    let csv = dir.join("counts.csv");
    std::fs::write(
        &csv,
        format!("{HEAD}a,MDF,140,24,20,2d,0,361,639\nb,MDF,140,30,10,2d,0,40,460\n"),
    )
    .unwrap();
    let fit = |threads: &str, out: &str| {
        let out_dir = dir.join(out);
        json(&dicephys(&[
            "fit",
            "--data",
            csv.to_str().unwrap(),
            "--free",
            "e,mu",
            "--points",
            "20",
            "--degree",
            "2",
            "--rolls",
            "100",
            "--dt",
            "1/250",
            "--threads",
            threads,
            "--out",
            out_dir.to_str().unwrap(),
            "--json",
        ]))
    };
    let (a, b) = (fit("1", "one"), fit("2", "two"));
    for key in ["estimate", "designs", "params", "first_pass", "passes"] {
        assert_eq!(a[key], b[key], "{key} differs between 1 and 2 threads");
    }
    let e = &a["estimate"];
    assert_eq!(e["params"].as_array().unwrap().len(), 2);
    // Every printed estimate lies inside its own 1σ and 2σ intervals.
    for p in e["params"].as_array().unwrap() {
        let v = p["value"].as_f64().unwrap();
        for key in ["one_sigma", "two_sigma"] {
            let (lo, hi) = (p[key][0].as_f64().unwrap(), p[key][1].as_f64().unwrap());
            assert!(lo <= v && v <= hi, "{key}: {p}");
        }
    }
    for f in ["fit.json", "report.md", "fit_profiles.png", "fit_rows.svg"] {
        assert!(dir.join("one").join(f).exists(), "{f}");
    }
    // A block the fit did not see, on its surface: probabilities with both errors.
    let fit_json = dir.join("one/fit.json");
    let p = json(&dicephys(&[
        "predict",
        "--fit",
        fit_json.to_str().unwrap(),
        "--block",
        "140x27x13",
        "--2d",
        "--draws",
        "4",
        "--rolls",
        "200",
        "--json",
    ]));
    let ratio = &p["ratio"];
    assert!(
        ratio["value"].as_f64().unwrap() > 0.0 && ratio["err"].as_f64().unwrap() > 0.0,
        "{p}"
    );
    let (ep, es, e) = (
        ratio["err_params"].as_f64().unwrap(),
        ratio["err_sim"].as_f64().unwrap(),
        ratio["err"].as_f64().unwrap(),
    );
    assert!((e * e - ep * ep - es * es).abs() < 1e-12, "{ratio}");
    // An unknown surface is refused with one line.
    let bad = dicephys(&[
        "predict",
        "--fit",
        fit_json.to_str().unwrap(),
        "--block",
        "140x27x13",
        "--surface",
        "ice",
    ]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&bad.stderr).contains("surface 'ice' is not in the fit"));
}

#[test]
fn bad_counts_files_name_their_line_and_column() {
    let dir = Scratch::new("fit-bad");
    let cases = [
        (
            format!("{HEAD}a,MDF,140,24,20,3d,0,x,639\n"),
            "line 2, column 8 (breadth_vertical)",
        ),
        (
            format!("{HEAD}a,MDF,140,24,20,3d,0,36,-\n"),
            "line 2, column 7",
        ),
        (
            format!("{HEAD}a,MDF,140,24,20,3d,0,36,60\nb,MDF,-1,24,20,3d,0,1,1\n"),
            "line 3, column 3 (length_mm)",
        ),
        (
            format!("{HEAD}a,MDF,140,24,20,5d,0,36,60\n"),
            "line 2, column 6 (mode)",
        ),
        ("label,surface\n".into(), "line 1: the header"),
        (
            format!("{HEAD}a,MDF,140,24,20,2d,0,36,60\n"),
            "2 free parameters from 1 independent counts",
        ),
    ];
    for (i, (text, want)) in cases.iter().enumerate() {
        let csv = dir.join(format!("bad{i}.csv"));
        std::fs::write(&csv, text).unwrap();
        let out = dicephys(&[
            "fit",
            "--data",
            csv.to_str().unwrap(),
            "--out",
            dir.to_str().unwrap(),
        ]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{text}: {err}");
        assert!(err.contains(want), "{err} (wanted {want})");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
    }
}

#[test]
fn values_outside_their_physical_ranges_are_refused() {
    let dir = Scratch::new("fit-ranges");
    let csv = two_blocks(&dir);
    let out_dir = dir.to_str().unwrap();
    for (flags, want) in [
        (vec!["--range", "e=0.2:1.5"], "range of e"),
        (vec!["--range", "mu=-1:1"], "range of mu"),
        (vec!["--range", "mu=0.9:0.2"], "high to low"),
        (vec!["--range", "kappa=0:10"], "kappa is not among --free"),
        (vec!["--restitution", "1.2"], "e 1.2"),
        (vec!["--friction", "-0.1"], "mu -0.1"),
        (vec!["--kappa", "-3"], "kappa -3"),
        (vec!["--free", "e,size"], "unknown parameter 'size'"),
        (vec!["--points", "5"], "--points 5"),
        (
            vec!["--recover", "e=0.5"],
            "give a value for the free parameter mu",
        ),
        (vec!["--recover", "e=2,mu=0.3"], "outside its range"),
    ] {
        let mut args = vec!["fit", "--data", &csv, "--out", out_dir];
        args.extend(flags.iter());
        let out = dicephys(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{flags:?}: {err}");
        assert!(err.contains(want), "{flags:?}: {err} (wanted {want})");
    }
    // A die refused at the end of a free parameter's box is named by the box the user sets
    // with --range, not by --com or --pips, which they may not have written (reliability
    // round 5, class G).
    let faces = dir.join("faces.csv");
    std::fs::write(
        &faces,
        "label,surface,length_mm,breadth_mm,width_mm,mode,face_1,face_2,face_3,face_4,face_5,\
         face_6\nd,MDF,16,16,16,3d,30,25,25,25,25,20\n",
    )
    .unwrap();
    for (flags, want) in [
        (
            vec!["--free", "com_z", "--range", "com_z=-7.9:7.9"],
            "--range com_z=-7.9:7.9: the die at the box's end, its centre of mass 0,0,-7.9 mm, \
             is too far",
        ),
        (
            vec![
                "--free",
                "pip_depth",
                "--pips",
                "3,1",
                "--range",
                "pip_depth=0.5:1.6",
            ],
            "--range pip_depth=0.5:1.6: the die at the box's end, its pip depth 1.6 mm",
        ),
    ] {
        let mut args = vec!["fit", "--data", faces.to_str().unwrap(), "--kappa", "0"];
        args.extend(flags.iter());
        let out = dicephys(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{flags:?}: {err}");
        assert!(err.contains(want), "{flags:?}: {err} (wanted {want})");
        assert!(
            !err.contains("--com") && !err.contains("--pips depth"),
            "{err}"
        );
    }
    // The hand's throw needs its κ, and κ needs the hand (alone, --kappa asks for it).
    for (flags, want) in [
        (vec!["--throw", "hand"], "--throw hand: needs --kappa"),
        (
            vec!["--throw", "tumble", "--kappa", "3"],
            "only --throw hand takes",
        ),
        (vec!["--throw", "hand", "--kappa", "-1"], "--kappa -1"),
    ] {
        let mut args = vec!["roll", "--block", "140x24x20", "--rolls", "10"];
        args.extend(flags.iter());
        let out = dicephys(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{flags:?}: {err}");
        assert!(err.contains(want), "{flags:?}: {err} (wanted {want})");
    }
}

#[test]
fn predict_blocks_tests_held_out_counts_in_one_command() {
    // A tiny 2D fit of two MDF rows; then three blocks at once: one measured as the fit's own
    // row (its z within 3), one measured far from any prediction (all 1000 throws on the
    // width: the held-out χ² rejects it, p < 1e-6), one not measured.
    let dir = Scratch::new("fit-blocks");
    let csv = dir.join("counts.csv");
    std::fs::write(
        &csv,
        format!("{HEAD}a,MDF,140,24,20,2d,0,361,639\nb,MDF,140,30,10,2d,0,40,460\n"),
    )
    .unwrap();
    let out = dir.join("fit");
    fit_e(
        csv.to_str().unwrap(),
        &out,
        &[
            "--points",
            "8",
            "--degree",
            "2",
            "--max-degree",
            "2",
            "--rolls",
            "100",
        ],
    );
    let blocks = dir.join("blocks.csv");
    std::fs::write(
        &blocks,
        "label,block,mode,length_vertical,breadth_vertical,width_vertical\n\
         same,140x24x20,2d,0,361,639\nfar,140x27x13,2d,0,0,1000\nnew,140x26x12,2d,,,\n",
    )
    .unwrap();
    let p = json(&dicephys(&[
        "predict",
        "--fit",
        out.join("fit.json").to_str().unwrap(),
        // The old spelling of --blocks-file, still read for a version.
        "--blocks",
        blocks.to_str().unwrap(),
        "--draws",
        "4",
        "--rolls",
        "200",
        "--out",
        dir.join("pred").to_str().unwrap(),
        "--json",
    ]));
    let rows = p["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 3);
    assert!(rows[0]["z"].as_f64().unwrap().abs() < 3.0, "{}", rows[0]);
    assert!(rows[2]["z"].is_null() && rows[2]["chi2"].is_null());
    assert_eq!(p["dof"], 2);
    assert!(p["p_value"].as_f64().unwrap() < 1e-6, "{p}");
    for f in [
        "predictions.csv",
        "predictions.json",
        "report.md",
        "predictions.svg",
    ] {
        assert!(dir.join("pred").join(f).exists(), "{f}");
    }
    let csv_text = std::fs::read_to_string(dir.join("pred/predictions.csv")).unwrap();
    assert_eq!(csv_text.lines().count(), 4);
}

/// Points a block in [`counted_at_e_03`]'s fit.
const POINTS: usize = 8;
/// Rolls a point.
const ROLLS: u64 = 500;

/// Rows on surfaces A and B counted at e = 0.3, and a fit of e on them: [`POINTS`] × [`ROLLS`]
/// a block, dt = 1/250.
fn counted_at_e_03(runner: &Runner) -> FitConfig {
    let row = |label: &str, surface: &str, block: &str, n: u64| DataRow {
        label: label.into(),
        surface: surface.into(),
        thrower: "all".into(),
        block: block.parse().unwrap(),
        mode: Mode::TwoD,
        outcomes: Default::default(),
        counts: vec![0, 0, n],
        groups: vec![vec![1], vec![2]],
        labels: Vec::new(),
        die: None,
    };
    let shape = vec![
        row("a1", "A", "140x30x10", 4000),
        row("a2", "A", "140x24x20", 2000),
        row("b1", "B", "140x30x10", 2000),
    ];
    let cfg = FitConfig {
        rows: shape,
        model: ModelSpec::free(&[Kind::E]),
        method: Method {
            engine: EngineKind::Bullet,
            dt: 1.0 / 250.0,
            max_steps: dicephys::sim::roll::DEFAULT_MAX_STEPS,
            die: Default::default(),
            dice: Vec::new(),
        },
        design: DesignSpec {
            points: POINTS,
            rolls: ROLLS,
            degree: 2,
            max_degree: 3,
            ..DesignSpec::default()
        },
        search: Search {
            seed: 35,
            ..Search::default()
        },
        seed: 35,
    };
    let truth = Fixed {
        e: 0.3,
        ..Fixed::default()
    };
    let rows = recovery::simulate_data(&cfg, &truth, 3535, runner)
        .unwrap()
        .unwrap();
    FitConfig { rows, ..cfg }
}

/// Counts at e = 0.3 on two surfaces (2D blocks, whose outcomes move with e: 140x30x10 falls
/// on its breadth 1.4 % of the time at e = 0.05, 2.3 % at 0.3, 4.2 % at 0.6), and a first pass
/// made to miss: its 2σ interval of e[A] put at 0.65–0.72, so that the second pass's box,
/// e[A] 0.61–0.76, leaves the truth out. The fit must widen that box until e[A]'s maximum and
/// 2σ interval are inside it, rolling again only the blocks whose box moved: e[B] (one row, never
/// narrowed) keeps its range, and its block's design is the first pass's throughout. Before
/// the widening, the fit stopped at the second pass with e[A] on the box's lower edge, 0.6125.
/// About 40,000 rolls.
#[test]
fn a_box_that_cut_a_parameter_is_widened_until_it_does_not() {
    let runner = Runner::new(2, Stop::new());
    let cfg = counted_at_e_03(&runner);
    let session = Session::default();
    let mut first = first_pass(&cfg, &runner, None, &session).unwrap().unwrap();
    let a = first
        .estimate
        .params
        .iter_mut()
        .find(|p| p.name == "e[A]")
        .unwrap();
    a.two_sigma = [0.65, 0.72];
    let fitted = second_pass(first, &runner, None, &session)
        .unwrap()
        .unwrap();

    let p = fitted
        .estimate
        .params
        .iter()
        .find(|p| p.name == "e[A]")
        .unwrap();
    let (r, whole) = (p.param.range, p.param.whole);
    let u = Kind::E.coordinate(r, p.value);
    let passes: Vec<String> = fitted.passes.iter().map(|p| format!("{p:?}")).collect();
    let said = format!(
        "e[A] {} in {r} (2σ {:?}); passes {passes:#?}",
        p.value, p.two_sigma
    );
    // Interior: not on an edge of its box that is not its range's own.
    assert!(
        r.lo == whole.lo || u > 0.02,
        "on the box's lower edge: {said}"
    );
    assert!(
        r.hi == whole.hi || u < 0.98,
        "on the box's upper edge: {said}"
    );
    assert_ne!(p.identified, Identified::Cut, "{said}");
    assert!(
        p.two_sigma[0] <= 0.3 && 0.3 <= p.two_sigma[1],
        "the truth: {said}"
    );
    // The second pass's box cut e[A] below; the last pass's cut nothing.
    let second = &fitted.passes[1];
    assert!(
        second.cut.len() == 1 && second.cut[0].param == "e[A]" && second.cut[0].lower,
        "{said}"
    );
    assert!(
        fitted.passes.len() >= 3 && fitted.passes.len() <= 6,
        "{said}"
    );
    assert!(fitted.passes.last().unwrap().cut.is_empty(), "{said}");
    assert_eq!(fitted.unresolved, None, "{said}");
    // Each pass records its maximum, so the table shows where the passes went.
    assert!(fitted.passes.iter().all(|p| p.values.len() == 2), "{said}");
    // e[B] keeps its whole range in every pass, and its block's design is never rolled again:
    // each pass after the first rolls only the two blocks of surface A, or none where its box
    // is an earlier pass's (that pass's designs, their surrogates through every later point).
    let per_design = POINTS as u64 * ROLLS;
    assert_eq!(fitted.passes[0].rolls, 2 * per_design, "{said}");
    for pass in &fitted.passes[1..] {
        assert!(pass.rolls == 2 * per_design || pass.rolls == 0, "{said}");
        let b = pass.bounds.iter().find(|b| b.param == "e[B]").unwrap();
        assert_eq!(b.range, Kind::E.default_range(), "{said}");
    }
    // One design a key: three while e[A]'s box is narrowed, two where it is the whole range
    // (then both surfaces' rows of 140x30x10 read one design).
    let keys = dicephys::calibration::design::keys(&fitted.config.rows, &fitted.config.model);
    assert_eq!(fitted.designs.len(), keys.len(), "{said}");
    let total: u64 = fitted.passes.iter().map(|p| p.rolls).sum();
    assert_eq!(fitted.rolls, total);
}

#[test]
fn a_parameter_at_its_ranges_end_is_reported_as_the_model_asking_for_more() {
    // The paper's rows want e near 0.5; searched over 0.05–0.1 only, its likelihood rises to
    // the range's upper end. The report and fit.json say so rather than give 0.1 as a value.
    let dir = Scratch::new("fit-range-end");
    let csv = two_blocks(&dir);
    let out = dir.join("out");
    let v = fit_e(
        &csv,
        &out,
        &[
            "--range",
            "e=0.05:0.1",
            "--points",
            "12",
            "--degree",
            "2",
            "--rolls",
            "100",
        ],
    );
    let p = &v["estimate"]["params"][0];
    assert_eq!(p["asks_for_more"], "upper", "{p}");
    assert_eq!(p["value"], 0.1, "{p}");
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(
        md.contains("0.100 (the range's upper end)") && md.contains("the model asks for more"),
        "{md}"
    );
}

#[test]
fn a_misfit_is_widened_by_its_overdispersion_and_a_fit_that_fits_is_not() {
    // Issue 49: three rows on one surface, their counts rolled at e = 0.5 (dt = 1/250); in the
    // second file two rows of the same block disagree (breadth 1,590 of 3,000 against 1,358):
    // no e fits both. There the bootstrap's p is below 0.05, the overdispersion φ is the
    // data's χ² over the bootstrap's mean, every profile's bound is φ times the Bartlett's, the 2σ
    // interval is wider than the profile's own Δ = 4b, and data drawn with φ check it.
    let dir = Scratch::new("fit-misfit");
    let fit = |name: &str, rows: &str| {
        let csv = dir.join(name);
        std::fs::write(&csv, format!("{HEAD}{rows}")).unwrap();
        let out = dir.join(format!("{name}-out"));
        let design = ["--points", "16", "--degree", "2", "--rolls", "1500"];
        fit_e(csv.to_str().unwrap(), &out, &design)
    };
    let a = "a,felt,140,24,20,3d,1,1088,1911\n";
    let fits = fit(
        "fits.csv",
        &format!("{a}b,felt,100,43.9,43.2,3d,29,1470,1501\nc,felt,100,43.9,43.2,3d,22,1418,1560\n"),
    );
    let e = &fits["estimate"];
    assert_eq!(e["overdispersion"], 1.0, "{e}");
    assert!(e["bootstrap"].get("widened_coverage").is_none(), "{e}");

    let misfit = fit(
        "misfit.csv",
        &format!("{a}b,felt,100,43.9,43.2,3d,29,1590,1381\nc,felt,100,43.9,43.2,3d,22,1358,1620\n"),
    );
    let e = &misfit["estimate"];
    let boot = &e["bootstrap"];
    let f = |v: &serde_json::Value| v.as_f64().unwrap();
    let (phi, b) = (f(&e["overdispersion"]), f(&e["bartlett"]));
    assert!(f(&boot["chi2_p"]) < 0.05, "{e}");
    assert!(
        (phi - f(&e["chi2"]) / f(&boot["chi2_mean"])).abs() < 1e-9 && phi > 2.0,
        "{e}"
    );
    // The region's bound is the bootstrap sets' own 95.45 % quantile of Δ (the rule's
    // coverage is tested in estimate::tests), times φ; data drawn with φ check the widened
    // region.
    let region = f(&e["region_delta"]) / phi;
    assert!(region > 0.0 && region.is_finite(), "{e}");
    // Each set's Δ is in fit.json, so anyone can recompute the bound (the k-th smallest, k =
    // ⌈0.9545 (n + 1)⌉) and the check sets' coverage under it.
    let list = |key: &str| -> Vec<f64> { boot[key].as_array().unwrap().iter().map(f).collect() };
    let (mut delta, check) = (list("delta"), list("check_delta"));
    assert_eq!(delta.len() as f64, f(&boot["sets"]), "{boot}");
    delta.sort_by(f64::total_cmp);
    let k = (0.9545 * (delta.len() + 1) as f64).ceil() as usize;
    assert!((delta[k - 1] - region).abs() <= 1e-9 * region, "{boot}");
    let held = check.iter().filter(|&&d| d <= region).count() as f64;
    assert!(
        (held / check.len() as f64 - f(&boot["coverage"])).abs() < 1e-12,
        "{boot}"
    );
    assert!(f(&boot["widened_coverage"]) >= 0.9, "{e}");
    let p = &e["params"][0];
    let unwidened_lo = p["profile"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|q| f(&q[1]) <= 4.0 * b)
        .map(|q| f(&q[0]))
        .fold(f64::INFINITY, f64::min);
    assert!(f(&p["two_sigma"][0]) < unwidened_lo - 0.02, "{p}");
}

/// Issue 49: the estimate is the data's, not its boxes'. Counts rolled at a hand's throw (κ 5,
/// e 0.45, μ 0.3; four blocks, 1,000 throws each, dt = 1/250) are fitted for e and μ from three
/// first boxes (the default ranges, e 0.2–0.8 with μ 0.1–0.7, e 0.05–0.6 with μ 0.2–1) at three
/// seeds. Every fit's passes settle, and every pair of the nine estimates agrees within two
/// combined standard errors (each its 1σ interval's side towards the other; the pairs share
/// the data, so they differ only by their designs' noise, which each error also holds). At
/// `cbc57c1`, with the passes stopped at the first box that cut nothing and each surrogate
/// through its own box's points only, 66 of the 72 comparisons held and μ's worst pair stood
/// 3.9 combined σ apart (by half-widths); at `b91e912` all 72 held (worst 1.6). The rows are
/// of 1,000 throws, so that the data, not the 16-point designs, set the errors: at 3,000 the
/// bootstrap that rolls the design again put the region's bound at 1.6–2.7 times χ²'s, and a
/// pass's design (box 2, seed 3) drew μ to 0.453 where the others gave 0.23–0.35 (2.7 sided σ):
/// an estimate that is its design's noise, wherever the box. About 300,000 rolls.
#[test]
fn the_same_counts_from_three_first_boxes_at_three_seeds_give_one_estimate() {
    let dir = Scratch::new("fit-boxes");
    let mut csv = HEAD.to_string();
    for block in ["140x24x20", "100x43.9x43.2", "60x24x20", "30x24x20"] {
        let args = "--throw hand --kappa 5 --restitution 0.45 --friction 0.3 --dt 1/250 \
                    --rolls 1000 --seed 11 --json";
        let mut roll = vec!["roll", "--block", block];
        roll.extend(args.split(' '));
        let c = &json(&dicephys(&roll))["counts"];
        let mm: Vec<&str> = block.split('x').collect();
        csv += &format!(
            "{block},T,{},{},{},3d,{},{},{}\n",
            mm[0], mm[1], mm[2], c["length"], c["breadth"], c["width"]
        );
    }
    let data = dir.join("hand.csv");
    std::fs::write(&data, csv).unwrap();
    let boxes: [&[&str]; 3] = [
        &[],
        &["--range", "e=0.2:0.8", "--range", "mu=0.1:0.7"],
        &["--range", "e=0.05:0.6", "--range", "mu=0.2:1"],
    ];
    let mut fits = Vec::new();
    for (b, first) in boxes.iter().enumerate() {
        for seed in ["1", "2", "3"] {
            let out = dir.join(format!("b{b}-s{seed}"));
            let args = "--free e,mu --kappa 5 --dt 1/250 --points 16 --degree 2 \
                        --point-rolls 300 --json";
            let mut fit = vec!["fit", "--data", data.to_str().unwrap(), "--seed", seed];
            fit.extend(args.split(' '));
            fit.extend_from_slice(first);
            fit.extend(["--out", out.to_str().unwrap()]);
            let v = json(&dicephys(&fit));
            assert!(v.get("unresolved").is_none(), "box {b} seed {seed}: {v}");
            fits.push((
                format!("box {b} seed {seed}"),
                v["estimate"]["params"].clone(),
            ));
        }
    }
    for (i, (a, pa)) in fits.iter().enumerate() {
        for (b, pb) in &fits[i + 1..] {
            for k in 0..2 {
                let (x, y) = (&pa[k], &pb[k]);
                let v = |p: &serde_json::Value| p["value"].as_f64().unwrap();
                // Each its error on the side of the other (the profile's 1σ interval is not
                // symmetric, and one that runs to its range's end is far from it).
                let (lo, hi) = if v(x) <= v(y) { (x, y) } else { (y, x) };
                let up = lo["one_sigma"][1].as_f64().unwrap() - v(lo);
                let down = v(hi) - hi["one_sigma"][0].as_f64().unwrap();
                let z = (v(hi) - v(lo)) / up.hypot(down);
                assert!(
                    z <= 2.0,
                    "{}: {a} {} (1σ {}) against {b} {} (1σ {}): {z:.2} combined σ apart",
                    x["name"],
                    x["value"],
                    x["one_sigma"],
                    y["value"],
                    y["one_sigma"]
                );
            }
        }
    }
}

/// Issue 49's held-out check: blocks counted at a known e and μ (the paper's throw, 2D, 2,000
/// throws each), three fitted and three others predicted by `predict --blocks-file`, 16 times
/// over (seeds 1–16, each its own counts, designs and predictions). A prediction's error holds
/// the fit's uncertainty and the simulation's, so each held-out χ² (on 3) should fall inside
/// χ²₃'s two-sided 95 % band (p in 0.025–0.975) 95 % of the time, and their mean near 3.
/// Measured: 22 of 24, mean 2.77 (40 repetitions: 38, mean 2.37). At 13 of 16 the binomial's
/// chance of failing a right error is 0.7 %; errors 1.5 times too small put about one χ² in
/// five outside the band (failing it 40 % of the time) and the mean near 6.7, which fails the
/// mean's bound (3 ± 0.61 for 16: 4.5 is 2.5σ). It was 24 times over (20 of 24: 0.6 % and
/// 54 %), the suite's second-longest test; 16 keep its power in the mean.
#[test]
fn held_out_blocks_fall_in_their_chi2_band_at_the_stated_rate() {
    let dir = Scratch::new("fit-held-out");
    let fitted = ["140x24x20", "140x30x10", "140x43.9x43.2"];
    let held = ["140x27x13", "140x26x12", "140x35x20"];
    let mut inside = 0;
    let mut chi2 = Vec::new();
    for seed in 1..=16 {
        let seed = seed.to_string();
        let mut fit_csv = HEAD.to_string();
        let mut held_csv =
            "label,block,mode,length_vertical,breadth_vertical,width_vertical\n".to_string();
        for block in fitted.iter().chain(&held) {
            let args = "--2d --restitution 0.45 --friction 0.3 --dt 1/250 --rolls 2000 --json";
            let mut roll = vec!["roll", "--block", block, "--seed", &seed];
            roll.extend(args.split(' '));
            let c = &json(&dicephys(&roll))["counts"];
            let (l, b, w) = (&c["length"], &c["breadth"], &c["width"]);
            if fitted.contains(block) {
                let mm: Vec<&str> = block.split('x').collect();
                fit_csv += &format!("{block},T,{},{},{},2d,{l},{b},{w}\n", mm[0], mm[1], mm[2]);
            } else {
                held_csv += &format!("{block},{block},2d,{l},{b},{w}\n");
            }
        }
        let (data, blocks) = (dir.join(format!("fit-{seed}.csv")), dir.join("held.csv"));
        std::fs::write(&data, fit_csv).unwrap();
        std::fs::write(&blocks, held_csv).unwrap();
        let out = dir.join(format!("fit-{seed}"));
        let args = "--free e,mu --dt 1/250 --points 16 --degree 2 --point-rolls 300 --json";
        let mut fit = vec!["fit", "--data", data.to_str().unwrap(), "--seed", &seed];
        fit.extend(args.split(' '));
        fit.extend(["--out", out.to_str().unwrap()]);
        json(&dicephys(&fit));
        let fit_json = out.join("fit.json");
        let p = json(&dicephys(&[
            "predict",
            "--fit",
            fit_json.to_str().unwrap(),
            "--blocks-file",
            blocks.to_str().unwrap(),
            "--draws",
            "8",
            "--rolls",
            "500",
            "--seed",
            &seed,
            "--out",
            dir.join(format!("pred-{seed}")).to_str().unwrap(),
            "--json",
        ]));
        assert_eq!(p["dof"], 3, "seed {seed}: {p}");
        let pv = p["p_value"].as_f64().unwrap();
        inside += usize::from((0.025..=0.975).contains(&pv));
        chi2.push(p["chi2"].as_f64().unwrap());
    }
    let mean = chi2.iter().sum::<f64>() / chi2.len() as f64;
    assert!(
        inside >= 13,
        "{inside} of 16 inside χ²₃'s 95 % band: {chi2:?}"
    );
    // The mean of 16 χ²₃ is 3 ± 0.61: within 2.5 of its σ.
    assert!(
        (1.5..=4.5).contains(&mean),
        "mean held-out χ² {mean:.2}: {chi2:?}"
    );
}

/// Issue 49's second item: a throw outside the fit's family (counts rolled in a tumble, fitted
/// with the paper's throw) is a bias that differs from block to block, which the rows
/// predicted without themselves show and the fit learns as a discrepancy on the log-odds, a line
/// in the predicted log-odds with a spread about it; every prediction of a block the fit did
/// not see is moved along the line and widened by it. At seed 13 the held-out χ² on 6 falls
/// from 31.4 (p 2e-5, the fit's overdispersion alone) to 8.4 with a spread alone (p 0.21) and
/// 1.8 with the line (p 0.94: a line learnt from four rows errs wide). Over 103 seeds the moved
/// predictions held 101 (93 with a spread alone): docs/results/calibration.md, "A line through the misses".
#[test]
fn a_fit_that_misses_rows_it_did_not_see_widens_its_predictions_by_its_discrepancy() {
    let dir = Scratch::new("fit-discrepancy");
    let fitted = ["140x24x20", "100x43.9x43.2", "60x24x20", "30x24x20"];
    let held = ["120x24x20", "80x43.9x43.2", "45x24x20"];
    let mut fit_csv = HEAD.to_string();
    let mut held_csv =
        "label,block,mode,length_vertical,breadth_vertical,width_vertical\n".to_string();
    for block in fitted.iter().chain(&held) {
        let roll = [
            "roll", "--block", block, "--throw", "tumble", "--dt", "1/250", "--rolls", "3000",
            "--seed", "13", "--json",
        ];
        let c = &json(&dicephys(&roll))["counts"];
        let (l, b, w) = (&c["length"], &c["breadth"], &c["width"]);
        if fitted.contains(block) {
            let mm: Vec<&str> = block.split('x').collect();
            fit_csv += &format!("{block},T,{},{},{},3d,{l},{b},{w}\n", mm[0], mm[1], mm[2]);
        } else {
            held_csv += &format!("{block},{block},3d,{l},{b},{w}\n");
        }
    }
    let (data, blocks) = (dir.join("fit.csv"), dir.join("held.csv"));
    std::fs::write(&data, fit_csv).unwrap();
    std::fs::write(&blocks, held_csv).unwrap();
    let out = dir.join("fit");
    let fit = json(&dicephys(&[
        "fit",
        "--data",
        data.to_str().unwrap(),
        "--free",
        "e,mu",
        "--points",
        "24",
        "--degree",
        "2",
        "--point-rolls",
        "300",
        "--dt",
        "1/250",
        "--seed",
        "13",
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]));
    let outcomes = fit["discrepancy"]["outcomes"].as_array().unwrap();
    let length = outcomes.iter().find(|o| o["outcome"] == "length").unwrap();
    assert!(
        length["p_value"].as_f64().unwrap() < 0.05 && length["asked"] == true,
        "the end counts' misses ask for a discrepancy: {length}"
    );
    // The tumble lands long blocks on their ends more often than the paper's throw: the miss
    // on the end's log-odds is positive at the rows' centre.
    assert!(length["shift"].as_f64().unwrap() > 0.0, "{length}");
    let p = json(&dicephys(&[
        "predict",
        "--fit",
        out.join("fit.json").to_str().unwrap(),
        "--blocks-file",
        blocks.to_str().unwrap(),
        "--draws",
        "8",
        "--rolls",
        "2000",
        "--out",
        dir.join("pred").to_str().unwrap(),
        "--json",
    ]));
    // The held-out χ² without the discrepancy: against the fit's own share (`fit_value`
    // where the line moved it) with the error's other parts (as `heldout::test` forms it:
    // each count's variance φ N q + N² σ²; those parts as carried along the line, a little
    // wider than the fit's own for a share moved up).
    let mut without = 0.0;
    for r in p["rows"].as_array().unwrap() {
        let pred = &r["prediction"];
        let phi = pred["overdispersion"].as_f64().unwrap();
        let counts: Vec<f64> = r["counts"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c.as_f64().unwrap())
            .collect();
        let n: f64 = counts.iter().sum();
        let shares = pred["p"].as_array().unwrap();
        assert!(shares[0]["err_model"].as_f64().unwrap() > 0.0, "{pred}");
        for (c, q) in counts.iter().zip(shares) {
            let (v, e) = (q["value"].as_f64().unwrap(), q["err"].as_f64().unwrap());
            let (a, b) = (
                q["err_params"].as_f64().unwrap(),
                q["err_sim"].as_f64().unwrap(),
            );
            let m = q.get("err_model").map_or(0.0, |m| m.as_f64().unwrap());
            assert!((e * e - (a * a + b * b + m * m)).abs() < 1e-12, "{q}");
            let v = q.get("fit_value").map_or(v, |f| f.as_f64().unwrap());
            without += (c - n * v).powi(2) / (phi * n * v + n * n * (a * a + b * b));
        }
    }
    let (chi2, pv) = (p["chi2"].as_f64().unwrap(), p["p_value"].as_f64().unwrap());
    // χ²₆'s 95 % point is 12.59.
    assert!(
        without > 12.59,
        "without the discrepancy the held-out χ² is {without:.1}"
    );
    assert!(
        pv > 0.05,
        "the widened predictions' held-out χ² {chi2:.1} (p {pv:.3})"
    );
}

/// `compare`: two fits of three rows by nested models, each row scored by a fit without it;
/// the simpler model is the one with fewer parameters whatever the order given, and fits of
/// different rows, or of too few to score, are refused with one line naming the file.
#[test]
fn compare_sets_two_models_side_by_side_and_refuses_fits_of_other_rows() {
    let dir = Scratch::new("fit-compare");
    let rows = "a,MDF,140,24,20,2d,0,410,590\nb,MDF,140,22,13,2d,0,260,740\n";
    let three = dir.join("three.csv");
    std::fs::write(&three, format!("{HEAD}{rows}c,MDF,140,30,10,2d,0,80,920\n")).unwrap();
    let two = dir.join("two.csv");
    std::fs::write(&two, format!("{HEAD}{rows}")).unwrap();
    let small = [
        "--points",
        "12",
        "--rolls",
        "200",
        "--degree",
        "2",
        "--max-degree",
        "2",
    ];
    let fit = |data: &std::path::Path, free: &str, name: &str| {
        let out = dir.join(name);
        let head = ["fit", "--data", data.to_str().unwrap(), "--free", free];
        let tail = [
            "--dt",
            "1/250",
            "--no-refine",
            "--json",
            "--out",
            out.to_str().unwrap(),
        ];
        let v = json(&dicephys(&[&head[..], &small, &tail].concat()));
        (out.display().to_string(), v)
    };
    let (e, fe) = fit(&three, "e", "e");
    let (emu, _) = fit(&three, "e,mu", "emu");
    let (short, fs) = fit(&two, "e", "short");
    let labels: Vec<&str> = fe["loo"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["label"].as_str().unwrap())
        .collect();
    assert_eq!(labels, ["a", "b", "c"]);
    assert!(fs.get("loo").is_none(), "two rows: none scored");
    let c = json(&dicephys(&["compare", &emu, &e, "--json"]));
    assert_eq!(c["models"][0]["name"], "e");
    assert_eq!(c["models"][1]["name"], "e,mu");
    assert_eq!(c["rows"].as_array().unwrap().len(), 3);
    let gain: f64 = c["rows"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["gain"].as_f64().unwrap())
        .sum();
    assert!((gain - c["decision"]["score_gain"].as_f64().unwrap()).abs() < 1e-9);
    assert_eq!(c["decision"]["lr_test"][1], 1, "nested: one more parameter");
    let text = String::from_utf8(dicephys(&["compare", &e, &emu]).stdout).unwrap();
    assert!(text.contains("Verdict: "), "{text}");
    for (args, says) in [
        ([&e, &short], "no row was predicted without itself"),
        (
            [&e, &format!("{}/nothing", dir.path().display())],
            "nothing",
        ),
    ] {
        let out = dicephys(&["compare", args[0], args[1]]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(err.contains(says) && err.lines().count() == 1, "{err}");
    }
}

// The promises every command keeps, kept by `fit`, `fit --recover` and `predict` (issue 34).

/// One 2D row: the cheapest data a fit can take.
fn counts(dir: &Path, extra: &str) -> PathBuf {
    let path = dir.join("counts.csv");
    std::fs::write(
        &path,
        format!("{HEAD}a,MDF,140,24,20,2d,0,361,639\nb,MDF,140,30,10,2d,0,40,460\n{extra}"),
    )
    .unwrap();
    path
}

/// A tiny fit's flags (e free, 8 points × 40 rolls a block, one pass, a coarse step).
fn tiny(data: &Path, out: &Path) -> Vec<String> {
    [
        "fit",
        "--data",
        data.to_str().unwrap(),
        "--free",
        "e",
        "--points",
        "8",
        "--degree",
        "2",
        "--max-degree",
        "2",
        "--rolls",
        "40",
        "--dt",
        "1/250",
        "--no-refine",
        "--out",
        out.to_str().unwrap(),
    ]
    .iter()
    .map(|s| s.to_string())
    .collect()
}

fn run(args: &[String]) -> Output {
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    dicephys(&args)
}

/// Class 1: a calibration command refuses a directory another command or run owns.
#[test]
fn a_fit_refuses_a_directory_another_run_owns() {
    let dir = Scratch::new("promise-own");
    let data = counts(&dir, "");
    // Another command's directory (its owner file as `paper` writes it) and its report.
    let paper = dir.join("paper");
    std::fs::create_dir_all(&paper).unwrap();
    std::fs::write(
        paper.join("dicephys-run.json"),
        r#"{"command":"paper","key":"0","config":{}}"#,
    )
    .unwrap();
    std::fs::write(paper.join("report.md"), "the paper's report").unwrap();
    refused(&run(&tiny(&data, &paper)), 2, "`paper` run");
    assert_eq!(
        std::fs::read_to_string(paper.join("report.md")).unwrap(),
        "the paper's report"
    );
    // A second fit with another seed on one --out.
    let out = dir.join("fit");
    let first = run(&tiny(&data, &out));
    assert!(first.status.success(), "{}", stderr(&first));
    let before = std::fs::read(out.join("fit.json")).unwrap();
    let mut other = tiny(&data, &out);
    other.extend(["--seed".into(), "7".into()]);
    refused(&run(&other), 2, "another `fit` run");
    assert_eq!(std::fs::read(out.join("fit.json")).unwrap(), before);
    // The same fit again continues (reads its cells back) and writes the same estimate.
    let again = run(&tiny(&data, &out));
    assert!(again.status.success(), "{}", stderr(&again));
    let v = |b: &[u8]| serde_json::from_slice::<serde_json::Value>(b).unwrap()["estimate"].clone();
    assert_eq!(v(&before), v(&std::fs::read(out.join("fit.json")).unwrap()));
    // A Slurm run's directory, and `fit --recover` and `paper --calibrated` in a sweep's.
    let slurm = dir.join("slurm");
    std::fs::create_dir_all(&slurm).unwrap();
    std::fs::write(slurm.join("slurm.json"), "{}").unwrap();
    refused(&run(&tiny(&data, &slurm)), 2, "Slurm run");
    let converge = dir.join("converge");
    std::fs::create_dir_all(&converge).unwrap();
    std::fs::write(
        converge.join("dicephys-run.json"),
        r#"{"command":"converge","key":"0","config":{}}"#,
    )
    .unwrap();
    let mut recover = tiny(&data, &converge);
    recover.extend([
        "--recover".into(),
        "e=0.4".into(),
        "--repeats".into(),
        "1".into(),
    ]);
    refused(&run(&recover), 2, "`converge` run");
    let (code, err, _) = timed(
        &["paper", "--calibrated", "--out", converge.to_str().unwrap()],
        Duration::from_secs(20),
    );
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("`converge` run"), "{err}");
}

/// Classes 2 and 3: a stop in the estimate ends `fit` at once with exit 130 and no fit.json;
/// the estimate says its stages; the same command then finishes, as an unstopped fit does.
#[test]
fn ctrl_c_in_the_estimate_stops_a_fit_at_once_and_it_resumes() {
    let dir = Scratch::new("promise-stop");
    let args = |out: &str| -> Vec<String> {
        [
            "fit",
            "--data",
            "paper",
            "--free",
            "e,mu",
            "--shared",
            "e,mu",
            "--points",
            "20",
            "--degree",
            "2",
            "--max-degree",
            "2",
            "--rolls",
            "20",
            "--dt",
            "1/250",
            "--no-refine",
            "--out",
        ]
        .iter()
        .map(|s| s.to_string())
        .chain([dir.join(out).display().to_string()])
        .collect()
    };
    let child = bin()
        .args(args("stopped"))
        .env("DICEPHYS_PROGRESS_SECS", "0")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Wait for the estimate's first line, then interrupt.
    let (code, seen, waited) = interrupt_after(child, "fit: the maximum");
    assert_eq!(code, Some(130), "{seen}");
    assert!(waited < Duration::from_secs(3), "stopped after {waited:?}");
    assert!(!dir.join("stopped/fit.json").exists());
    // Run again: it finishes, and its estimate is that of a fit never stopped.
    let resumed = run(&args("stopped"));
    assert!(resumed.status.success(), "{}", stderr(&resumed));
    let whole = run(&args("whole"));
    assert!(whole.status.success(), "{}", stderr(&whole));
    let read = |d: &str| -> serde_json::Value {
        serde_json::from_slice(&std::fs::read(dir.join(d).join("fit.json")).unwrap()).unwrap()
    };
    assert_eq!(read("stopped")["estimate"], read("whole")["estimate"]);
}

/// Reliability round 5, class H: a stop in the profiles of many parameters ends the fit at
/// once. Twelve surfaces with e and μ free each (24 parameters) on one thread: the profiles
/// take about 100 s here at 40 rolls a point (a minute at the 10 used, reached in 5 s where 40
/// took 15), and before the fix a Ctrl-C in them took 56 s to end the run (each profile
/// point's search spent its whole budget on a likelihood that had become +∞). The signal
/// follows the stage's own line, so the run is long by construction; the bound, 3 s, is one a
/// slow machine meets (5 ms here).
#[test]
fn ctrl_c_in_the_profiles_of_24_parameters_ends_the_fit_at_once() {
    let dir = Scratch::new("promise-profiles");
    let data = dir.join("twelve.csv");
    let mut csv = String::from(HEAD);
    for k in 0..12 {
        for (block, base) in [("140,24,20", 330), ("140,22,13", 180), ("140,30,10", 40)] {
            let b = base + 5 * k;
            let label = block.replace(',', "x");
            csv.push_str(&format!(
                "r{k}-{label},s{k},{block},2d,0,{b},{}\n",
                1000 - b
            ));
        }
    }
    std::fs::write(&data, csv).unwrap();
    let child = bin()
        .args(["fit", "--data"])
        .arg(&data)
        .args([
            "--free", "e,mu", "--points", "12", "--rolls", "10", "--degree", "2",
        ])
        .args([
            "--max-degree",
            "2",
            "--no-refine",
            "--threads",
            "1",
            "--dt",
            "1/250",
            "--out",
        ])
        .arg(dir.join("out"))
        .env("DICEPHYS_PROGRESS_SECS", "0")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let (code, seen, waited) = interrupt_after(child, "fit: the profiles of 24 parameters");
    assert_eq!(code, Some(130), "{seen}");
    assert!(waited < Duration::from_secs(3), "stopped after {waited:?}");
    assert!(!dir.join("out/fit.json").exists());
}

/// Class 2: a named pipe with no writer as `--data` does not hold off a SIGTERM.
#[test]
fn sigterm_while_waiting_on_a_pipe_ends_the_fit() {
    let dir = Scratch::new("promise-fifo");
    let fifo = dir.join("counts.csv");
    let path = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    assert_eq!(unsafe { libc::mkfifo(path.as_ptr(), 0o600) }, 0);
    let out = dir.join("out");
    let mut child = bin()
        .args([
            "fit",
            "--data",
            fifo.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(300));
    unsafe { libc::kill(child.id() as i32, libc::SIGTERM) };
    let code = wait_at_most(&mut child, Duration::from_secs(3));
    assert_eq!(code, Some(130));
    assert!(!out.exists());
}

/// Class 3: the bootstrap's cost does not grow with the counts (10¹¹ throws in a row).
#[test]
fn a_row_of_a_hundred_billion_throws_is_estimated_in_seconds() {
    let dir = Scratch::new("promise-big");
    let path = dir.join("big.csv");
    std::fs::write(
        &path,
        format!(
            "{HEAD}a,MDF,140,24,20,2d,0,36100000000,63900000000\nb,MDF,140,30,10,2d,0,40,460\n"
        ),
    )
    .unwrap();
    let args = tiny(&path, &dir.join("out"));
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let (code, err, took) = timed(&args, Duration::from_secs(60));
    assert_eq!(code, Some(0), "{err}");
    assert!(took < Duration::from_secs(30), "{took:?}");
    // Counts above the cap are refused at once.
    std::fs::write(
        &path,
        format!("{HEAD}a,MDF,140,24,20,2d,0,3610000000000,1\n"),
    )
    .unwrap();
    refused(
        &run(&tiny(&path, &dir.join("out2"))),
        2,
        "at most 1000000000000 throws",
    );
}

/// Class 4: `--threads 1` uses one core throughout, the estimate included: the process never
/// has more than its main thread, the signal handler's and one worker (a pool of rayon's own
/// would add one per core), and its CPU time stays within its wall time. The fit is run twice:
/// the second reads its cells back and spends its time in the estimate (profiles, bootstrap,
/// draws). Two blocks on one surface, not the paper's 19 rows: the estimate runs every one of
/// those stages either way, and on the paper's ten parameters it took 28 s of a single core
/// twice over (the suite's fourth-longest test) where a pool of rayon's own would show as a
/// fourth thread, or as CPU time past the wall time, within the first second.
#[test]
fn threads_one_is_one_core_in_the_estimate_too() {
    let dir = Scratch::new("promise-threads");
    let out = dir.join("out");
    let data = two_blocks(&dir);
    let args = [
        "fit",
        "--data",
        data.as_str(),
        "--free",
        "e,mu",
        "--points",
        "20",
        "--degree",
        "2",
        "--max-degree",
        "2",
        "--rolls",
        "5",
        "--dt",
        "1/250",
        "--no-refine",
        "--threads",
        "1",
        "--out",
        out.to_str().unwrap(),
    ];
    assert!(dicephys(&args).status.success());
    let mut child = bin()
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let (t, mut most) = (Instant::now(), 0);
    let tasks = format!("/proc/{}/task", child.id());
    // The child's CPU time, from its own /proc/PID/stat (utime and stime, in clock ticks).
    let stat = format!("/proc/{}/stat", child.id());
    let tick = unsafe { libc::sysconf(libc::_SC_CLK_TCK) } as f64;
    let mut cpu = 0.0;
    while child.try_wait().unwrap().is_none() {
        if let Ok(d) = std::fs::read_dir(&tasks) {
            most = most.max(d.count());
        }
        if let Ok(s) = std::fs::read_to_string(&stat) {
            let f: Vec<&str> = s.rsplit(')').next().unwrap().split_whitespace().collect();
            cpu = (f[11].parse::<f64>().unwrap() + f[12].parse::<f64>().unwrap()) / tick;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let wall = t.elapsed().as_secs_f64();
    assert!(out.join("fit.json").exists());
    assert!(most <= 3, "{most} threads at once");
    // Two busy cores would give CPU ≈ 2 × wall; a clock tick (10 ms) of slack on the CPU
    // time keeps a short run on a fast machine from failing on the tick's rounding.
    let tick_slack = 2.0 / tick;
    assert!(
        cpu <= 1.1 * wall + tick_slack,
        "CPU {cpu} s in {wall} s wall"
    );
}

/// Class 5: inputs are read through a cap, and a long counts file is read in linear time.
#[test]
fn inputs_are_capped_and_long_files_read_fast() {
    let dir = Scratch::new("promise-cap");
    let limited = |args: &str| {
        Command::new("bash")
            .arg("-c")
            .arg(format!(
                "ulimit -v 4000000; exec '{}' {args}",
                bin().get_program().to_str().unwrap()
            ))
            .output()
            .unwrap()
    };
    let o = limited(&format!(
        "fit --data /dev/zero --out '{}'",
        dir.join("a").display()
    ));
    refused(&o, 2, "larger than 16 MiB");
    let o = limited("predict --fit /dev/zero --block 140x24x20");
    refused(&o, 2, "larger than 64 MiB");
    // 100,000 rows: read (and refused for their size of fit) in well under a second's work.
    let mut text = HEAD.to_string();
    for i in 0..100_000 {
        text.push_str(&format!("r{i},MDF,140,24,20,2d,0,3,6\n"));
    }
    text.push_str("bad,MDF,140,24,20,2d,0,x,6\n");
    let path = dir.join("long.csv");
    std::fs::write(&path, text).unwrap();
    let t = Instant::now();
    let o = dicephys(&["fit", "--data", path.to_str().unwrap()]);
    refused(&o, 2, "line 100002, column 8");
    assert!(t.elapsed() < Duration::from_secs(5), "{:?}", t.elapsed());
}

/// Class 10: counts-file errors on one line, at the true line, control characters escaped,
/// invalid UTF-8 located.
#[test]
fn counts_file_errors_name_the_true_line() {
    let dir = Scratch::new("promise-lines");
    let path = dir.join("c.csv");
    let cases: [(&[u8], &str); 5] = [
        (
            b"label,surface,length_mm,breadth_mm,width_mm,mode,length_vertical,breadth_vertical,width_vertical\r\na,MDF,140,24,20,2d,0,1,1\r\nb,MDF,140,24,20,2d,0,x,1\r\n",
            "line 3, column 8",
        ),
        (
            b"label,surface,length_mm,breadth_mm,width_mm,mode,length_vertical,breadth_vertical,width_vertical\na,MDF,140,24,20,2d,0,1,1\n\n\nb,MDF,140,24,20,2d,0,x,1\n",
            "line 5, column 8",
        ),
        (
            b"label,surface,length_mm,breadth_mm,width_mm,mode,length_vertical,breadth_vertical,width_vertical\n\"a\nb\",MDF,140,24,20,2d,0,1,1\nc,MDF,140,24,20,2d,0,x,1\n",
            "line 2, column 1 (label): 'a\\nb' holds a control character",
        ),
        (
            b"label,surface,length_mm,breadth_mm,width_mm,mode,length_vertical,breadth_vertical,width_vertical\na,MDF,140,24,20,2d,0,\x1b[31mred,1\n",
            "\\u{1b}[31mred",
        ),
        (
            b"label,surface,length_mm,breadth_mm,width_mm,mode,length_vertical,breadth_vertical,width_vertical\na,MDF,140,24,20,2d,0,1,1\nb,M\xffDF,140,24,20,2d,0,1,1\n",
            "line 3, byte 4",
        ),
    ];
    for (text, says) in cases {
        std::fs::write(&path, text).unwrap();
        let o = dicephys(&["fit", "--data", path.to_str().unwrap()]);
        refused(&o, 2, says);
        assert!(!stderr(&o).contains('\x1b'), "{}", stderr(&o));
    }
}

/// Classes 9, 13 and 14: a name given twice, a flag that does not apply, a count out of range.
#[test]
fn names_twice_flags_that_do_not_apply_and_counts_out_of_range_are_refused() {
    let dir = Scratch::new("promise-twice");
    let data = counts(&dir, "");
    let d = data.to_str().unwrap();
    let out = dir.join("o");
    let o = out.to_str().unwrap();
    for (args, says) in [
        (
            vec![
                "fit",
                "--data",
                d,
                "--free",
                "e",
                "--recover",
                "e=0.3,e=0.6",
                "--out",
                o,
            ],
            "twice",
        ),
        (
            vec![
                "fit",
                "--data",
                d,
                "--free",
                "e",
                "--range",
                "e=0.1:0.5",
                "--range",
                "e=0.3:0.7",
                "--out",
                o,
            ],
            "twice",
        ),
        (
            vec!["fit", "--data", d, "--free", "e,mu,e", "--out", o],
            "twice",
        ),
        (
            vec![
                "roll",
                "--block",
                "140x24x20",
                "--throw",
                "rest",
                "--velocity",
                "50:60",
            ],
            "--throw rest",
        ),
        (
            vec![
                "crosscheck",
                "--block",
                "140x24x20",
                "--engines",
                "bullet,bullet",
            ],
            "--engines",
        ),
    ] {
        let r = dicephys(&args);
        refused(&r, 2, says);
    }
    assert!(!out.exists());
    let fit = good_fit(&dir);
    let r = dicephys(&[
        "predict",
        "--fit",
        fit.to_str().unwrap(),
        "--block",
        "140x27x13",
        "--rolls",
        "2000000000",
    ]);
    refused(&r, 2, "--rolls 2000000000: from 1 to 1000000000");
}

/// Class 7: a fit whose rolls did not settle is refused; a prediction never gives
/// probabilities that do not sum to one.
#[test]
fn a_fit_of_unsettled_rolls_is_refused_and_predict_never_sums_to_zero() {
    let dir = Scratch::new("promise-unsettled");
    let data = counts(&dir, "");
    let mut args = tiny(&data, &dir.join("a"));
    args.extend(["--max-steps".into(), "3".into()]);
    let o = run(&args);
    refused(&o, 1, "did not settle");
    assert!(stderr(&o).contains("--max-steps"), "{}", stderr(&o));
    assert!(!dir.join("a/fit.json").exists());
    // A good fit, its step cap edited to 3 and sealed again: predict refuses to give zeros.
    let fit = good_fit(&dir);
    let mut v: serde_json::Value = serde_json::from_slice(&std::fs::read(&fit).unwrap()).unwrap();
    v["config"]["method"]["max_steps"] = 3.into();
    let edited = dir.join("edited.json");
    std::fs::write(&edited, dicephys::run::seal::to_string(&v, true).unwrap()).unwrap();
    let o = dicephys(&[
        "predict",
        "--fit",
        edited.to_str().unwrap(),
        "--block",
        "140x27x13",
        "--2d",
        "--draws",
        "2",
        "--rolls",
        "20",
    ]);
    refused(&o, 1, "settled");
}

/// A good tiny fit's fit.json (under `dir/good`).
fn good_fit(dir: &Path) -> PathBuf {
    let data = counts(dir, "");
    let out = dir.join("good");
    let o = run(&tiny(&data, &out));
    assert!(o.status.success(), "{}", stderr(&o));
    out.join("fit.json")
}

/// Class 8: fit.json is sealed: an edited or damaged file is refused by name, never a panic.
#[test]
fn predict_refuses_an_edited_or_emptied_fit() {
    let dir = Scratch::new("promise-seal");
    let fit = good_fit(&dir);
    let predict = |f: &Path| {
        dicephys(&[
            "predict",
            "--fit",
            f.to_str().unwrap(),
            "--block",
            "140x27x13",
            "--2d",
            "--draws",
            "2",
            "--rolls",
            "20",
        ])
    };
    let mut v: serde_json::Value = serde_json::from_slice(&std::fs::read(&fit).unwrap()).unwrap();
    v["config"]["model"]["fixed"]["mu"] = 0.9.into();
    let edited = dir.join("edited.json");
    std::fs::write(&edited, serde_json::to_string_pretty(&v).unwrap()).unwrap();
    refused(&predict(&edited), 2, "checksum");
    // Emptied draws, sealed again: refused with a reason, not a panic.
    v["config"]["model"]["fixed"]["mu"] = 0.29.into();
    v["estimate"]["draws"] = serde_json::json!([[], []]);
    std::fs::write(&edited, dicephys::run::seal::to_string(&v, true).unwrap()).unwrap();
    refused(&predict(&edited), 2, "draws");
    // Draws outside the unit box, sealed again.
    v["estimate"]["draws"] = serde_json::json!([[1.5], [0.5]]);
    std::fs::write(&edited, dicephys::run::seal::to_string(&v, true).unwrap()).unwrap();
    refused(&predict(&edited), 2, "draws");
}

/// Class 12: `predict` refuses a thrower or surface the fit does not have, and says when a
/// block lies outside the blocks the fit saw.
#[test]
fn predict_refuses_what_the_fit_has_not_and_names_an_extrapolation() {
    let dir = Scratch::new("promise-predict");
    let fit = good_fit(&dir);
    let f = fit.to_str().unwrap();
    let r = dicephys(&[
        "predict",
        "--fit",
        f,
        "--block",
        "140x27x13",
        "--thrower",
        "bob",
    ]);
    refused(&r, 2, "thrower 'bob' is not in the fit");
    let p = crate::helpers::json(&dicephys(&[
        "predict",
        "--fit",
        f,
        "--block",
        "400x27x13",
        "--2d",
        "--draws",
        "2",
        "--rolls",
        "40",
        "--json",
    ]));
    let x = p["extrapolation"].as_str().unwrap_or_default();
    assert!(x.contains("length 400"), "{p}");
    assert_eq!(p["thrower"], "all");
    assert_eq!(p["p"].as_array().unwrap().len(), 3);
    let inside = crate::helpers::json(&dicephys(&[
        "predict",
        "--fit",
        f,
        "--block",
        "140x27x13",
        "--2d",
        "--draws",
        "2",
        "--rolls",
        "40",
        "--json",
    ]));
    assert!(inside["extrapolation"].is_null(), "{inside}");
}
