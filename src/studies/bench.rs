//! `dicephys bench`: the standard workload (140x24x20, 3D and 2D, dt = 1 ms, the paper's throw
//! ranges, a fixed seed) for each engine and each speed lever, on 1 thread and on all, against
//! the faithful configuration (Bullet, DicePhys's rest rule, box floor, dicephys281) measured
//! in the same run. Speed is reported as ratios measured side by side: this machine is noisy.

use crate::engine::EngineKind;
use crate::model::faces::Layout;
use crate::model::scene::{Floor, Mode, Scene};
use crate::model::throws::{ThrowKind, ThrowRanges, ThrowStyle, Throws};
use crate::report::bench::{
    format_row, Bench, BenchRow, DiceCost, DicePhysRun, EngineFloor, FfiCost, Verdict,
};
use crate::run::batch;
use crate::run::cputime::{peak_rss_bytes, process_cpu_seconds};
use crate::run::tally::{Agreement, Tally};
use crate::sim::roll::{RollConfig, RollRecord, Rule};
use crate::theory::stats;
use serde::{Deserialize, Serialize};
use std::time::Instant;

/// The children's CPU seconds so far (user and system).
fn children_cpu_s() -> f64 {
    // SAFETY: getrusage writes the struct it is given; RUSAGE_CHILDREN is always valid.
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    unsafe { libc::getrusage(libc::RUSAGE_CHILDREN, &mut u) };
    let s = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    s(u.ru_utime) + s(u.ru_stime)
}

