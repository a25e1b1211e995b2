//! Tests of `paper_data`.

use super::*;

fn table() -> PaperTable {
    load().expect("the shipped table parses")
}

#[test]
fn all_19_rows_load() {
    let t = table();
    assert_eq!(t.rows.len(), 19);
    for (i, r) in t.rows.iter().enumerate() {
        assert_eq!(r.row, i + 1);
    }
    let counts = |s| t.set(s).count();
    assert_eq!(
        (counts(Set::Pine), counts(Set::Mdf), counts(Set::Carpet)),
        (6, 8, 5)
    );
    let total: u64 = t.rows.iter().map(|r| r.throws).sum();
    assert_eq!(total, 16_300);
}

#[test]
fn ditto_marks_are_resolved() {
    let t = table();
    let r2 = &t.rows[1];
    assert_eq!((r2.breadth_mm.value, r2.width_mm.value), (25.0, 18.0));
    assert_eq!(
        (r2.block, r2.surface, r2.set),
        (Material::Pine, Surface::Carpet, Set::Pine)
    );
    assert_eq!(t.rows[3].surface, Surface::ThinTowel);
    let r13 = &t.rows[12];
    assert_eq!((r13.length_mm.value, r13.length_mm.decimals), (140.0, 1));
    assert_eq!((r13.block, r13.surface), (Material::Printed, Surface::Mdf));
    assert_eq!(t.rows[18].surface, Surface::ToughCarpet);
    let extra: Vec<usize> = t
        .rows
        .iter()
        .filter(|r| r.extra_length)
        .map(|r| r.row)
        .collect();
    assert_eq!(extra, [2, 8, 9, 11]);
}

#[test]
fn simulated_rows_are_the_five_red_140mm_blocks() {
    let t = table();
    let sim: Vec<String> = t
        .rows
        .iter()
        .filter(|r| r.simulated)
        .map(|r| r.block_dims().unwrap().to_string())
        .collect();
    assert_eq!(
        sim,
        [
            "140x24x20",
            "140x22x13",
            "140x27x13",
            "140x29x11",
            "140x30x10"
        ]
    );
    assert!(t
        .rows
        .iter()
        .filter(|r| r.simulated)
        .all(|r| r.set == Set::Mdf && r.surface == Surface::Mdf));
}

#[test]
fn the_check_finds_exactly_the_known_discrepancy() {
    let t = table();
    assert_eq!(t.discrepancies.len(), 1, "{:#?}", t.discrepancies);
    let d = &t.discrepancies[0];
    assert_eq!((d.row, d.field), (7, "ratio"));
    assert_eq!(d.label, "140x24x20 MDF");
    assert_eq!(d.printed.value, 0.54);
    assert!((d.recomputed - 361.0 / 639.0).abs() < 1e-15);
    assert_eq!(
        d.describe(),
        "row 7 (140x24x20 MDF): printed ratio 0.54, counts give 0.565"
    );
}

/// The paper's errors are rounded to nearest or up. This pins which ones were rounded up,
/// so a change in the data or the arithmetic shows.
#[test]
fn errors_rounded_up_are_listed() {
    let t = table();
    let up: Vec<(usize, &str)> = t.rounded_up.iter().map(|d| (d.row, d.field)).collect();
    assert_eq!(
        up,
        [
            (1, "ratio_err"),
            (1, "predicted_ratio_err"),
            (2, "ratio_err"),
            (2, "predicted_ratio_err"),
            (3, "predicted_ratio_err"),
            (6, "ratio_err"),
            (7, "predicted_ratio_err"),
            (8, "predicted_ratio_err"),
            (9, "ratio_err"),
            (9, "predicted_ratio_err"),
            (11, "ratio_err"),
            (15, "ratio_err"),
            (15, "predicted_ratio_err"),
            (19, "ratio_err"),
        ]
    );
}

