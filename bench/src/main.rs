//! Times `pe` (contact solvers `exact`, `soft` and `auto`) against rapier2d and Box2D v3 on
//! scenes with known answers, and writes the results as Markdown to docs/bench/results.md;
//! with `sweep`, the work–precision sweeps to docs/bench/sweep.md and their plots; with
//! `pe <scene> [solver] [fresh]`, one scene in pe alone (for profiling), printing its
//! outcome; with `throws [count] [seed] [list]`, the random throws alone (`throws.rs`),
//! listing each that sinks with `list`; with `stages <scene>` (feature `stages`), pe's
//! stages beside rapier2d's and Box2D v3's own profiles of the same scene; with `samples
//! [name,...]`, Box2D v3's samples in every engine (`sample_runs.rs`), printing their
//! tables; with `cradle`, Newton's cradle in every engine (`cradle.rs`) to
//! docs/bench/cradle.md and its plot.
//!
//! Run with `cargo run --release [-- sweep | -- pe smash soft | -- throws | -- samples |
//! -- cradle]` inside bench/.

mod box2d_scenes;
mod cradle;
mod format;
mod harness;
mod machine;
mod pe_scenes;
mod piles;
mod profile;
mod rapier_scenes;
mod report;
mod robots;
mod sample_runs;
mod scene;
mod sweep;
mod throws;

use harness::{Timing, interleaved};
use machine::{
    PeerBuild, code_version, load_average, locked_version, machine, rapier_version, today,
};
use pe::ContactSolver;
use pe_scenes::PeConfig;
use piles::{narrow_phase_rows, pile_rows, run_pile_with_peers};
use profile::{run_pe_alone, run_stages_beside_peers};
use report::{report, write_throws};
use scene::{H, Metric, PENDULUMS, PYRAMIDS, Pendulum, bounce, chain, joint_grid, smash};
use std::fmt::Write as _;
use std::time::Instant;

/// One engine's run of one scene.
#[derive(Debug, Clone, Copy)]
pub struct Outcome {
    pub timing: Timing,
    pub metric: Metric,
}

impl Outcome {
    pub fn new(timing: Timing, metric: Metric) -> Self {
        Self { timing, metric }
    }
}

/// The pe solvers compared; the peers are the references for the time ratios.
pub const PE_SOLVERS: [ContactSolver; 3] = [
    ContactSolver::Exact,
    ContactSolver::Soft,
    ContactSolver::Auto,
];

/// The peer engines, in the order of `Row::peers`.
pub const PEERS: [&str; 2] = ["rapier2d", "Box2D v3"];

/// One scene in every engine.
pub struct Row {
    pub scene: String,
    pub known: String,
    /// In the order of `PE_SOLVERS`.
    pub pe: Vec<Outcome>,
    /// In the order of `PEERS`.
    pub peers: Vec<Outcome>,
}