/// Runs DicePhys 2.81 (`binary`) as the paper ran it, in `mode`, as one process per core
/// (`processes`), each `rolls` throws, and times it.
pub fn run_dicephys(
    binary: &std::path::Path,
    mode: Mode,
    processes: usize,
    rolls: u64,
    stop: &crate::run::stop::Stop,
) -> crate::Result<DicePhysRun> {
    use std::process::{Command, Stdio};
    // DicePhys's flags (its main.cpp): velocity, spin and drop-height ranges, friction,
    // restitution, step, breadth, width and length (0: its 2D mode), the paper's own
    // settings (-D), rolls.
    let length = match mode {
        Mode::ThreeD => "0.14",
        Mode::TwoD => "0",
    };
    let args = [
        "-v", "-0.2", "0.2", "-a", "31", "160", "-y", "0.2", "0.4", "-f", "0.29", "-r", "0.5",
        "-t", "0.001", "-w", "0.024", "-h", "0.020", "-d", length, "-D", "-n",
    ];
    let failed = |why: String| crate::Error::failed(format!("{}: {why}", binary.display()));
    let cpu = children_cpu_s();
    let wall = Instant::now();
    let mut children = Vec::new();
    for _ in 0..processes.max(1) {
        children.push(
            Command::new(binary)
                .args(args)
                .arg(rolls.to_string())
                .stdin(Stdio::null())
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .spawn()
                .map_err(|e| failed(format!("cannot run it ({e})")))?,
        );
    }
    for mut c in children {
        loop {
            if let Some(status) = c.try_wait().map_err(|e| failed(e.to_string()))? {
                if !status.success() {
                    return Err(failed(format!("ended with {status}")));
                }
                break;
            }
            if stop.requested() {
                let _ = c.kill();
                let _ = c.wait();
                return Err(crate::Error::Stopped);
            }
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
    }
    let wall_s = wall.elapsed().as_secs_f64();
    let cpu_s = children_cpu_s() - cpu;
    Ok(DicePhysRun {
        mode: mode.name().into(),
        binary: binary.display().to_string(),
        processes: processes.max(1),
        rolls,
        wall_s,
        ms_per_roll: 1000.0 * cpu_s / (processes.max(1) as u64 * rolls) as f64,
    })
}

/// The cores a run on `threads` threads keeps busy: no more than the machine has.
pub fn cores_busy(threads: usize) -> usize {
    let machine = std::thread::available_parallelism().map_or(1, |n| n.get());
    threads.clamp(1, machine)
}

/// One way of rolling: an engine and the levers it uses.
#[derive(Clone, Debug, Serialize)]
pub struct Method {
    /// The method's name in the log and the report.
    pub name: String,
    /// The engine that rolls.
    pub engine: EngineKind,
    /// The floor: DicePhys's box, or the plane.
    pub floor: Floor,
    /// The rule that ends a roll.
    pub rule: Rule,
    /// Free flight integrated in closed form.
    pub fast_flight: bool,
    /// Shown by a cross-check at >= 20,000 rolls not to change the result (docs/method.md);
    /// only such methods can be the benchmark's verdict.
    pub proven: bool,
}

impl Method {
    /// A method from its levers; proven if it keeps the box floor.
    pub fn new(
        name: &str,
        engine: EngineKind,
        floor: Floor,
        rule: Rule,
        fast_flight: bool,
    ) -> Method {
        Method {
            name: name.into(),
            engine,
            floor,
            rule,
            fast_flight,
            // The plane floor changes the contact and so the result (measured: docs/method.md).
            proven: floor == Floor::Box,
        }
    }

    /// The baseline: Bullet, box floor, DicePhys's rest rule, every step by the engine.
    pub fn faithful() -> Method {
        Method::new(
            "faithful",
            EngineKind::Bullet,
            Floor::Box,
            Rule::Dicephys,
            false,
        )
    }

    /// `base` with this method's rule and free flight.
    pub fn settle(&self, base: &RollConfig) -> RollConfig {
        RollConfig {
            rule: self.rule,
            fast_flight: self.fast_flight,
            ..*base
        }
    }
}

/// The methods the benchmark compares: each lever on its own, then together.
pub fn methods() -> Vec<Method> {
    use EngineKind::*;
    use Floor::*;
    use Rule::*;
    vec![
        Method::faithful(),
        Method::new("early stop", Bullet, Box, Certificate, false),
        Method::new("fast flight", Bullet, Box, Dicephys, true),
        Method::new("plane floor", Bullet, Plane, Dicephys, false),
        Method::new("early stop + flight", Bullet, Box, Certificate, true),
        Method::new("all + plane floor", Bullet, Plane, Certificate, true),
        Method::new("rapier", Rapier, Box, Dicephys, false),
        Method::new("rapier early stop", Rapier, Box, Certificate, false),
        // Rapier's free flight flown in Rust as its own steps would (its defaults).
        Method::new("rapier stop + flight", Rapier, Box, Certificate, true),
    ]
}

/// An engine whose steps are timed: the bench's floor (`EngineFloor`).
pub struct TimedEngine {
    inner: Box<dyn crate::engine::Engine>,
    /// Seconds spent in `step`, so far.
    pub step_s: f64,
}

impl crate::engine::Engine for TimedEngine {
    fn reset(&mut self, start: &crate::model::state::BodyState) -> crate::Result<()> {
        self.inner.reset(start)
    }
    fn set_state(&mut self, now: &crate::model::state::BodyState) -> crate::Result<()> {
        self.inner.set_state(now)
    }
    fn ballistic_flight(&self) -> bool {
        self.inner.ballistic_flight()
    }
    fn contact_free(&self) -> bool {
        self.inner.contact_free()
    }
    fn own_flight(&self) -> bool {
        self.inner.own_flight()
    }
    fn own_flight_start(&mut self, s: &crate::model::state::BodyState) -> bool {
        self.inner.own_flight_start(s)
    }
    fn own_flight_step(
        &mut self,
        s: &crate::model::state::BodyState,
    ) -> Option<crate::model::state::BodyState> {
        self.inner.own_flight_step(s)
    }
    fn step(&mut self) -> crate::Result<()> {
        let t = Instant::now();
        let r = self.inner.step();
        self.step_s += t.elapsed().as_secs_f64();
        r
    }
    fn state(&self) -> crate::model::state::BodyState {
        self.inner.state()
    }
}

/// The engine floor of a method on a scene: its rolls of `throws` 0..`rolls` on this thread,
/// each engine step timed.
pub fn engine_floor(
    m: &Method,
    scene: &Scene,
    throws: &Throws,
    base: &RollConfig,
    rolls: u64,
    stop: &crate::run::stop::Stop,
) -> crate::Result<EngineFloor> {
    let mut e = TimedEngine {
        inner: crate::engine::new_engine(m.engine, scene)?,
        step_s: 0.0,
    };
    let cfg = m.settle(base);
    let mut engine_steps = 0u64;
    let wall = Instant::now();
    for i in 0..rolls {
        if stop.requested() {
            return Err(crate::Error::Stopped);
        }
        engine_steps += crate::sim::roll::roll(&mut e, scene, &throws.get(i), &cfg).engine_steps;
    }
    let roll_s = wall.elapsed().as_secs_f64();
    let n = rolls.max(1) as f64;
    Ok(EngineFloor {
        us_per_engine_step: 1e6 * e.step_s / engine_steps.max(1) as f64,
        engine_steps_per_roll: engine_steps as f64 / n,
        ms_per_roll: 1e3 * e.step_s / n,
        roll_ms: 1e3 * roll_s / n,
        share: e.step_s / roll_s,
    })
}

/// The accuracy bound: a method's ratio within this many combined standard errors of the
/// faithful method's, on the same throws.
pub const Z_BOUND: f64 = 2.0;

/// Every die `dice_costs` times, as a scene: the made cubes of [`made_dice`], then dice of
/// other shapes (`--shape`: a d6, which takes the box's path as the cuboid does, with and
/// without pips; a d20 and a d4 on the general hull path, and the d20 rounded 1 mm), and the
/// sharp cube under issue 72's candidates (a hand's toss, a flip, a printed shell and infill,
/// rolling resistance, a soft contact). Each with the throw it is thrown in: a tumble but for the toss and the flip.
/// Not a coin: a thin one spins like Euler's disk, about 100 ms a roll, and would double the
/// benchmark's time (its cost is on docs/results/shapes.md).
pub fn bench_dice() -> crate::Result<Vec<(String, Scene, ThrowStyle)>> {
    let block: crate::model::block::Block = "16x16x16".parse()?;
    let tumble = ThrowStyle::Tumble;
    let mut out: Vec<(String, Scene, ThrowStyle)> = made_dice()
        .into_iter()
        .map(|(name, features)| {
            let mut scene = Scene::paper(block, Mode::ThreeD);
            scene.features = features;
            (name.to_string(), scene, tumble)
        })
        .collect();
    let sharp = Scene::paper(block, Mode::ThreeD);
    out.push(("--throw toss".into(), sharp.clone(), ThrowStyle::Toss));
    out.push(("--throw flip".into(), sharp.clone(), ThrowStyle::Flip));
    let mut printed = sharp.clone();
    printed.features.shell = Some(crate::model::mass::Shell {
        wall: 0.001,
        infill: 0.2,
    });
    out.push(("--shell 1,0.2".into(), printed, tumble));
    let mut rolling = sharp.clone();
    rolling.rolling_resistance = 1e-4;
    out.push(("--rolling-resistance 0.1".into(), rolling, tumble));
    let mut soft = sharp.clone();
    soft.contact_time = 0.005;
    out.push(("--contact-time 5".into(), soft, tumble));
    let mut holding = sharp;
    holding.static_ratio = 1.5;
    out.push(("--static-ratio 1.5".into(), holding, tumble));
    for name in ["d6", "d20", "d4"] {
        let shape = crate::model::shape::named(name, None)?;
        out.push((
            format!("--shape {name}"),
            Scene::paper_shape(shape, Mode::ThreeD),
            tumble,
        ));
    }
    // The die `roll` rolls when none is named, as the command line resolves it (issue 70: a
    // 16 mm d6 on the box path, at the cuboid's cost).
    out.insert(
        out.len() - 2,
        (
            "(no die named)".to_string(),
            crate::run::request::SceneRequest::default().scene()?,
            tumble,
        ),
    );
    let mut d6_pips = Scene::paper_shape(crate::model::shape::named("d6", None)?, Mode::ThreeD);
    d6_pips.features.pips = made_dice()[2].1.pips;
    let d6_pips = d6_pips
        .resting_at_com()
        .map_err(|e| crate::Error::Invalid(format!("the d6 with pips: {e}")))?;
    out.insert(
        out.len() - 2,
        ("--shape d6 --pips 3,1".to_string(), d6_pips, tumble),
    );
    // Issue 72's rounded mesh: the d20's hull rounded 1 mm (`Shape::rounded`), against the
    // sharp d20 above.
    let d20 = crate::model::shape::named("d20", None)?
        .rounded(0.001)
        .map_err(|e| crate::Error::Invalid(format!("the rounded d20: {e}")))?;
    out.push((
        "--shape d20 --edge-radius 1".into(),
        Scene::paper_shape(d20, Mode::ThreeD),
        tumble,
    ));
    Ok(out)
}

/// The made dice `dice_costs` times, each as flags would give it: a weight 2 mm toward
/// face 6, 3 mm pips 1 mm deep, edges rounded 1 mm, all three; and a die file's insert (a
/// 4 mm tungsten cube off every axis, so that the body is turned off the die's axes).
pub fn made_dice() -> Vec<(&'static str, crate::model::mass::Features)> {
    use crate::model::mass::{Features, Insert, Pips};
    let com = Some([0.0, 0.0, -0.002]);
    let pips = Some(Pips::caps(0.003, 0.001));
    vec![
        ("sharp uniform", Features::default()),
        (
            "--com 0,0,-2",
            Features {
                com,
                ..Default::default()
            },
        ),
        (
            "--pips 3,1",
            Features {
                pips,
                ..Default::default()
            },
        ),
        (
            "--edge-radius 1",
            Features {
                edge_radius: 0.001,
                ..Default::default()
            },
        ),
        (
            "all three",
            Features {
                com,
                pips,
                edge_radius: 0.001,
                ..Default::default()
            },
        ),
        (
            "[insert] 4 mm at 1,1,-4, 19300 kg/m³",
            Features {
                insert: Some(Insert {
                    size: [0.004; 3],
                    centre: [0.001, 0.001, -0.004],
                    density: 19300.0,
                }),
                ..Default::default()
            },
        ),
    ]
}

/// Times every made die of `made_dice` on both engines (`rolls` each on Bullet, a quarter as
/// many on Rapier, which is slower), one thread, the dice of an engine run in turn `repeat`
/// rounds over, each keeping its fastest run.
pub fn dice_costs(
    rolls: u64,
    seed: u64,
    repeat: u32,
    stop: &crate::run::stop::Stop,
    log: &dyn Fn(&str),
) -> crate::Result<Vec<DiceCost>> {
    let throws = |style| {
        Throws::styled(
            ThrowKind::Keyed,
            style,
            None,
            seed,
            ThrowRanges::default(),
            0,
        )
    };
    // As `roll` rolls by default at this step: the early stop, free flight flown.
    let cfg = RollConfig {
        rule: Rule::Certificate,
        fast_flight: true,
        ..RollConfig::default()
    };
    let dice = bench_dice()?;
    let mut out = Vec::new();
    // The arbiter beside the engines, on the dice it models (no rounded edges).
    for (engine, n) in [
        (EngineKind::Bullet, rolls),
        (EngineKind::Rapier, (rolls / 4).max(1)),
        (EngineKind::Moreau, rolls),
    ] {
        let models = |scene: &Scene| {
            (engine != EngineKind::Moreau || crate::engine::moreau::models(scene).is_ok())
                && (engine == EngineKind::Bullet
                    || ((scene.rolling_resistance == 0.0 || engine.resists_rolling(scene.mode))
                        && scene.contact_time == 0.0
                        && scene.static_ratio == 1.0))
        };
        let mut best = vec![(f64::INFINITY, Vec::new()); dice.len()];
        for _ in 0..repeat.max(1) {
            for ((_, scene, style), best) in dice.iter().zip(best.iter_mut()) {
                if !models(scene) {
                    continue;
                }
                let throws = throws(*style);
                let job = batch::Job {
                    engine,
                    scene,
                    throws: &throws,
                    cfg: &cfg,
                };
                let list: Vec<u64> = (0..n).collect();
                let cpu = process_cpu_seconds();
                let recs = batch::run_indices(&job, &list, 1, stop, &|_| {})?;
                let c = process_cpu_seconds() - cpu;
                if (recs.len() as u64) < n {
                    return Err(crate::Error::Stopped);
                }
                if c < best.0 {
                    *best = (c, recs);
                }
            }
        }
        let sharp_ms = 1000.0 * best[0].0 / n as f64;
        for ((name, scene, _), (cpu_s, recs)) in dice.iter().zip(&best) {
            if !models(scene) {
                continue;
            }
            let t = Tally::of(recs, scene.die.counts_sides())?;
            let ms = 1000.0 * cpu_s / n as f64;
            let row = DiceCost {
                engine: engine.name().into(),
                die: name.to_string(),
                rolls: n,
                cpu_ms_per_roll: ms,
                vs_sharp: ms / sharp_ms,
                engine_steps_per_roll: t.engine_steps as f64 / n as f64,
                faces: match scene.die.as_shape() {
                    None => {
                        let up = t.by_direction();
                        Layout::Right
                            .numbers()
                            .map(|k| up[Layout::Right.direction_of(k).unwrap_or(0)])
                            .to_vec()
                    }
                    Some(_) => t.faces.to_vec(),
                },
            };
            log(&format!(
                "made die, {:<6} {:<16} {:>6} rolls  {:.3} ms/roll  {:.2}x the sharp uniform die  {:.0} engine steps/roll",
                row.engine, row.die, row.rolls, row.cpu_ms_per_roll, row.vs_sharp, row.engine_steps_per_roll
            ));
            out.push(row);
        }
    }
    Ok(out)
}

/// What the benchmark measures.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Config {
    /// Throws per method, mode and thread count.
    pub rolls: u64,
    /// Throws per made die (0: none, `dice_costs`).
    pub dice_rolls: u64,
    /// The keyed throws' seed.
    pub seed: u64,
    /// Threads for the "all threads" measurements.
    pub threads: usize,
    /// Rounds over every method of a mode and thread count, each keeping its fastest run.
    pub repeat: u32,
    /// DicePhys 2.81's binary, to run beside (`None`: no ratio to DicePhys).
    pub dicephys: Option<std::path::PathBuf>,
}

