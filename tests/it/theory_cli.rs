//! `dicephys theory` run as a user runs it: the built binary, its stdout, stderr and exit code.

use std::process::Output;

use super::helpers::dicephys;

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn json(args: &[&str]) -> serde_json::Value {
    let o = dicephys(args);
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    serde_json::from_slice(&o.stdout).expect("stdout is one JSON document")
}

fn num(v: &serde_json::Value, path: &[&str]) -> f64 {
    let mut v = v;
    for p in path {
        v = &v[*p];
    }
    v.as_f64()
        .unwrap_or_else(|| panic!("{path:?} is not a number: {v}"))
}

#[test]
fn block_text_has_r_and_the_ratio() {
    let o = dicephys(&["theory", "--block", "140x24x20"]);
    assert!(o.status.success());
    let text = stdout(&o);
    let line = |key: &str| {
        text.lines()
            .find(|l| l.contains(key))
            .unwrap_or_else(|| panic!("no line with {key} in\n{text}"))
            .to_string()
    };
    assert!(
        line("R = width/breadth").contains("0.833 ± 0.005"),
        "{text}"
    );
    assert!(line("ratio B/W").contains("0.511"), "{text}");
    assert!(text.contains("140x24x20"));
    assert!(text.contains("3D Simpson"));
    assert!(o.stderr.is_empty());
}

#[test]
fn block_json_has_the_fields() {
    let v = json(&["theory", "--block", "140x24x20", "--json"]);
    assert_eq!(num(&v, &["block", "length_mm"]), 140.0);
    assert_eq!(num(&v, &["block", "breadth_mm"]), 24.0);
    assert_eq!(num(&v, &["block", "width_mm"]), 20.0);
    assert_eq!(num(&v, &["tolerance_mm"]), 0.1);
    assert!((num(&v, &["r", "value"]) - 0.8333).abs() < 1e-4);
    assert!((num(&v, &["r", "err"]) - 0.0054).abs() < 1e-4);
    let ratio = num(&v, &["theory_2d", "ratio", "value"]);
    assert!((ratio - 0.511).abs() < 0.0005);
    assert!(num(&v, &["theory_2d", "ratio", "err"]) > 0.0);
    let pb = num(&v, &["theory_2d", "p_breadth_vertical"]);
    let pw = num(&v, &["theory_2d", "p_width_vertical"]);
    assert!((pb + pw - 1.0).abs() < 1e-12 && (pb / pw - ratio).abs() < 1e-12);
    assert!(num(&v, &["theory_2d", "p_err"]) > 0.0);
    let nb = num(&v, &["no_bounce_2d", "ratio"]);
    assert!(ratio < nb && nb < 1.0);
    assert!(num(&v, &["no_bounce_2d", "p_breadth_vertical"]) > pb);
    let s: f64 = [
        "p_breadth_vertical",
        "p_width_vertical",
        "p_length_vertical",
    ]
    .iter()
    .map(|k| num(&v, &["simpson_3d", k]))
    .sum();
    assert!((s - 1.0).abs() < 1e-12);
}

#[test]
fn tolerance_changes_only_the_errors() {
    let a = json(&[
        "theory",
        "--block",
        "140x24x20",
        "--json",
        "--tolerance",
        "0",
    ]);
    assert_eq!(num(&a, &["r", "err"]), 0.0);
    assert_eq!(num(&a, &["theory_2d", "ratio", "err"]), 0.0);
    let b = json(&[
        "theory",
        "--block",
        "140x24x20",
        "--json",
        "--tolerance",
        "0.2",
    ]);
    assert_eq!(
        num(&a, &["theory_2d", "ratio", "value"]),
        num(&b, &["theory_2d", "ratio", "value"])
    );
    assert!(num(&b, &["theory_2d", "ratio", "err"]) > 0.02);
}

#[test]
fn table_json_has_19_rows_and_one_discrepancy() {
    let v = json(&["theory", "--table", "--json"]);
    let rows = v["rows"].as_array().expect("rows");
    assert_eq!(rows.len(), 19);
    for (i, r) in rows.iter().enumerate() {
        assert_eq!(r["row"].as_u64(), Some(i as u64 + 1));
        for k in ["theory_ratio", "measured_ratio", "r"] {
            assert!(
                r[k]["value"].is_f64() && r[k]["err"].is_f64(),
                "row {i} {k}"
            );
        }
        assert!(r["z"].is_f64() && r["no_bounce_ratio"].is_f64());
    }
    assert_eq!(rows[6]["surface"], "mdf");
    assert_eq!(rows[6]["set"], "mdf");
    assert_eq!(rows[6]["simulated"], true);
    let d = v["discrepancies"].as_array().expect("discrepancies");
    assert_eq!(d.len(), 1, "{d:#?}");
    assert_eq!(d[0]["row"], 7);
    assert_eq!(d[0]["field"], "ratio");
    assert_eq!(d[0]["printed"]["value"], 0.54);
    assert!((d[0]["recomputed"].as_f64().unwrap() - 0.5649).abs() < 1e-4);
    let sets: Vec<&str> = v["chi_square"]
        .as_array()
        .expect("chi_square")
        .iter()
        .map(|c| c["set"].as_str().unwrap())
        .collect();
    assert_eq!(sets, ["pine", "mdf", "carpet"]);
    assert!(v["errors_rounded_up"].as_array().is_some());
}

#[test]
fn table_text_reports_the_discrepancy() {
    let o = dicephys(&["theory", "--table"]);
    assert!(o.status.success());
    let text = stdout(&o);
    assert!(
        text.contains("row 7 (140x24x20 MDF): printed ratio 0.54, counts give 0.565"),
        "{text}"
    );
    assert!(text.contains("chi2"));
}

#[test]
fn bad_input_is_one_line_and_exit_2() {
    for args in [
        &["theory", "--block", "0x24x20"][..],
        &["theory", "--block", "abc"],
        &["theory", "--block", "-5x2x1"],
        &["theory", "--block", "NaNx1x1"],
        &["theory", "--block", "140x24x20", "--table"],
        &["theory"],
        &["theory", "--block", "140x24x20", "--tolerance", "-1"],
        &["theory", "--block", "140x24x20", "--tolerance", "inf"],
        &["theory", "--table", "--tolerance", "0.2"],
    ] {
        let o = dicephys(args);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
        assert!(err.starts_with("dicephys: "), "{args:?}: {err}");
        assert!(o.stdout.is_empty(), "{args:?}");
    }
}

#[test]
fn the_markov_chain_absorbs_to_the_theory_ratio() {
    for block in ["140x24x20", "140x30x10", "100x50x49"] {
        let v = json(&["theory", "--block", block, "--json"]);
        let chain = num(&v, &["markov_2d", "ratio"]);
        let theory = num(&v, &["theory_2d", "ratio", "value"]);
        assert!(
            (chain - theory).abs() < 1e-12,
            "{block}: {chain} vs {theory}"
        );
        let p = num(&v, &["markov_2d", "p_k"]) + num(&v, &["markov_2d", "p_l"]);
        assert!((p - 1.0).abs() < 1e-12, "{block}: P(K) + P(L) = {p}");
    }
}
