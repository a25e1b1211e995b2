//! Property tests ("fuzzing") of everything in the library that takes user input: no input
//! panics; what is accepted is valid; every accepted scene gives a working world.

use dicephys::engine::{new_engine, EngineKind};
use dicephys::model::block::Block;
use dicephys::model::scene::{Mode, Scene};
use dicephys::model::throws::{keyed, Range, ThrowRanges};
use dicephys::run::spec::{RunSpec, Shard, ThrowSpec};
use dicephys::sim::roll::RollConfig;
use proptest::prelude::*;

/// The run a command line would ask for, from its words as typed: block, dt, μ, e, density,
/// velocity, spin, rolls (`None` where a word does not parse as what it spells).
fn spec(words: [&str; 8], two_d: bool) -> Option<RunSpec> {
    let [block, dt, mu, e, rho, v, spin, rolls] = words;
    let num = |s: &str| s.trim().parse::<f64>().ok();
    let block: Block = block.parse().ok()?;
    let mut scene = Scene::paper(block, if two_d { Mode::TwoD } else { Mode::ThreeD });
    scene.dt = num(dt)?;
    scene.friction = num(mu)?;
    scene.restitution = num(e)?;
    scene.density = num(rho)?;
    let ranges = ThrowRanges {
        velocity: v.parse().ok()?,
        spin: spin.parse().ok()?,
        ..ThrowRanges::default()
    };
    Some(RunSpec {
        engine: EngineKind::Bullet,
        scene,
        throws: ThrowSpec {
            ranges,
            ..ThrowSpec::keyed(1)
        },
        roll: RollConfig::fast(),
        rolls: rolls.trim().parse().ok()?,
        shard: None,
    })
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
    fn the_run_specification_never_panics(
        block in prop_oneof![number(), Just("140x24x20".to_string())],
        dt in number(), mu in number(), e in number(), rho in number(),
        v in number(), spin in number(), rolls in number(), two_d in any::<bool>(),
    ) {
        if let Some(spec) = spec([&block, &dt, &mu, &e, &rho, &v, &spin, &rolls], two_d) {
            if spec.validate(false).is_ok() {
                let scene = &spec.scene;
                prop_assert!(scene.dt > 0.0 && scene.dt <= 0.1);
                prop_assert!(scene.mass() > 0.0 && scene.mass().is_finite());
                let t = keyed(1, &spec.throws.ranges, 0);
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
        let words = [format!("{l}x{b}x{w}"), dt.to_string(), mu.to_string(), e.to_string(),
            rho.to_string(), "-0.2:0.2".into(), "31:160".into(), "1".into()];
        let Some(spec) = spec(words.each_ref().map(|w| w.as_str()), two_d) else { return Ok(()) };
        if spec.validate(false).is_err() { return Ok(()) }
        let scene = spec.scene;
        let kind = if rapier { EngineKind::Rapier } else { EngineKind::Bullet };
        let mut engine = new_engine(kind, &scene).unwrap();
        let throw = keyed(3, &spec.throws.ranges, 0);
        let settle = dicephys::sim::roll::RollConfig { max_steps: 300, ..Default::default() };
        let r = dicephys::sim::roll::roll(engine.as_mut(), &scene, &throw, &settle);
        prop_assert!(r.steps <= 300);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(4000))]

    /// A chunk's packed rolls, whatever their bytes (a damaged chunk, or one forged under a
    /// valid checksum), in either format, are read or refused, never a panic; the rolls read
    /// are tallied or refused, as a cuboid's and as a shape's; and written again they read
    /// back as they were written.
    #[test]
    fn packed_rolls_of_any_bytes_are_read_or_refused(
        rolls in proptest::collection::vec(
            (0u64..1 << 13, 0u64..300, proptest::collection::vec(0u64..1 << 20, 5), any::<u64>()),
            0..4,
        ),
        noise in proptest::collection::vec(any::<u8>(), 0..3),
        n in 0u64..4,
        v1 in any::<bool>(),
    ) {
        // Rolls laid out as `rolls-v2` lays them (a tag, a face where its bits say, steps, a
        // certified step and face, the dip), whatever the tag, the face and the counts say,
        // then a few stray bytes: most parse, as `rolls-v2` or as `rolls-v1`, or end early.
        let mut bytes = Vec::new();
        let mut put = |mut w: u64| {
            while w >= 0x80 {
                bytes.push((w as u8 & 0x7f) | 0x80);
                w >>= 7;
            }
            bytes.push(w as u8);
        };
        for (tag, face, counts, depth) in &rolls {
            let tag = if v1 { *tag } else { tag & 0x7f };
            put(tag);
            if tag & 3 < 2 && tag >> 2 & 1 == 1 {
                put(*face);
            }
            put(counts[0]);
            put(counts[1]);
            if tag >> 4 & 1 == 1 {
                put(counts[2]);
                put(*face);
            }
            put(counts[3]);
            put(counts[4]);
            if tag >> 6 & 1 == 1 {
                for k in 0..8 {
                    put(depth >> (8 * k) & 0x7f);
                }
            }
        }
        bytes.extend(noise);
        use dicephys::model::throws::{ThrowKind, Throws};
        use dicephys::run::pack::{pack, unpack, FORMAT, FORMAT_V1};
        use dicephys::run::tally::Tally;
        let throws = Throws::new(ThrowKind::Keyed, 1, ThrowRanges::default(), 0);
        let indices: Vec<u64> = (0..n).collect();
        let format = if v1 { FORMAT_V1 } else { FORMAT };
        if let Ok(recs) = unpack(&bytes, &indices, &throws, format) {
            let _ = Tally::of(&recs, true);
            let _ = Tally::of(&recs, false);
            let packed = pack(&recs);
            let again = unpack(&packed, &indices, &throws, FORMAT).unwrap();
            prop_assert_eq!(pack(&again), packed);
        }
    }
}
