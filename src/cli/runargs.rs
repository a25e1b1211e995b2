//! A run's own command line, kept with its checkpoint and its output: what `--resume` replays
//! and what `merge` compares. Options that do not change the result are left out.

/// Options that change how a run is carried out or reported, not its result.
const INCIDENTAL: &[(&str, bool)] = &[
    ("--threads", true),
    ("--json", false),
    ("--per-roll", true),
    ("--checkpoint", true),
    ("--resume", true),
];

/// `args` (after the subcommand) without the options named in `drop` (with their values).
pub fn without(args: &[String], drop: &[(&str, bool)]) -> Vec<String> {
    let mut out = Vec::new();
    let mut skip_value = false;
    for a in args {
        if skip_value {
            skip_value = false;
            continue;
        }
        let name = a.split('=').next().unwrap_or(a);
        match drop.iter().find(|(n, _)| *n == name) {
            Some((_, takes_value)) => skip_value = *takes_value && !a.contains('='),
            None => out.push(a.clone()),
        }
    }
    out
}

/// The result-defining arguments of this process's subcommand.
pub fn defining(args: &[String]) -> Vec<String> {
    without(args, INCIDENTAL)
}

/// The same, without the shard: equal for every shard of one run.
pub fn defining_unsharded(args: &[String]) -> Vec<String> {
    without(&defining(args), &[("--shard", true)])
}

/// The command line as parsed (after `--resume` was expanded into the stored run's own).
pub static EFFECTIVE: std::sync::OnceLock<Vec<String>> = std::sync::OnceLock::new();

/// The parsed command line's arguments after the subcommand.
pub fn current() -> Vec<String> {
    match EFFECTIVE.get() {
        Some(a) => a.iter().skip(2).cloned().collect(),
        None => std::env::args().skip(2).collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(s: &str) -> Vec<String> {
        s.split_whitespace().map(String::from).collect()
    }

    #[test]
    fn drops_incidental_options_and_their_values() {
        let a = v("--block 140x24x20 --threads 2 --json --per-roll x.csv --checkpoint=d --shard 1/3 --rolls 9");
        assert_eq!(defining(&a), v("--block 140x24x20 --shard 1/3 --rolls 9"));
        assert_eq!(defining_unsharded(&a), v("--block 140x24x20 --rolls 9"));
    }
}
