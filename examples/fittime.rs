//! Scratch: time the phases of a fit (args: csv points rolls dt degree).
use dicephys::calibration::design::DesignSpec;
use dicephys::calibration::estimate::Search;
use dicephys::calibration::params::{Fixed, Kind, Method, ModelSpec};
use dicephys::calibration::{data, estimate_with, FitConfig};
use dicephys::engine::EngineKind;
use dicephys::run::runner::Runner;
use dicephys::run::stop::Stop;
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let rows = data::parse(&std::fs::read_to_string(&a[1]).unwrap(), "x").unwrap();
    let free: Vec<Kind> = a[6].split(',').map(|k| k.parse().unwrap()).collect();
    let cfg = FitConfig {
        rows,
        model: ModelSpec {
            ranges: free.iter().map(|k| k.default_range()).collect(),
            free,
            shared: vec![],
            fixed: Fixed::default(),
        },
        method: Method {
            engine: EngineKind::Bullet,
            dt: a[4].parse().unwrap(),
            max_steps: 20_000_000,
        },
        design: DesignSpec {
            points: a[2].parse().unwrap(),
            rolls: a[3].parse().unwrap(),
            degree: a[5].parse().unwrap(),
            max_degree: a[5].parse().unwrap(),
        },
        search: Search::default(),
        seed: 1,
    };
    let t = std::time::Instant::now();
    let d = dicephys::studies::fit::simulate(&cfg, &Runner::new(0, Stop::new()), None)
        .unwrap()
        .unwrap();
    eprintln!("simulate {:.1}s", t.elapsed().as_secs_f64());
    let t = std::time::Instant::now();
    let (_, e) = estimate_with(&cfg.rows, &cfg.model, &d, &cfg.search).unwrap();
    eprintln!(
        "estimate {:.1}s  f {:.2}",
        t.elapsed().as_secs_f64(),
        e.minus_two_ln_l
    );
}