/// The most throws per method a bench takes.
pub const MAX_ROLLS: u64 = 10_000_000;

/// The most throws per made die a bench takes.
pub const MAX_DICE_ROLLS: u64 = 1_000_000;

impl Config {
    /// Checks every value before anything runs.
    pub fn validate(&self) -> crate::Result<()> {
        use crate::error::{Error, Field};
        if self.rolls == 0 {
            return Err(Error::field(Field::Rolls, 0, "need at least one roll"));
        }
        if self.rolls > MAX_ROLLS {
            return Err(Error::field(
                Field::Rolls,
                self.rolls,
                format!("at most {MAX_ROLLS}"),
            ));
        }
        if self.repeat == 0 {
            return Err(Error::field(Field::Repeat, 0, "need at least one run"));
        }
        if self.dice_rolls > MAX_DICE_ROLLS {
            return Err(Error::field(
                Field::DiceRolls,
                self.dice_rolls,
                format!("at most {MAX_DICE_ROLLS}"),
            ));
        }
        if let Some(p) = self.dicephys.as_ref().filter(|p| !p.is_file()) {
            return Err(Error::field(
                Field::Dicephys,
                p.display(),
                "not a file (DicePhys 2.81's binary)",
            ));
        }
        Ok(())
    }
}

/// A method's records (the same every run: runs are reproducible) and its fastest run's wall
/// and CPU seconds.
type Fastest = (Vec<RollRecord>, f64, f64);

