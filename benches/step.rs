//! `cargo bench`: the cost of one engine step, and of calling Bullet once per step through
//! cxx against a loop that steps the same world inside C++ alone.

use criterion::{criterion_group, criterion_main, Criterion};
use dicephys::engine::bullet::Bullet;
use dicephys::engine::{new_engine, Engine, EngineKind};
use dicephys::model::scene::{Mode, Scene};
use dicephys::model::throws::{keyed, ThrowRanges};
use std::hint::black_box;

/// 500 steps of one throw, from its start: flight, first bounces.
const STEPS: u32 = 500;

fn scene(mode: Mode) -> Scene {
    Scene::paper("140x24x20".parse().unwrap(), mode)
}

fn bench_steps(c: &mut Criterion) {
    let mut g = c.benchmark_group("500 steps of a 140x24x20 throw");
    for mode in [Mode::ThreeD, Mode::TwoD] {
        let scene = scene(mode);
        let start = keyed(1, &ThrowRanges::default(), 0).start(&scene);
        for kind in [EngineKind::Bullet, EngineKind::Rapier] {
            let mut e = new_engine(kind, &scene).unwrap();
            g.bench_function(format!("{kind} {} (Rust loop)", mode.name()), |b| {
                b.iter(|| {
                    e.reset(&start).unwrap();
                    for _ in 0..STEPS {
                        e.step().unwrap();
                        black_box(e.state());
                    }
                })
            });
        }
        // The same world stepped inside C++ alone: the FFI's share is the difference.
        let mut bullet = Bullet::new(&scene).unwrap();
        g.bench_function(format!("bullet {} (C++ loop)", mode.name()), |b| {
            b.iter(|| {
                bullet.reset(&start).unwrap();
                bullet.step_n(STEPS).unwrap();
                black_box(bullet.state());
            })
        });
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30);
    targets = bench_steps
}
criterion_main!(benches);
