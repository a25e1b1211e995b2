//! Scratch: surrogate adequacy per block (args: points rolls dt).
use dicephys::calibration::design::keys;
use dicephys::calibration::design::DesignSpec;
use dicephys::calibration::params::{Fixed, Kind, Method, ModelSpec};
use dicephys::engine::EngineKind;
use dicephys::inference::surrogate::{DesignPoint, Surrogate};
use dicephys::run::runner::Runner;
use dicephys::run::stop::Stop;
use dicephys::studies::fit::simulate::{self as design, Plan};

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let points: usize = a[1].parse().unwrap();
    let rolls: u64 = a[2].parse().unwrap();
    let dt: f64 = a[3].parse().unwrap();
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
        degree: 2,
        max_degree: 2,
    };
    let runner = Runner::new(0, Stop::new());
    let plan = Plan {
        model: &model,
        method: &method,
        design: &ds,
        seed: 3,
    };
    for blk in ["140x24x20", "140x30x10", "99.3x43.9x43.2"] {
        let b = blk.parse().unwrap();
        let d = design::simulate(
            &plan,
            &[(b, dicephys::model::scene::Mode::ThreeD)],
            &runner,
            None,
        )
        .unwrap()
        .unwrap();
        let pts: Vec<DesignPoint> = d[0].points.clone();
        // the truth by direct simulation
        let x = [
            Kind::E.coordinate(Kind::E.default_range(), 0.5),
            Kind::Mu.coordinate(Kind::Mu.default_range(), 0.3),
            Kind::Kappa.coordinate(Kind::Kappa.default_range(), 30.0),
        ];
        let v = model.values(&x);
        let spec = method.spec(b, dicephys::model::scene::Mode::ThreeD, &v, 99, 20000);
        let t = runner
            .run(&spec, None, &mut |_| Ok(()))
            .unwrap()
            .tally
            .counts;
        let n = (t.length + t.breadth + t.width) as f64;
        let truth = [
            t.length as f64 / n,
            t.breadth as f64 / n,
            t.width as f64 / n,
        ];
        for deg in 1..=5 {
            if 2 * dicephys::inference::surrogate::exponents(3, deg).len() > pts.len() {
                break;
            }
            let s = Surrogate::fit(&pts, 3, 3, deg);
            let pr = s.predict(&x);
            println!("{blk} deg {deg}: LOF p {:.3} disp {:.2}  P(breadth) {:.4} ± {:.4} truth {:.4} ± {:.4}  P(len) {:.4} ± {:.4} truth {:.4}", s.lack_of_fit_p(), s.dispersion, pr.p[1], pr.cov[(1,1)].sqrt(), truth[1], (truth[1]*(1.0-truth[1])/n).sqrt(), pr.p[0], pr.cov[(0,0)].sqrt(), truth[0]);
        }
    }
}