/// Runs the benchmark: `rolls` throws per method, mode and thread count, then the made dice's
/// costs on `dice_rolls` (0: none, `dice_costs`); `log` gets a line per measurement. With
/// `repeat` > 1, every method of a mode and thread count is run in turn, `repeat` rounds
/// over, and each keeps its fastest run: a spell of load from elsewhere then falls on
/// different methods in different rounds, not on one method's every run.
pub fn run(
    cfg: &Config,
    stop: &crate::run::stop::Stop,
    log: &dyn Fn(&str),
) -> crate::Result<Bench> {
    let block: crate::model::block::Block = "140x24x20".parse()?;
    let throws = Throws::new(ThrowKind::Keyed, cfg.seed, ThrowRanges::default(), 0);
    let base = RollConfig::default();
    let methods = methods();
    let mut rows = Vec::new();
    let mut dicephys_runs = Vec::new();
    for mode in [Mode::ThreeD, Mode::TwoD] {
        let dp = dicephys_beside(cfg, mode, stop, log)?;
        dicephys_runs.extend(dp.clone());
        let mut floors = Vec::new();
        for m in &methods {
            let mut scene = Scene::paper(block, mode);
            scene.floor = m.floor;
            floors.push(engine_floor(m, &scene, &throws, &base, cfg.rolls, stop)?);
        }
        let mut thread_counts = vec![1];
        if cfg.threads > 1 {
            thread_counts.push(cfg.threads);
        }
        for &threads in &thread_counts {
            let mut best: Vec<Fastest> = vec![(Vec::new(), f64::INFINITY, 0.0); methods.len()];
            for _ in 0..cfg.repeat.max(1) {
                for (m, best) in methods.iter().zip(best.iter_mut()) {
                    let mut scene = Scene::paper(block, mode);
                    scene.floor = m.floor;
                    let job = batch::Job {
                        engine: m.engine,
                        scene: &scene,
                        throws: &throws,
                        cfg: &m.settle(&base),
                    };
                    let run = timed_run(&job, cfg.rolls, threads, stop)?;
                    if run.1 < best.1 {
                        *best = run;
                    }
                }
            }
            let mut faithful: Option<(&[RollRecord], f64)> = None;
            for ((m, fastest), floor) in methods.iter().zip(&best).zip(&floors) {
                let row = bench_row(m, mode, threads, fastest, *floor, faithful, dp.as_ref())?;
                log(&format_row(&row));
                if faithful.is_none() {
                    faithful = Some((&fastest.0, row.rolls_per_s));
                }
                rows.push(row);
            }
        }
    }
    let ffi = ffi_cost(&Scene::paper(block, Mode::ThreeD))?;
    log(&format!(
        "FFI: {} steps (fastest of 3 per throw), Rust loop (one cxx call per step, writing the state into Rust's copy) {:.3} s, C++ loop (the same steps and state reads) {:.3} s: overhead {:+.1} %",
        ffi.steps,
        ffi.rust_loop_s,
        ffi.cpp_loop_s,
        100.0 * ffi.overhead
    ));
    let verdicts = verdicts(&rows, &methods, cfg.threads);
    log_verdicts(&verdicts, log);
    if cfg.dicephys.is_none() {
        log("×DicePhys: not measured (give --dicephys PATH, DicePhys 2.81's binary, to run it beside)");
    }
    let dice = if cfg.dice_rolls > 0 {
        dice_costs(cfg.dice_rolls, cfg.seed, cfg.repeat, stop, log)?
    } else {
        Vec::new()
    };
    Ok(Bench {
        rows,
        verdicts,
        ffi,
        peak_rss_mb: peak_rss_bytes() as f64 / 1e6,
        seed: cfg.seed,
        repeat: cfg.repeat.max(1),
        dice,
        dicephys: dicephys_runs,
    })
}

