//! Scratch: one recovery repetition in detail (args: points rolls dt degree seed).
use dicephys::calibration::design::keys;
use dicephys::calibration::design::DesignSpec;
use dicephys::calibration::estimate::{row_fits, Likelihood, Search};
use dicephys::calibration::estimate_with;
use dicephys::calibration::params::{Fixed, Kind, Method, ModelSpec};
use dicephys::calibration::{data, FitConfig};
use dicephys::engine::EngineKind;
use dicephys::run::runner::Runner;
use dicephys::run::stop::Stop;
use dicephys::studies::fit::recovery;
use dicephys::studies::fit::simulate::{self as design, Plan};

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let points: usize = a[1].parse().unwrap();
    let rolls: u64 = a[2].parse().unwrap();
    let dt: f64 = a[3].parse().unwrap();
    let degree: usize = a[4].parse().unwrap();
    let seed: u64 = a[5].parse().unwrap();
    let text = "label,surface,length_mm,breadth_mm,width_mm,mode,length_vertical,breadth_vertical,width_vertical\n\
a,S,140,24,20,3d,0,400,600\nb,S,140,30,10,3d,0,50,950\nc,S,99.3,43.9,43.2,3d,20,1000,980\n";
    let rows = data::parse(text, "x").unwrap();
    let free = vec![Kind::E, Kind::Mu, Kind::Kappa];
    let model = ModelSpec {
        ranges: free.iter().map(|k| k.default_range()).collect(),
        free,
        shared: vec![],
        fixed: Fixed::default(),
    };
    let cfg = FitConfig {
        rows,
        model: model.clone(),
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
            draws: 100,
            ..Search::default()
        },
        seed,
    };
    let runner = Runner::new(0, Stop::new());
    let x_true = vec![
        Kind::E.coordinate(Kind::E.default_range(), 0.5),
        Kind::Mu.coordinate(Kind::Mu.default_range(), 0.3),
        Kind::Kappa.coordinate(Kind::Kappa.default_range(), 30.0),
    ];
    let truth = model.values(&x_true);
    let data = recovery::simulate_data(&cfg, &truth, seed ^ 0x5eed_da7a, &runner)
        .unwrap()
        .unwrap();
    let plan = Plan {
        model: &model,
        method: &cfg.method,
        design: &cfg.design,
        seed,
    };
    let designs = design::simulate(&plan, &keys(&data), &runner, None)
        .unwrap()
        .unwrap();
    for d in &designs {
        println!(
            "{}: degree {} LOF p {:.3} disp {:.2}",
            d.name(),
            d.surrogate.degree,
            d.surrogate.lack_of_fit_p(),
            d.surrogate.dispersion
        );
    }
    let (params, est) = estimate_with(&data, &model, &designs, &cfg.search).unwrap();
    let lik = Likelihood::new(&data, &designs, &model, &params);
    println!(
        "f(truth) {:.2} f(min) {:.2} at {:?}",
        lik.minus_two_ln_l(&x_true),
        est.minus_two_ln_l,
        est.params
            .iter()
            .map(|p| format!("{:.3}", p.value))
            .collect::<Vec<_>>()
    );
    println!(
        "bartlett {:.2} region {:.2}",
        est.bartlett, est.region_delta
    );
    for (which, x) in [("truth", &x_true), ("mle", &est.x)] {
        for r in row_fits(&lik, x) {
            println!(
                "  {which} {}: counts {:?} p {:?} err {:?} z {:?} chi2 {:.2}",
                r.label,
                r.counts,
                r.p.iter().map(|v| format!("{v:.4}")).collect::<Vec<_>>(),
                r.p_err
                    .iter()
                    .map(|v| format!("{v:.4}"))
                    .collect::<Vec<_>>(),
                r.z.iter().map(|v| format!("{v:.2}")).collect::<Vec<_>>(),
                r.chi2
            );
        }
    }
    for p in &est.params {
        println!(
            "{} {:.3} 1σ {:?} 2σ {:?} {:?}",
            p.name, p.value, p.one_sigma, p.two_sigma, p.identified
        );
    }
}
