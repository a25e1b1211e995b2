//! Property tests ("fuzzing") of everything that takes user input: no input panics; what is
//! accepted is valid; the scene builder gives a working world for every accepted scene.

use clap::Parser;
use dicephys::block::Block;
use dicephys::cli::args::{RunArgs, SceneArgs, ThrowArgs};
use dicephys::engine::{new_engine, EngineKind};
use dicephys::summary::Shard;
use dicephys::throws::{keyed, Range};
use proptest::prelude::*;

#[derive(Parser, Debug)]
struct Probe {
    #[command(flatten)]
    scene: SceneArgs,
    #[command(flatten)]
    throw: ThrowArgs,
    #[command(flatten)]
    run: RunArgs,
}

fn number() -> impl Strategy<Value = String> {
    prop_oneof![
        any::<f64>().prop_map(|v| v.to_string()),
        (-1e3f64..1e3).prop_map(|v| v.to_string()),
        Just("nan".to_string()),
        Just("-inf".to_string()),
        Just("1e400".to_string()),
        "[0-9.eE+-]{0,8}",
    ]
}

proptest! {
    #[test]
    fn block_parsing_never_panics(s in "\\\\PC{0,24}") {
        let _ = s.parse::<Block>();
    }

    #[test]
    fn accepted_blocks_are_valid(l in number(), b in number(), w in number()) {
        if let Ok(block) = format!("{l}x{b}x{w}").parse::<Block>() {
            for side in [block.length, block.breadth, block.width] {
                prop_assert!(side.is_finite() && side > 0.0 && side <= 10.0);
            }
            prop_assert!(block.breadth >= block.width);
        }
    }

    #[test]
    fn ranges_and_shards_never_panic(s in "\\\\PC{0,16}", a in number(), b in number()) {
        let _ = s.parse::<Range>();
        let _ = s.parse::<Shard>();
        if let Ok(r) = format!("{a}:{b}").parse::<Range>() {
            prop_assert!(r.lo.is_finite() && r.hi.is_finite() && r.lo <= r.hi);
        }
    }

    #[test]
    fn the_command_line_never_panics(
        block in prop_oneof![number(), Just("140x24x20".to_string())],
        dt in number(), mu in number(), e in number(), rho in number(),
        v in number(), spin in number(), rolls in number(), two_d in any::<bool>(),
    ) {
        let mut args = vec!["probe".to_string(), "--block".into(), block, "--dt".into(), dt,
            "--friction".into(), mu, "--restitution".into(), e, "--density".into(), rho,
            format!("--velocity={v}"), format!("--spin={spin}"), "--rolls".into(), rolls];
        if two_d { args.push("--2d".into()); }
        if let Ok(p) = Probe::try_parse_from(&args) {
            if let (Ok(scene), Ok(ranges), Ok(_)) = (p.scene.scene(), p.throw.ranges(), p.run.check()) {
                prop_assert!(scene.dt > 0.0 && scene.dt <= 0.1);
                prop_assert!(scene.mass() > 0.0 && scene.mass().is_finite());
                let t = keyed(1, &ranges, 0);
                prop_assert!(t.velocity.is_finite() && t.spin.is_finite());
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Every scene the command line accepts builds a world that steps without panicking; a
    /// roll either ends or reports why.
    #[test]
    fn every_accepted_scene_builds_and_steps(
        l in 1.0f64..2000.0, b in 1.0f64..500.0, w in 1.0f64..500.0,
        dt in 1e-4f64..0.1, mu in 0.0f64..2.0, e in 0.0f64..1.0, rho in 1.0f64..20000.0,
        two_d in any::<bool>(), rapier in any::<bool>(),
    ) {
        let args: Vec<String> = ["probe", "--block", &format!("{l}x{b}x{w}"), "--dt", &dt.to_string(),
            "--friction", &mu.to_string(), "--restitution", &e.to_string(), "--density", &rho.to_string()]
            .iter().map(|s| s.to_string()).chain(two_d.then(|| "--2d".to_string())).collect();
        let Ok(p) = Probe::try_parse_from(&args) else { return Ok(()) };
        let Ok(scene) = p.scene.scene() else { return Ok(()) };
        let kind = if rapier { EngineKind::Rapier } else { EngineKind::Bullet };
        let mut engine = new_engine(kind, &scene).unwrap();
        let throw = keyed(3, &p.throw.ranges().unwrap(), 0);
        let settle = dicephys::roll::Settle { max_steps: 300, ..Default::default() };
        let r = dicephys::roll::roll(engine.as_mut(), &scene, &throw, &settle);
        prop_assert!(r.steps <= 300);
    }
}