/// DicePhys itself, beside a mode's methods: one process per core, every core busy, `rolls`
/// throws in all (`None` without its binary).
fn dicephys_beside(
    cfg: &Config,
    mode: Mode,
    stop: &crate::run::stop::Stop,
    log: &dyn Fn(&str),
) -> crate::Result<Option<DicePhysRun>> {
    let Some(binary) = &cfg.dicephys else {
        return Ok(None);
    };
    let cores = cores_busy(usize::MAX);
    let run = run_dicephys(binary, mode, cores, cfg.rolls.div_ceil(cores as u64), stop)?;
    log(&format!(
        "DicePhys 2.81 {}: {} processes × {} rolls in {:.2} s, {:.3} CPU ms per roll",
        run.mode, run.processes, run.rolls, run.wall_s, run.ms_per_roll
    ));
    Ok(Some(run))
}

/// One method's `rolls` throws on `threads`, timed: its records, wall and CPU seconds.
fn timed_run(
    job: &batch::Job,
    rolls: u64,
    threads: usize,
    stop: &crate::run::stop::Stop,
) -> crate::Result<Fastest> {
    let wall = Instant::now();
    let cpu = process_cpu_seconds();
    let list: Vec<u64> = (0..rolls).collect();
    let recs = batch::run_indices(job, &list, threads, stop, &|_| {})?;
    if (recs.len() as u64) < rolls {
        return Err(crate::Error::Stopped);
    }
    let (c, w) = (process_cpu_seconds() - cpu, wall.elapsed().as_secs_f64());
    Ok((recs, w, c))
}

