//! Scratch: the fit's recovery of known parameters at a chosen size (args: points rolls reps dt free...).
use dicephys::calibration::design::DesignSpec;
use dicephys::calibration::estimate::Search;
use dicephys::calibration::params::{Fixed, Kind, Method, ModelSpec};
use dicephys::calibration::{data, FitConfig};
use dicephys::engine::EngineKind;
use dicephys::run::runner::Runner;
use dicephys::run::stop::Stop;
use dicephys::studies::fit::recovery;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let points: usize = a[1].parse().unwrap();
    let rolls: u64 = a[2].parse().unwrap();
    let reps: usize = a[3].parse().unwrap();
    let dt: f64 = a[4].parse().unwrap();
    let degree: usize = a[5].parse().unwrap();
    let text = "label,surface,length_mm,breadth_mm,width_mm,mode,length_vertical,breadth_vertical,width_vertical\n\
a,S,140,24,20,3d,0,400,600\nb,S,140,30,10,3d,0,50,950\nc,S,99.3,43.9,43.2,3d,20,1000,980\n";
    let rows = data::parse(text, "x").unwrap();
    let free = vec![Kind::E, Kind::Mu, Kind::Kappa];
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
            dt,
            max_steps: 20_000_000,
        },
        design: DesignSpec {
            points,
            rolls,
            degree,
            max_degree: degree + 1,
        },
        search: Search {
            draws: 200,
            ..Search::default()
        },
        seed: 7,
    };
    let t = std::time::Instant::now();
    let r = recovery::run(&cfg, &[0.5, 0.3, 30.0], reps, &Runner::new(0, Stop::new()))
        .unwrap()
        .unwrap();
    for rep in &r.repetitions {
        println!(
            "delta {:.2} covered {} {:?} {:?}",
            rep.truth_delta,
            rep.covered,
            rep.in_interval,
            rep.values
                .iter()
                .map(|v| format!("{v:.3}"))
                .collect::<Vec<_>>()
        );
    }
    println!(
        "coverage {} intervals {:?} region {:.2} rolls {} wall {:.1}s",
        r.coverage,
        r.interval_coverage,
        r.region_delta,
        r.rolls,
        t.elapsed().as_secs_f64()
    );
}
