//! Scratch: where a block's surrogate misses (args: block points rolls dt degree).
use dicephys::calibration::design::DesignSpec;
use dicephys::calibration::params::{Fixed, Kind, Method, ModelSpec};
use dicephys::engine::EngineKind;
use dicephys::inference::surrogate::Surrogate;
use dicephys::run::runner::Runner;
use dicephys::run::stop::Stop;
use dicephys::studies::fit::simulate::{self as design, Plan};

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let b = a[1].parse().unwrap();
    let points: usize = a[2].parse().unwrap();
    let rolls: u64 = a[3].parse().unwrap();
    let dt: f64 = a[4].parse().unwrap();
    let deg: usize = a[5].parse().unwrap();
    let free = vec![Kind::E, Kind::Mu, Kind::Kappa];
    let model = ModelSpec {
        ranges: free.iter().map(|k| k.default_range()).collect(),
        free,
        shared: vec![],
        fixed: Fixed::default(),
    };
    let method = Method {
        engine: EngineKind::Bullet,
        dt,
        max_steps: 20_000_000,
    };
    let ds = DesignSpec {
        points,
        rolls,
        degree: deg,
        max_degree: deg,
    };
    let runner = Runner::new(0, Stop::new());
    let plan = Plan {
        model: &model,
        method: &method,
        design: &ds,
        seed: 3,
    };
    let d = design::simulate(
        &plan,
        &[(b, dicephys::model::scene::Mode::ThreeD)],
        &runner,
        None,
    )
    .unwrap()
    .unwrap();
    let s = Surrogate::fit(&d[0].points, 3, 3, deg);
    println!(
        "deg {deg} LOF p {:.4} disp {:.2}",
        s.lack_of_fit_p(),
        s.dispersion
    );
    let mut res: Vec<(f64, Vec<f64>, Vec<u64>, Vec<f64>)> = d[0]
        .points
        .iter()
        .map(|p| {
            let q = s.p(&p.x);
            let n: u64 = p.counts.iter().sum();
            let chi: f64 = p
                .counts
                .iter()
                .zip(&q)
                .map(|(&c, &pq)| (c as f64 - n as f64 * pq).powi(2) / (n as f64 * pq).max(1e-9))
                .sum();
            (chi, p.x.clone(), p.counts.clone(), q)
        })
        .collect();
    res.sort_by(|a, b| b.0.total_cmp(&a.0));
    for r in res.iter().take(8) {
        println!(
            "chi2 {:.1} x {:?} counts {:?} p {:?}",
            r.0,
            r.1.iter().map(|v| format!("{v:.2}")).collect::<Vec<_>>(),
            r.2,
            r.3.iter().map(|v| format!("{v:.3}")).collect::<Vec<_>>()
        );
    }
    // the response along each axis through the centre
    for j in 0..3 {
        let mut line = String::new();
        for i in 0..=10 {
            let mut x = vec![0.5294, 0.2222, 0.3728];
            x[j] = i as f64 / 10.0;
            let q = s.p(&x);
            line += &format!(" {:.3}/{:.3}", q[1], q[0]);
        }
        println!("axis {j}:{line}");
    }
}