/// A method's row from its fastest run, against the mode's faithful method (the first, with
/// its records and rolls per second) and DicePhys where it ran.
fn bench_row(
    m: &Method,
    mode: Mode,
    threads: usize,
    (recs, wall_s, cpu_s): &Fastest,
    floor: EngineFloor,
    faithful: Option<(&[RollRecord], f64)>,
    dp: Option<&DicePhysRun>,
) -> crate::Result<BenchRow> {
    let (wall_s, cpu_s) = (*wall_s, *cpu_s);
    let rolls = recs.len() as u64;
    // The paper's block, counted by its sides.
    let t = Tally::of(recs, true)?;
    let r = stats::ratio(t.counts.breadth, t.counts.width);
    let rolls_per_s = rolls as f64 / wall_s;
    let (speedup, z, same) = match &faithful {
        None => (1.0, 0.0, 1.0),
        Some((f, f_rps)) => {
            let ft = Tally::of(f, true)?;
            let fr = stats::ratio(ft.counts.breadth, ft.counts.width);
            (
                rolls_per_s / f_rps,
                stats::z_score(r.value, r.err, fr.value, fr.err),
                Agreement::of(f, recs, true).of_rolls(),
            )
        }
    };
    let cores = cores_busy(threads);
    let dicephys = dp.map(|d| d.rolls_per_s(cores));
    Ok(BenchRow {
        method: m.name.clone(),
        engine: m.engine.name().into(),
        mode: mode.name().into(),
        threads,
        rolls,
        rolls_per_s,
        cpu_ms_per_roll: 1000.0 * cpu_s / rolls as f64,
        us_per_engine_step: 1e6 * cpu_s / t.engine_steps.max(1) as f64,
        steps_per_roll: t.steps as f64 / rolls as f64,
        engine_steps_per_roll: t.engine_steps as f64 / rolls as f64,
        speedup,
        cores,
        dicephys_rolls_per_s: dicephys,
        vs_dicephys: dicephys.map(|d| rolls_per_s / d),
        vs_dicephys_cpu: dp.map(|d| d.ms_per_roll * rolls as f64 / (1000.0 * cpu_s)),
        floor,
        ratio: r.value,
        ratio_err: r.err,
        z_vs_faithful: z,
        same_outcome: same,
    })
}

