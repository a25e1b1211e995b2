//! Scratch: is the surrogate biased at a point? (args: points rolls dt degree reps)
use dicephys::calibration::data;
use dicephys::calibration::design::{keys, DesignSpec};
use dicephys::calibration::params::{Fixed, Kind, Method, ModelSpec};
use dicephys::engine::EngineKind;
use dicephys::run::runner::Runner;
use dicephys::run::stop::Stop;
use dicephys::studies::fit::simulate::{simulate, Plan};
fn main() {
    let a: Vec<String> = std::env::args().collect();
    let (points, rolls, dt, degree, reps): (usize, u64, f64, usize, u64) = (
        a[1].parse().unwrap(),
        a[2].parse().unwrap(),
        a[3].parse().unwrap(),
        a[4].parse().unwrap(),
        a[5].parse().unwrap(),
    );
    let text = "label,surface,length_mm,breadth_mm,width_mm,mode,length_vertical,breadth_vertical,width_vertical\na,S,140,24,20,3d,0,400,600\nb,S,140,30,10,3d,0,50,950\nc,S,99.3,43.9,43.2,3d,20,1000,980\n";
    let rows = data::parse(text, "x").unwrap();
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
        degree,
        max_degree: degree + 1,
    };
    let runner = Runner::new(0, Stop::new());
    let x = vec![
        Kind::E.coordinate(Kind::E.default_range(), 0.5),
        Kind::Mu.coordinate(Kind::Mu.default_range(), 0.3),
        Kind::Kappa.coordinate(Kind::Kappa.default_range(), 30.0),
    ];
    let v = model.values(&x);
    let ks = keys(&rows);
    let mut truth = Vec::new();
    for &(b, m) in &ks {
        let t = runner
            .run(&method.spec(b, m, &v, 424242, 100_000), None, &mut |_| {
                Ok(())
            })
            .unwrap()
            .tally
            .counts;
        let n = (t.length + t.breadth + t.width) as f64;
        truth.push([t.length as f64 / n, t.breadth as f64 / n]);
        println!(
            "{b}: truth P(len) {:.5} P(breadth) {:.4} (n {n})",
            t.length as f64 / n,
            t.breadth as f64 / n
        );
    }
    let mut z = vec![vec![]; 6];
    for rep in 0..reps {
        let plan = Plan {
            model: &model,
            method: &method,
            design: &ds,
            seed: 1000 + rep,
        };
        let d = simulate(&plan, &ks, &runner, None).unwrap().unwrap();
        for (i, dd) in d.iter().enumerate() {
            let pr = dd.surrogate.predict(&x);
            for k in 0..2 {
                z[2 * i + k].push((pr.p[k] - truth[i][k]) / pr.cov[(k, k)].sqrt());
            }
        }
    }
    for (j, zz) in z.iter().enumerate() {
        let n = zz.len() as f64;
        let m = zz.iter().sum::<f64>() / n;
        let sd = (zz.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        println!(
            "block {} outcome {}: mean z {:+.2} sd {:.2}",
            j / 2,
            if j % 2 == 0 { "len" } else { "breadth" },
            m,
            sd
        );
    }
}
