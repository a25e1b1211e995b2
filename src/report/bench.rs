//! `dicephys bench`'s results and its table (the study: `studies::bench`): every measurement,
//! the verdicts, DicePhys 2.81 run beside them, what a made die's features cost.

use crate::report::text::{left, right, Columns};
use serde::Serialize;

/// DicePhys 2.81 itself, run beside the bench (`bench --dicephys PATH`): the paper's
/// workload (140x24x20, its throw ranges, μ 0.29, e 0.5, dt 1 ms) as one process per core,
/// every core busy, each rolling its share. DicePhys is single-threaded, so that is the fair
/// way to run it on a machine; a timing from another day is not a measurement.
#[derive(Clone, Debug, Serialize)]
pub struct DicePhysRun {
    /// "3d" or "2d".
    pub mode: String,
    /// The binary run.
    pub binary: String,
    /// Processes run at once (the machine's cores).
    pub processes: usize,
    /// Rolls per process.
    pub rolls: u64,
    /// Wall seconds until the last process ended.
    pub wall_s: f64,
    /// The processes' CPU ms per roll (user and system, `getrusage` of the children).
    pub ms_per_roll: f64,
}

impl DicePhysRun {
    /// DicePhys's rolls per second on `cores` cores busy: one process per core, each at the
    /// per-core rate measured with every core busy.
    pub fn rolls_per_s(&self, cores: usize) -> f64 {
        cores.max(1) as f64 * 1000.0 / self.ms_per_roll
    }
}

/// One measurement: a method, a mode and a thread count, its speed and its result.
#[derive(Clone, Debug, Serialize)]
pub struct BenchRow {
    /// The method's name.
    pub method: String,
    /// The engine's name.
    pub engine: String,
    /// "3d" or "2d".
    pub mode: String,
    /// Worker threads.
    pub threads: usize,
    /// Rolls made.
    pub rolls: u64,
    /// Rolls per wall-clock second (the fastest run of the repeats).
    pub rolls_per_s: f64,
    /// Process CPU milliseconds per roll, all threads.
    pub cpu_ms_per_roll: f64,
    /// Process CPU microseconds per step the engine took.
    pub us_per_engine_step: f64,
    /// Simulated steps per roll.
    pub steps_per_roll: f64,
    /// Steps the engine took per roll (fewer where free flight was coasted).
    pub engine_steps_per_roll: f64,
    /// Rolls per second over the faithful method's, same mode and threads, same run.
    pub speedup: f64,
    /// Cores this measurement keeps busy (threads, at most the machine's cores).
    pub cores: usize,
    /// DicePhys 2.81's rolls per second on as many cores, one process per core
    /// (`DicePhysRun::rolls_per_s`, measured in this run); `None` unless DicePhys was given.
    pub dicephys_rolls_per_s: Option<f64>,
    /// Rolls per second over DicePhys 2.81's on the same number of cores: per machine when
    /// every core is busy on both sides.
    pub vs_dicephys: Option<f64>,
    /// DicePhys 2.81's CPU time per roll over this method's (process CPU, all threads): the
    /// like-for-like figure, which moves less than `vs_dicephys` when other work takes the
    /// machine's cores (wall time counts the time the threads waited for one; CPU time does
    /// not).
    pub vs_dicephys_cpu: Option<f64>,
    /// The engine floor (`Floor`) of this method and mode, measured on one thread.
    pub floor: EngineFloor,
    /// N(breadth vertical)/N(width vertical) over the rolls.
    pub ratio: f64,
    /// Its binomial error.
    pub ratio_err: f64,
    /// (ratio − faithful ratio) / combined error, on the same throws.
    pub z_vs_faithful: f64,
    /// Fraction of throws with the same outcome as the faithful method.
    pub same_outcome: f64,
}

/// The engine floor: what a roll would cost if everything but the engine's own steps were
/// free. Measured on one thread over the same throws, with each engine step timed
/// (`TimedEngine`: the call into the engine and the state it returns).
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct EngineFloor {
    /// Wall-clock µs per engine step, inside the engine.
    pub us_per_engine_step: f64,
    /// Engine steps per roll.
    pub engine_steps_per_roll: f64,
    /// µs per engine step × engine steps per roll, ms.
    pub ms_per_roll: f64,
    /// What a roll cost in the same pass, ms (wall, one thread). The bench's table shows
    /// the floor as `share` × the row's CPU ms per roll: the share, measured within one pass,
    /// holds better than either time alone on a machine shared with other work.
    pub roll_ms: f64,
    /// The floor's share of the roll's cost.
    pub share: f64,
}

/// What crossing into C++ once per step costs (`ffi_cost`).
#[derive(Clone, Debug, Serialize)]
pub struct FfiCost {
    /// Steps in each loop, over all throws (200 × 1,000).
    pub steps: u64,
    /// Seconds, summed over 200 throws of the fastest of three runs per throw.
    pub rust_loop_s: f64,
    /// The same for the loop inside C++ (`Bullet::step_n`), s.
    pub cpp_loop_s: f64,
    /// (Rust loop − C++ loop) / C++ loop: what crossing into C++ once per step costs (both
    /// loops step and read the state every step).
    pub overhead: f64,
}