/// Each mode's verdict: its fastest proven Bullet method on every thread within `Z_BOUND` of
/// faithful.
fn verdicts(rows: &[BenchRow], methods: &[Method], all_threads: usize) -> Vec<Verdict> {
    [Mode::ThreeD, Mode::TwoD]
        .iter()
        .filter_map(|mode| {
            let of_mode = |t: usize| {
                rows.iter()
                    .filter(move |r| r.mode == mode.name() && r.threads == t)
            };
            let faithful_1 = of_mode(1).find(|r| r.method == "faithful")?.rolls_per_s;
            let proven: Vec<&String> = methods
                .iter()
                .filter(|m| m.proven && m.engine == EngineKind::Bullet)
                .map(|m| &m.name)
                .collect();
            let best = of_mode(all_threads.max(1))
                .filter(|r| proven.contains(&&r.method) && r.z_vs_faithful.abs() <= Z_BOUND)
                .max_by(|a, b| a.rolls_per_s.total_cmp(&b.rolls_per_s))?;
            Some(Verdict {
                mode: mode.name().into(),
                method: best.method.clone(),
                threads: best.threads,
                rolls_per_s: best.rolls_per_s,
                speedup: best.speedup,
                speedup_vs_faithful_1_thread: best.rolls_per_s / faithful_1,
                vs_dicephys: best.vs_dicephys,
                vs_dicephys_cpu: best.vs_dicephys_cpu,
                // The floor's share of the cost, measured within one pass, carries over to
                // this run's speed better than the floor's own time on a noisy machine.
                vs_dicephys_at_floor: best.vs_dicephys_cpu.map(|v| v / best.floor.share),
                z_vs_faithful: best.z_vs_faithful,
            })
        })
        .collect()
}