#[test]
fn predictions_and_errors_follow_from_the_dimensions() {
    // Every one of the 19 printed R ± σ_R and predicted ratios ± errors, recomputed from the
    // printed dimensions and their ± (e.g. 61.7 ± 0.4): values to nearest, errors to nearest
    // or rounded up.
    for row in table().rows {
        let p = row.theory();
        assert_eq!(rounding(row.r, p.r), Rounding::Nearest, "row {} R", row.row);
        assert_eq!(
            rounding(row.predicted_ratio, p.ratio),
            Rounding::Nearest,
            "row {} ratio",
            row.row
        );
        assert_ne!(
            rounding(row.r_err, p.r_err),
            Rounding::Off,
            "row {} σR",
            row.row
        );
        assert_ne!(
            rounding(row.predicted_ratio_err, p.ratio_err),
            Rounding::Off,
            "row {} σ ratio {} vs {}",
            row.row,
            p.ratio_err,
            row.predicted_ratio_err
        );
    }
}

#[test]
fn counts_sum_to_throws() {
    for row in table().rows {
        assert_eq!(
            row.length_vertical + row.breadth_vertical + row.width_vertical,
            row.throws
        );
    }
}

#[test]
fn rounding_rule() {
    let p = |s| PrintedNumber::parse(s).unwrap();
    assert_eq!(rounding(p("0.04"), 0.0372), Rounding::Nearest);
    assert_eq!(rounding(p("0.04"), 0.0450), Rounding::Nearest);
    assert_eq!(rounding(p("0.04"), 0.0451), Rounding::Off);
    assert_eq!(rounding(p("0.03"), 0.0243), Rounding::Up);
    assert_eq!(rounding(p("0.03"), 0.0200), Rounding::Off);
    assert_eq!(rounding(p("0.02"), 0.0372), Rounding::Off);
    assert_eq!(rounding(p("0.54"), 0.5649), Rounding::Off);
    assert_eq!(rounding(p("0.070"), 0.06992), Rounding::Nearest);
}

#[test]
fn printed_numbers_keep_their_decimals() {
    let n = PrintedNumber::parse("0.070").unwrap();
    assert_eq!(
        (n.value, n.decimals, n.to_string()),
        (0.07, 3, "0.070".to_string())
    );
    assert_eq!(PrintedNumber::parse("782").unwrap().decimals, 0);
    for bad in ["", "1.", ".5", "1e3", "NaN", "0x1", "1.2.3", "-"] {
        assert!(PrintedNumber::parse(bad).is_none(), "{bad}");
    }
}

#[test]
fn altered_data_is_reported_not_fixed() {
    // Break row 10's throws and row 19's printed error, and a predicted value.
    let text = PAPER_TABLE_CSV
        .replace("1000,0,160,840,0.19,0.02", "1001,0,160,840,0.19,0.02")
        .replace("1957,0.022,0.004", "1957,0.022,0.002")
        .replace(
            "0.591,0.005,0.146,0.005,Printed,Tough",
            "0.591,0.005,0.148,0.005,Printed,Tough",
        );
    let t = parse(&text).unwrap();
    let found: Vec<(usize, &str)> = t.discrepancies.iter().map(|d| (d.row, d.field)).collect();
    assert_eq!(
        found,
        [
            (7, "ratio"),
            (10, "throws"),
            (16, "predicted_ratio"),
            (19, "ratio_err")
        ]
    );
    assert_eq!(t.rows.len(), 19);
    assert_eq!(t.rows[9].throws, 1001);
}

#[test]
fn malformed_data_is_an_error() {
    assert!(parse("").is_err());
    assert!(parse("row,length_mm\n1,2").is_err());
    let short = PAPER_TABLE_CSV.replace(",Pine,Carpet,pine,false,800", ",Pine,Carpet,pine,800");
    assert!(parse(&short).is_err());
    let bad_surface = PAPER_TABLE_CSV.replace("Towel+Rug", "Lino");
    assert!(parse(&bad_surface).is_err());
    let bad_count = PAPER_TABLE_CSV.replace(",46,154,", ",4.6,154,");
    assert!(parse(&bad_count).is_err());
}