/// Per mode: the fastest proven Bullet method whose ratio stays within the accuracy bound of
/// the faithful one's (|z| ≤ `Z_BOUND` on the same throws), on all threads.
#[derive(Clone, Debug, Serialize)]
pub struct Verdict {
    /// "3d" or "2d".
    pub mode: String,
    /// The method's name.
    pub method: String,
    /// Worker threads (all).
    pub threads: usize,
    /// Rolls per wall-clock second.
    pub rolls_per_s: f64,
    /// Over the faithful method on the same number of threads.
    pub speedup: f64,
    /// Over the faithful method on one thread (DicePhys is single-threaded).
    pub speedup_vs_faithful_1_thread: f64,
    /// Rolls per second over DicePhys 2.81's on the same cores, one process per core
    /// (measured in this run; `None` unless DicePhys was given).
    pub vs_dicephys: Option<f64>,
    /// DicePhys 2.81's CPU time per roll over this method's (`BenchRow::vs_dicephys_cpu`).
    pub vs_dicephys_cpu: Option<f64>,
    /// `vs_dicephys_cpu` if everything but the engine's steps were free (`EngineFloor`): the
    /// most this method could reach without fewer or cheaper engine steps.
    pub vs_dicephys_at_floor: Option<f64>,
    /// (ratio − faithful ratio) / combined error, on the same throws.
    pub z_vs_faithful: f64,
}

/// The benchmark's results: every measurement, the verdicts, the FFI cost.
#[derive(Clone, Debug, Serialize)]
pub struct Bench {
    /// Every measurement, in the order run.
    pub rows: Vec<BenchRow>,
    /// Per mode, the fastest proven method within the accuracy bound; a mode with none is left out.
    pub verdicts: Vec<Verdict>,
    /// What one cxx call per step costs.
    pub ffi: FfiCost,
    /// Peak resident set size of the process, MB (10⁶ bytes).
    pub peak_rss_mb: f64,
    /// The throws' seed (keyed throws).
    pub seed: u64,
    /// Runs per measurement; the fastest counts.
    pub repeat: u32,
    /// What each feature of a made die costs against the sharp uniform die (`dice_costs`).
    pub dice: Vec<DiceCost>,
    /// DicePhys 2.81 run beside the methods, per mode, when its binary was given.
    pub dicephys: Vec<DicePhysRun>,
}

/// What a made die's features cost: a 16 mm cube thrown in a tumble, rolled by default
/// (early stop, fast flight) on one thread, against the sharp uniform cube on the same
/// engine, the same throws, in the same run.
#[derive(Clone, Debug, Serialize)]
pub struct DiceCost {
    /// The engine's name.
    pub engine: String,
    /// The die: "sharp uniform", or its features as flags.
    pub die: String,
    /// Rolls made.
    pub rolls: u64,
    /// Process CPU ms per roll (the fastest run of the repeats).
    pub cpu_ms_per_roll: f64,
    /// Over the sharp uniform die's on the same engine.
    pub vs_sharp: f64,
    /// Engine steps per roll.
    pub engine_steps_per_roll: f64,
    /// Face counts: a cube's 1 to 6; a die of any shape's in the order of its faces.
    pub faces: Vec<u64>,
}

/// The column heads of the log's measurement lines (`format_row`).
pub fn header() -> String {
    TABLE.header()
}

/// One measurement as a line of the log, under `header`.
pub fn format_row(r: &BenchRow) -> String {
    TABLE.row(&[
        r.method.clone(),
        r.mode.to_string(),
        r.threads.to_string(),
        format!("{:.0}", r.rolls_per_s),
        format!("{:.3}", r.cpu_ms_per_roll),
        format!("{:.2}", r.floor.us_per_engine_step),
        format!("{:.0}", r.steps_per_roll),
        format!("{:.0}", r.engine_steps_per_roll),
        format!("{:.2}x", r.speedup),
        r.vs_dicephys.map_or("—".into(), |v| format!("{v:.1}x")),
        r.vs_dicephys_cpu.map_or("—".into(), |v| format!("{v:.1}x")),
        format!("{:.3}", r.cpu_ms_per_roll * r.floor.share),
        format!("{:.0}%", 100.0 * r.floor.share),
        format!("{:.4} ± {:.4}", r.ratio, r.ratio_err),
        format!("{:+.1}", r.z_vs_faithful),
        format!("{:.1}%", 100.0 * r.same_outcome),
    ])
}

/// The columns of the bench's table.
const TABLE: Columns = Columns(&[
    left("method", 20),
    right("mode", 4),
    right("thr", 3),
    right("rolls/s", 9),
    right("ms/roll", 8),
    right("eng µs/st", 9),
    right("steps", 7),
    right("engine", 7),
    right("speedup", 8),
    right("×DicePhys", 9),
    right("×DP cpu", 7),
    right("floor ms", 8),
    right("share", 5),
    right("ratio", 16),
    right("z", 6),
    right("same", 6),
]);