/// Runs one scene in each pe solver and in each peer, taking turns (`interleaved`), and
/// reports progress on stderr (the whole benchmark takes a few minutes).
fn run_row(
    scene: &str,
    known: String,
    pe_run: impl Fn(ContactSolver) -> Outcome + Sync,
    rapier_run: impl FnOnce() -> Outcome + Send,
    box2d_run: impl FnOnce() -> Outcome + Send,
) -> Row {
    let started = Instant::now();
    eprint!(
        "{scene}: pe {}, rapier2d, Box2D v3 taking turns…",
        PE_SOLVERS.map(|s| s.name()).join(", pe ")
    );
    let pe_run = &pe_run;
    let mut jobs: Vec<Job<'_>> = PE_SOLVERS
        .iter()
        .map(|&s| Box::new(move || pe_run(s)) as Job<'_>)
        .collect();
    jobs.push(Box::new(rapier_run));
    jobs.push(Box::new(box2d_run));
    let mut pe = interleaved(jobs);
    let peers = pe.split_off(PE_SOLVERS.len());
    eprintln!(" {:.1} s", started.elapsed().as_secs_f64());
    let names = PE_SOLVERS.iter().map(|s| format!("pe {}", s.name()));
    for (name, o) in names
        .chain(PEERS.map(String::from))
        .zip(pe.iter().chain(&peers))
    {
        if o.timing.cut_short() {
            eprintln!(
                "  ({name} stopped after {} steps: budget)",
                o.timing.steps_run
            );
        }
    }
    Row {
        scene: scene.to_string(),
        known,
        pe,
        peers,
    }
}

/// One engine's whole run of a scene, for `interleaved`.
pub type Job<'a> = Box<dyn FnOnce() -> Outcome + Send + 'a>;

fn main() {
    if !PeerBuild::CURRENT.runs_here() {
        eprintln!(
            "this build runs Box2D v3 and rapier2d in AVX2, which this processor lacks: \
             build with `cargo run --release --no-default-features` (the peers' default \
             lanes)"
        );
        std::process::exit(2);
    }
    let docs = concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/bench");
    let load = load_average();
    let code = code_version();
    harness::pin_to_the_benchmark_core();
    let started = Instant::now();
    if std::env::args().nth(1).as_deref() == Some("sweep") {
        let mut md = sweep::run(docs);
        let _ = writeln!(
            md,
            "Machine: {}; load average at start: {load}; {}; {code}; whole sweep {:.0} s. \
             rapier2d: {}; Box2D v3: {}; every engine's Rust compiled for this processor.",
            machine(),
            today(),
            started.elapsed().as_secs_f64(),
            PeerBuild::CURRENT.rapier2d(),
            PeerBuild::CURRENT.box2d(),
        );
        write_doc(docs, "sweep.md", &md);
        return;
    }
    if std::env::args().nth(1).as_deref() == Some("cradle") {
        let mut md = cradle::run(docs);
        let _ = writeln!(md, "{}", run_line(None, &code));
        write_doc(docs, "cradle.md", &md);
        return;
    }
    if std::env::args().nth(1).as_deref() == Some("pe") {
        run_pe_alone();
        return;
    }
    if std::env::args().nth(1).as_deref() == Some("stages") {
        run_stages_beside_peers();
        return;
    }
    if std::env::args().nth(1).as_deref() == Some("pile") {
        run_pile_with_peers();
        return;
    }
    if std::env::args().nth(1).as_deref() == Some("samples") {
        let names: Vec<String> = std::env::args()
            .skip(2)
            .flat_map(|a| a.split(',').map(String::from).collect::<Vec<_>>())
            .collect();
        let rows = sample_runs::run(&names);
        let mut md = format!("{}\n", run_line(Some(&load), &code));
        sample_runs::write(&mut md, &rows);
        println!("{md}");
        return;
    }
    if std::env::args().nth(1).as_deref() == Some("throws") {
        let arg = |k: usize| std::env::args().nth(k);
        let count = arg(2)
            .and_then(|a| a.parse().ok())
            .unwrap_or(throws::THROWS);
        let seed = arg(3).and_then(|a| a.parse().ok()).unwrap_or(throws::SEED);
        let list = std::env::args().any(|a| a == "list");
        let mut md = String::new();
        write_throws(&mut md, &throws::run(count, seed, list), seed);
        println!("{md}");
        return;
    }
    let rows = engine_rows();
    let piles = pile_rows();
    let narrow = narrow_phase_rows();
    let robot_rows = robots::run();
    let throw_rows = throws::run(throws::THROWS, throws::SEED, false);
    let sample_rows = sample_runs::run(&[]);
    let mut report = report(
        &rows,
        &piles,
        &narrow,
        &robot_rows,
        &throw_rows,
        started.elapsed(),
        (&load, &code),
    );
    sample_runs::write(&mut report, &sample_rows);
    write_doc(docs, "results.md", &report);
}

/// The main run's scenes with known answers, each in every engine (`run_row`).
fn engine_rows() -> Vec<Row> {
    let mut rows = Vec::new();
    for spec in &PYRAMIDS {
        rows.push(run_row(
            spec.name,
            "stands: drift 0, 0 fallen".into(),
            |s| pe_scenes::pyramid(PeConfig::new(s), spec, H),
            || rapier_scenes::pyramid(spec, H, rapier_scenes::ITERATIONS),
            || box2d_scenes::pyramid(spec, H, box2d_scenes::SUBSTEPS),
        ));
    }
    for spec in &PENDULUMS {
        rows.push(run_row(
            spec.name,
            format!("T = {:.5} s, ΔE = 0", Pendulum::exact_period()),
            |s| pe_scenes::pendulum(PeConfig::new(s), spec),
            || rapier_scenes::pendulum(spec, rapier_scenes::ITERATIONS),
            || box2d_scenes::pendulum(spec, box2d_scenes::SUBSTEPS),
        ));
    }
    rows.push(run_row(
        chain::NAME,
        "gap 0".into(),
        |s| pe_scenes::heavy_chain(PeConfig::new(s), H),
        || rapier_scenes::heavy_chain(H, rapier_scenes::ITERATIONS),
        || box2d_scenes::heavy_chain(H, box2d_scenes::SUBSTEPS),
    ));
    rows.push(run_row(
        bounce::NAME,
        format!("peak e²·h = {} m", bounce::expected_peak()),
        |s| pe_scenes::bounce(PeConfig::new(s), H),
        || rapier_scenes::bounce(H, rapier_scenes::ITERATIONS),
        || box2d_scenes::bounce(H, box2d_scenes::SUBSTEPS),
    ));
    rows.push(run_row(
        joint_grid::NAME,
        "gap 0".into(),
        |s| pe_scenes::joint_grid(PeConfig::new(s)),
        rapier_scenes::joint_grid,
        box2d_scenes::joint_grid,
    ));
    rows.push(run_row(
        smash::NAME,
        "momentum drift 0; energy falls; no overlap".into(),
        |s| pe_scenes::smash(PeConfig::new(s)),
        rapier_scenes::smash,
        box2d_scenes::smash,
    ));
    rows
}

/// A report's closing line: the machine, the load at the start (if given), the date, the
/// code measured and the peers' versions and builds.
fn run_line(load: Option<&str>, code: &str) -> String {
    let load = load.map_or(String::new(), |l| format!("load average at start: {l}; "));
    format!(
        "Machine: {}; {load}{}; {code}; rapier2d {}: {}; Box2D v3 through boxdd {}: {}.",
        machine(),
        today(),
        rapier_version(),
        PeerBuild::CURRENT.rapier2d(),
        locked_version("boxdd"),
        PeerBuild::CURRENT.box2d(),
    )
}

/// Prints a report and writes it to `docs/<file>`, exiting with an error if it cannot.
fn write_doc(docs: &str, file: &str, md: &str) {
    println!("{md}");
    let path = format!("{docs}/{file}");
    if let Err(e) = std::fs::write(&path, md) {
        eprintln!("could not write {path}: {e}");
        std::process::exit(1);
    }
    eprintln!("written to docs/bench/{file}");
}