fn log_verdicts(verdicts: &[Verdict], log: &dyn Fn(&str)) {
    for v in verdicts {
        let against = match (v.vs_dicephys, v.vs_dicephys_cpu, v.vs_dicephys_at_floor) {
            (Some(w), Some(c), Some(f)) => format!(
                ", {w:.1}x DicePhys on as many cores, {c:.1}x its CPU time per roll ({f:.1}x if \
                 all but the engine's steps were free)"
            ),
            _ => String::new(),
        };
        log(&format!(
            "fastest within |z| <= {Z_BOUND} of faithful, {}: {} on {} threads, {:.0} rolls/s: {:.2}x faithful on {} threads, {:.2}x faithful on 1 thread{against}",
            v.mode, v.method, v.threads, v.rolls_per_s, v.speedup, v.threads, v.speedup_vs_faithful_1_thread
        ));
    }
}

/// What one cxx call per step costs: the same 1,000-step stretch of the same throws, stepped
/// from Rust (one call per step, which writes the state into Rust's copy, as a roll does)
/// and inside C++ alone (the same steps and state reads), interleaved and repeated so that
/// machine noise falls on both alike.
pub fn ffi_cost(scene: &Scene) -> crate::Result<FfiCost> {
    use crate::engine::Engine;
    let mut bullet = crate::engine::bullet::Bullet::new(scene)?;
    let throws = Throws::new(ThrowKind::Keyed, 1, ThrowRanges::default(), 0);
    let n = 1000u32;
    let (mut rust_s, mut cpp_s) = (0.0, 0.0);
    let mut sink = 0.0;
    // Per throw, the two loops side by side, three times each; the fastest of each three
    // counts, so that a moment's load on this shared machine does not.
    for i in 0..200u64 {
        let start = throws.get(i).start(scene);
        let (mut rust_best, mut cpp_best) = (f64::INFINITY, f64::INFINITY);
        for _ in 0..3 {
            bullet.reset(&start)?;
            let t = Instant::now();
            for _ in 0..n {
                bullet.step()?;
                sink += bullet.state().position.y;
            }
            rust_best = rust_best.min(t.elapsed().as_secs_f64());
            bullet.reset(&start)?;
            let t = Instant::now();
            bullet.step_n(n)?;
            sink += bullet.state().position.y;
            cpp_best = cpp_best.min(t.elapsed().as_secs_f64());
        }
        rust_s += rust_best;
        cpp_s += cpp_best;
    }
    std::hint::black_box(sink);
    Ok(FfiCost {
        steps: 200 * n as u64,
        rust_loop_s: rust_s,
        cpp_loop_s: cpp_s,
        overhead: rust_s / cpp_s - 1.0,
    })
}
