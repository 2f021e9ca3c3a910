//! Times `pe` (contact solvers `exact`, `soft` and `auto`) against rapier2d and Box2D v3 on
//! scenes with known answers, and writes the results as Markdown to docs/bench/results.md;
//! with `sweep`, the work–precision sweeps to docs/bench/sweep.md and their plots; with
//! `pe <scene> [solver] [fresh]`, one scene in pe alone (for profiling), printing its
//! outcome; with `throws [count] [seed] [list]`, the random throws alone (`throws.rs`),
//! listing each that sinks with `list`; with `stages <scene>` (feature `stages`), pe's
//! stages beside rapier2d's and Box2D v3's own profiles of the same scene; with `samples
//! [name,...]`, Box2D v3's samples in every engine (`sample_runs.rs`), printing their
//! tables.
//!
//! Run with `cargo run --release [-- sweep | -- pe smash soft | -- throws | -- samples]`
//! inside bench/.

mod box2d_scenes;
mod harness;
mod pe_scenes;
mod rapier_scenes;
mod robots;
mod sample_runs;
mod scene;
mod sweep;
mod throws;

use harness::{RUN_BUDGET, TURN_STEPS, Timing, WARMUP_STEPS, WARMUP_WALL, interleaved};
use pe::ContactSolver;
use pe_scenes::PeConfig;
use scene::{H, Metric, PENDULUMS, PYRAMIDS, Pendulum, bounce, chain, joint_grid, smash};
use std::fmt::Write as _;
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

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
const PE_SOLVERS: [ContactSolver; 3] = [
    ContactSolver::Exact,
    ContactSolver::Soft,
    ContactSolver::Auto,
];

/// The peer engines, in the order of `Row::peers`.
const PEERS: [&str; 2] = ["rapier2d", "Box2D v3"];

/// One scene in every engine.
struct Row {
    scene: String,
    known: String,
    /// In the order of `PE_SOLVERS`.
    pe: Vec<Outcome>,
    /// In the order of `PEERS`.
    peers: Vec<Outcome>,
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
type Job<'a> = Box<dyn FnOnce() -> Outcome + Send + 'a>;

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
        let mut md = format!(
            "Machine: {}; load average at start: {load}; {}; {code}; rapier2d {}: {}; \
             Box2D v3 through boxdd {}: {}.\n",
            machine(),
            today(),
            rapier_version(),
            PeerBuild::CURRENT.rapier2d(),
            locked_version("boxdd"),
            PeerBuild::CURRENT.box2d(),
        );
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

/// `pe <scene> [solver] [fresh] [forwards] [substeps=S] [steps=N] [stages [from=K]]`: one
/// pile, grid or smash scene in pe alone, so that a profiler sees only pe's step (`fresh`:
/// no manifold reuse; `forwards`: the soft step sweeps its colours in one order only;
/// `substeps=S`: the soft step's substeps instead of the default 4; `steps=N`:
/// exactly N steps, with no time budget, so that two builds' instruction counts compare;
/// `stages`, in a build with the feature `stages`: the fewest and the median cycles of each
/// stage of the step, over the steps from the K-th, by default from half way).
fn run_pe_alone() {
    let scene = std::env::args().nth(2).unwrap_or_default();
    let solver_name = std::env::args().nth(3).unwrap_or_else(|| "soft".into());
    let Some(solver) = ContactSolver::from_name(&solver_name) else {
        eprintln!("unknown solver {solver_name:?}");
        std::process::exit(2);
    };
    let flags: Vec<String> = std::env::args().skip(4).collect();
    if let Some(steps) = flags
        .iter()
        .find_map(|f| f.strip_prefix("steps=")?.parse().ok())
    {
        harness::fixed_steps(steps);
    }
    let defaults = PeConfig::new(solver);
    let config = PeConfig {
        reuse_manifolds: !flags.iter().any(|f| f == "fresh"),
        soft_alternating_sweeps: !flags.iter().any(|f| f == "forwards"),
        soft_substeps: flags
            .iter()
            .find_map(|f| f.strip_prefix("substeps=")?.parse().ok())
            .unwrap_or(defaults.soft_substeps),
        ..defaults
    };
    let outcome = if let Some(spec) = PYRAMIDS.iter().find(|p| p.name == scene) {
        pe_scenes::pyramid(config, spec, H)
    } else if scene == joint_grid::NAME {
        pe_scenes::joint_grid(config)
    } else if scene == smash::NAME {
        pe_scenes::smash(config)
    } else {
        eprintln!(
            "unknown scene {scene:?}: one of {}",
            pile_scenes().join(", ")
        );
        std::process::exit(2);
    };
    println!("{scene} under pe {}: {outcome:?}", solver.name());
    if flags.iter().any(|f| f == "stages") {
        let from = flags
            .iter()
            .find_map(|f| f.strip_prefix("from=")?.parse().ok());
        print_stage_cycles(from);
    }
}

/// The table of `pe <scene> ... stages`: each stage's fewest and median cycles a step over
/// the steps from `from` on (half way by default), from `pe::stage_clock`.
fn print_stage_cycles(from: Option<usize>) {
    use pe::stage_clock::{self, Stage};
    if !stage_clock::ENABLED {
        eprintln!("stages: build with `--features stages` to count them");
        std::process::exit(2);
    }
    let steps = stage_clock::take_steps();
    let from = from.unwrap_or(steps.len() / 2).min(steps.len());
    let counted = &steps[from..];
    if counted.is_empty() {
        eprintln!("stages: no steps from step {from} on");
        std::process::exit(2);
    }
    println!(
        "\n| stage ({} steps from step {from}) | fewest cycles | median |",
        counted.len()
    );
    println!("| --- | ---: | ---: |");
    for (k, stage) in Stage::ALL.iter().enumerate() {
        let mut cycles: Vec<u64> = counted.iter().map(|s| s[k]).collect();
        cycles.sort_unstable();
        let fewest = cycles[0];
        let median = cycles[cycles.len() / 2];
        println!("| {} | {fewest} | {median} |", stage.name());
    }
}

/// `stages <scene> [steps=N] [from=K]`, in a build with the feature `stages`: pe
/// `soft`'s stage clock beside rapier2d's own timers (its `Counters`) and Box2D v3's own
/// profile (`b2World_GetProfile`) on one of `pile_scenes`, each engine's N steps (300 by
/// default) after the other's, each stage's median microseconds over the steps from the
/// K-th (half way by default), the stages matched as closely as the steps allow (a row
/// with no stage of an engine reads 0: that engine times it within another row). The peers
/// time their stages with the wall clock, pe with its stage clock, converted at the rate
/// `stage_clock::ticks_per_microsecond` measures.
fn run_stages_beside_peers() {
    use pe::stage_clock::{self, Stage};
    let args: Vec<String> = std::env::args().skip(2).collect();
    let scene = args.first().cloned().unwrap_or_default();
    let Some(mut jobs) = pile_jobs(&scene) else {
        eprintln!("stages: one of {}", pile_scenes().join(", "));
        std::process::exit(2);
    };
    if !stage_clock::ENABLED {
        eprintln!("stages: build with `--features stages` to count them");
        std::process::exit(2);
    }
    let number = |prefix: &str| {
        args.iter()
            .find_map(|f| f.strip_prefix(prefix)?.parse::<usize>().ok())
    };
    let steps = number("steps=").unwrap_or(300).max(2);
    let from = number("from=").unwrap_or(steps / 2).min(steps - 1);
    harness::fixed_steps(steps);
    // `pile_jobs`: pe `soft`, rapier2d, Box2D v3.
    let box2d_job = jobs.pop().expect("Box2D v3's job");
    let rapier_job = jobs.pop().expect("rapier2d's job");
    let pe_run = jobs.swap_remove(0)();
    let pe_steps = stage_clock::take_steps();
    let ticks_per_microsecond = stage_clock::ticks_per_microsecond().expect("enabled");
    rapier_scenes::PROFILES.keep();
    rapier_job();
    let rapier = rapier_scenes::PROFILES.take();
    box2d_scenes::PROFILES.keep();
    box2d_job();
    let box2d = box2d_scenes::PROFILES.take();
    let median = |mut values: Vec<f64>| {
        values.sort_by(f64::total_cmp);
        values[values.len() / 2]
    };
    let pe_time = |stages: &[Stage]| {
        median(
            pe_steps[from..]
                .iter()
                .map(|step| {
                    let ticks: u64 = stages.iter().map(|&s| step[s as usize]).sum();
                    ticks as f64 / ticks_per_microsecond
                })
                .collect(),
        )
    };
    type RapierFields = fn(&rapier_scenes::Profile) -> f64;
    let rapier_time = |fields: RapierFields| median(rapier[from..].iter().map(fields).collect());
    type Box2dFields = fn(&boxdd::Profile) -> f32;
    let box2d_time = |fields: Box2dFields| {
        median(
            box2d[from..]
                .iter()
                .map(|p| 1000.0 * f64::from(fields(p)))
                .collect(),
        )
    };
    struct Row {
        name: &'static str,
        pe: &'static [Stage],
        rapier: RapierFields,
        rapier_names: &'static str,
        box2d: Box2dFields,
        box2d_names: &'static str,
    }
    let rows = [
        Row {
            name: "broad phase",
            pe: &[Stage::BroadPhase],
            rapier: |p| p.broad_phase,
            rapier_names: "broad phase (both)",
            box2d: |p| p.pairs + p.refit,
            box2d_names: "pairs + refit",
        },
        Row {
            name: "narrow phase and contacts",
            pe: &[Stage::NarrowPhase, Stage::Contacts],
            rapier: |p| p.narrow_phase,
            rapier_names: "narrow phase",
            box2d: |p| p.collide,
            box2d_names: "collide",
        },
        Row {
            name: "preparing",
            pe: &[Stage::Preparing],
            rapier: |p| p.islands + p.assembly,
            rapier_names: "islands + velocity assembly",
            box2d: |p| p.solver_setup + p.prepare_constraints,
            box2d_names: "solverSetup + prepareConstraints",
        },
        Row {
            name: "velocities integrated",
            pe: &[],
            rapier: |p| p.update,
            rapier_names: "update (bodies and forces)",
            box2d: |p| p.integrate_velocities,
            box2d_names: "integrateVelocities (pe: in the rest)",
        },
        Row {
            name: "warm start",
            pe: &[Stage::WarmStart],
            rapier: |_| 0.0,
            rapier_names: "(in velocity resolution)",
            box2d: |p| p.warm_start,
            box2d_names: "warmStart",
        },
        Row {
            name: "solve",
            pe: &[Stage::Solve],
            rapier: |p| p.resolution,
            rapier_names: "velocity resolution (passes, integration, writeback)",
            box2d: |p| p.solve_impulses + p.integrate_positions + p.relax_impulses,
            box2d_names: "solveImpulses + integratePositions + relaxImpulses",
        },
        Row {
            name: "storing",
            pe: &[Stage::Storing],
            rapier: |_| 0.0,
            rapier_names: "(in velocity resolution)",
            box2d: |p| p.store_impulses + p.transforms,
            box2d_names: "storeImpulses + transforms",
        },
        Row {
            name: "continuous collision",
            pe: &[Stage::Continuous],
            rapier: |p| p.ccd,
            rapier_names: "ccd",
            box2d: |p| p.bullets,
            box2d_names: "bullets (other fast bodies: in transforms)",
        },
    ];
    let whole = (
        pe_time(&[Stage::Step]),
        rapier_time(|p| p.step),
        box2d_time(|p| p.step),
    );
    println!(
        "{scene} under pe soft: {pe_run:?}\n\n{scene} over {} steps from step {from}, \
         median microseconds a step (the stage clock at {ticks_per_microsecond:.0} ticks \
         a microsecond)\n",
        steps - from,
    );
    println!("| stage | pe soft | rapier2d | Box2D v3 | rapier2d's timers | Box2D v3's fields |");
    println!("| --- | ---: | ---: | ---: | --- | --- |");
    let print_row = |name: &str, (pe, rapier, b2): (f64, f64, f64), names: (&str, &str)| {
        println!(
            "| {name} | {pe:.0} | {rapier:.0} | {b2:.0} | {} | {} |",
            names.0, names.1
        );
    };
    let mut parts = (0.0, 0.0, 0.0);
    for row in rows {
        let times = (
            pe_time(row.pe),
            rapier_time(row.rapier),
            box2d_time(row.box2d),
        );
        parts = (parts.0 + times.0, parts.1 + times.1, parts.2 + times.2);
        print_row(row.name, times, (row.rapier_names, row.box2d_names));
    }
    let rest = (whole.0 - parts.0, whole.1 - parts.1, whole.2 - parts.2);
    let rest_names = ("step less the above", "step less the above");
    print_row(
        "the rest (whole step less the medians above)",
        rest,
        rest_names,
    );
    print_row("whole step", whole, ("step", "step"));
}

/// The scenes of `pile`: every pile, the joint grid and the smash.
fn pile_scenes() -> Vec<&'static str> {
    let mut names: Vec<&str> = PYRAMIDS.iter().map(|p| p.name).collect();
    names.extend([joint_grid::NAME, smash::NAME]);
    names
}

/// pe `soft`, rapier2d and Box2D v3 on one of `pile_scenes`, in that order, as jobs for
/// `interleaved`; `None` for another scene.
fn pile_jobs(scene: &str) -> Option<Vec<Job<'static>>> {
    let pe = PeConfig::new(ContactSolver::Soft);
    if let Some(spec) = PYRAMIDS.iter().find(|p| p.name == scene) {
        Some(vec![
            Box::new(move || pe_scenes::pyramid(pe, spec, H)),
            Box::new(move || rapier_scenes::pyramid(spec, H, rapier_scenes::ITERATIONS)),
            Box::new(move || box2d_scenes::pyramid(spec, H, box2d_scenes::SUBSTEPS)),
        ])
    } else if scene == joint_grid::NAME {
        Some(vec![
            Box::new(move || pe_scenes::joint_grid(pe)),
            Box::new(rapier_scenes::joint_grid),
            Box::new(box2d_scenes::joint_grid),
        ])
    } else if scene == smash::NAME {
        Some(vec![
            Box::new(move || pe_scenes::smash(pe)),
            Box::new(rapier_scenes::smash),
            Box::new(box2d_scenes::smash),
        ])
    } else {
        None
    }
}

/// One round of `pile_jobs`: pe soft, rapier2d and Box2D v3 taking turns.
struct PileRound {
    pe: Outcome,
    rapier: Outcome,
    box2d: Outcome,
}

impl PileRound {
    fn run(scene: &str) -> Option<Self> {
        let [pe, rapier, box2d] =
            <[Outcome; 3]>::try_from(interleaved(pile_jobs(scene)?)).expect("three engines");
        Some(Self { pe, rapier, box2d })
    }

    /// pe's median over rapier2d's and over Box2D v3's.
    fn ratios(&self) -> (f64, f64) {
        let of = |peer: &Outcome| time_ratio(self.pe.timing.median, peer.timing.median);
        (of(&self.rapier), of(&self.box2d))
    }
}

/// The smallest and largest of some ratios, as "lo–hi".
fn ratio_range(ratios: impl Iterator<Item = f64>) -> String {
    let (lo, hi) = ratios.fold((f64::INFINITY, 0.0_f64), |(lo, hi), r| {
        (lo.min(r), hi.max(r))
    });
    format!("{lo:.2}–{hi:.2}")
}

/// `pile <scene> [rounds]`: pe soft, rapier2d and Box2D v3 on one pile (or the joint grid,
/// or the smash), taking turns (`interleaved`), for a few rounds, printing each round's
/// medians and the ratios (a quick check while working on the soft step).
fn run_pile_with_peers() {
    let scene = std::env::args()
        .nth(2)
        .unwrap_or_else(|| "pyramid20".into());
    let rounds: usize = std::env::args()
        .nth(3)
        .and_then(|r| r.parse().ok())
        .unwrap_or(3);
    let mut done = Vec::with_capacity(rounds);
    for round in 1..=rounds {
        let Some(r) = PileRound::run(&scene) else {
            eprintln!(
                "unknown scene {scene:?}: one of {}",
                pile_scenes().join(", ")
            );
            std::process::exit(2);
        };
        let (to_rapier, to_box2d) = r.ratios();
        println!(
            "{scene} round {round}: pe soft {} ({}), rapier2d {} ({}), Box2D v3 {} ({}); \
             pe ÷ rapier2d {to_rapier:.2}, pe ÷ Box2D v3 {to_box2d:.2}",
            pretty(r.pe.timing.median),
            r.pe.metric,
            pretty(r.rapier.timing.median),
            r.rapier.metric,
            pretty(r.box2d.timing.median),
            r.box2d.metric,
        );
        done.push(r);
    }
    println!(
        "{scene} over {rounds} rounds: pe ÷ rapier2d {}, pe ÷ Box2D v3 {}",
        ratio_range(done.iter().map(|r| r.ratios().0)),
        ratio_range(done.iter().map(|r| r.ratios().1))
    );
}

/// The main run's closing rounds: pe `soft` and the two peers alone on each of
/// `pile_scenes`, `PILE_ROUNDS` times.
const PILE_ROUNDS: usize = 3;

fn pile_rows() -> Vec<(&'static str, Vec<PileRound>)> {
    pile_scenes()
        .into_iter()
        .map(|scene| {
            eprintln!("{scene}: pe soft, rapier2d, Box2D v3 taking turns, {PILE_ROUNDS} rounds…");
            let rounds = (0..PILE_ROUNDS)
                .map(|_| PileRound::run(scene).expect("a pile scene"))
                .collect();
            (scene, rounds)
        })
        .collect()
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

/// pe soft with the narrow phase's manifold reuse on and off, on the scenes of many
/// resting contacts, taking turns (`interleaved`) so that both see the machine in the
/// same states.
struct NarrowRow {
    scene: String,
    reuse: Outcome,
    fresh: Outcome,
}

fn narrow_phase_rows() -> Vec<NarrowRow> {
    let reuse = PeConfig::new(ContactSolver::Soft);
    let fresh = PeConfig {
        reuse_manifolds: false,
        ..reuse
    };
    let both = |scene: &str, run: &(dyn Fn(PeConfig) -> Outcome + Sync)| {
        eprintln!("{scene}: pe soft with and without manifold reuse, taking turns…");
        let [reuse, fresh] = <[Outcome; 2]>::try_from(interleaved(vec![
            Box::new(move || run(reuse)) as Job<'_>,
            Box::new(move || run(fresh)),
        ]))
        .expect("two runs");
        NarrowRow {
            scene: scene.to_string(),
            reuse,
            fresh,
        }
    };
    let mut out: Vec<NarrowRow> = PYRAMIDS
        .iter()
        .map(|spec| both(spec.name, &|c| pe_scenes::pyramid(c, spec, H)))
        .collect();
    out.push(both(smash::NAME, &pe_scenes::smash));
    out
}

/// A duration with three significant figures in a readable unit.
pub fn pretty(d: Duration) -> String {
    let s = d.as_secs_f64();
    let (value, unit) = match s {
        s if s < 1e-3 => (s * 1e6, "µs"),
        s if s < 1.0 => (s * 1e3, "ms"),
        s => (s, "s"),
    };
    match value {
        v if v < 10.0 => format!("{v:.2} {unit}"),
        v if v < 100.0 => format!("{v:.1} {unit}"),
        v => format!("{v:.0} {unit}"),
    }
}

/// A time cell: the median, flagged when the run was cut short by the budget.
fn time_cell(t: &Timing) -> String {
    if t.cut_short() {
        format!("{} † ({} timed)", pretty(t.median), t.timed_steps)
    } else {
        pretty(t.median)
    }
}

/// A metric cell, flagged with how much of the scene was simulated when cut short.
fn metric_cell(o: &Outcome) -> String {
    if o.timing.cut_short() {
        format!(
            "{} † (after {} of {} steps)",
            o.metric, o.timing.steps_run, o.timing.planned
        )
    } else {
        o.metric.to_string()
    }
}

/// pe's time over a peer's.
fn time_ratio(pe: Duration, peer: Duration) -> f64 {
    pe.as_secs_f64() / peer.as_secs_f64()
}

fn ratio(pe: Duration, peer: Duration) -> String {
    let r = time_ratio(pe, peer);
    if r < 100.0 {
        format!("{r:.2}")
    } else {
        format!("{r:.0}")
    }
}

fn report(
    rows: &[Row],
    piles: &[(&str, Vec<PileRound>)],
    narrow: &[NarrowRow],
    robot_rows: &[robots::RobotRow],
    throw_rows: &[throws::ThrowsRow],
    elapsed: Duration,
    (load, code): (&str, &str),
) -> String {
    let names: Vec<&str> = PE_SOLVERS.iter().map(|s| s.name()).collect();
    let mut md = String::new();
    let w = &mut md;
    // Writing to a String cannot fail.
    let _ = writeln!(w, "# pe vs rapier2d and Box2D v3\n");
    let _ = writeln!(w, "- Machine: {}; load average at start: {load}", machine());
    let _ = writeln!(w, "- Date: {} (UTC); {code}", today());
    let _ = writeln!(
        w,
        "- Engines: pe (this repository, f64) with contact solvers `{}`; rapier2d {} \
         (f32, {}, one thread), default `IntegrationParameters` except `dt`, \
         every body with `can_sleep(false)`; Box2D v3 through boxdd {} (built by cc: \
         {}; f32, one worker), default world settings with {} substeps, sleeping off. \
         Every engine's Rust compiled for this processor (`target-cpu=native`, \
         bench/.cargo/config.toml).",
        names.join("`, `"),
        rapier_version(),
        PeerBuild::CURRENT.rapier2d(),
        locked_version("boxdd"),
        PeerBuild::CURRENT.box2d(),
        box2d_scenes::SUBSTEPS
    );
    let _ = writeln!(
        w,
        "- Timing: the engines of a scene take turns of {TURN_STEPS} steps (each in its \
         own thread, one running at a time), so that all of them see the machine in the \
         same states; each step is timed alone with `std::time::Instant`; the first \
         {WARMUP_STEPS} steps of a run are a warm-up, simulated but not timed (only those \
         ending within the run's first {} s of turns, so a run of multi-second steps is \
         timed from its first step), and neither is the first step of each later turn \
         (the other engines' turns may have emptied the caches); the figure is the median of \
         the timed steps (mean of the middle two for an even count). Release build.",
        WARMUP_WALL.as_secs()
    );
    let _ = writeln!(
        w,
        "- Budget: a run starts no new step after {} s of its own turns once one step is timed; \
         runs cut short are marked †, and their metric covers only the steps run.",
        RUN_BUDGET.as_secs()
    );
    let _ = writeln!(
        w,
        "- Step h = 1/60 s except where the scene says; g = 10 m/s². pyramid40 is planned \
         for 300 steps (5 s) instead of 600 to bound the run time; large_pyramid (base 100, \
         5,050 boxes) for 500 steps as in Box2D's benchmark; many_pyramids (10 × 10 pyramids \
         of base 10, 5,500 boxes, ten to a floor on ten floors) for 300; smash (an 8 m box of density 10 \
         at 40 m/s into 120 × 80 boxes of 0.5 m, no gravity) and joint_grid (100 × 100 bodies, \
         19,800 pins) for 300; the pendulums run 60 s."
    );
    let _ = writeln!(w, "- Whole benchmark: {:.0} s.\n", elapsed.as_secs_f64());

    let _ = writeln!(w, "## Time per step (median)\n");
    let engines: Vec<String> = names
        .iter()
        .map(|n| format!("pe {n}"))
        .chain(PEERS.iter().map(|p| p.to_string()))
        .collect();
    let ratios = PEERS
        .iter()
        .flat_map(|peer| names.iter().map(move |n| format!("pe {n} ÷ {peer}")));
    let columns: Vec<String> = std::iter::once("steps planned (timed)".to_string())
        .chain(engines.iter().cloned())
        .chain(ratios)
        .collect();
    let _ = writeln!(w, "{}", table_head(&["scene"], &columns, "---:"));
    for r in rows {
        let t = &r.peers[0].timing;
        let _ = write!(w, "| {} | {} ({}) |", r.scene, t.planned, t.timed_steps);
        for o in r.pe.iter().chain(&r.peers) {
            let _ = write!(w, " {} |", time_cell(&o.timing));
        }
        for peer in &r.peers {
            for o in &r.pe {
                let _ = write!(w, " {} |", ratio(o.timing.median, peer.timing.median));
            }
        }
        let _ = writeln!(w);
    }

    let _ = writeln!(w, "\n## Accuracy and stability\n");
    let _ = writeln!(
        w,
        "{}",
        table_head(&["scene", "known answer"], &engines, "---")
    );
    for r in rows {
        let _ = write!(w, "| {} | {} |", r.scene, r.known);
        for o in r.pe.iter().chain(&r.peers) {
            let _ = write!(w, " {} |", metric_cell(o));
        }
        let _ = writeln!(w);
    }
    let _ = writeln!(
        w,
        "\nMetrics: pyramids — the top box's sideways displacement over the run in box \
         widths, the most it sank (box heights: soft contacts sag under the load), and how \
         many boxes ever moved more than half a box sideways; pendulums — \
         period from upward zero crossings of x against the exact compound-pendulum period, \
         and max |E − E0| / (m g L); heavychain — widest joint gap at any step (link \
         length 1 m; joint_grid the same, bodies 1 m apart); bounce — first rebound peak of the box's bottom against e²·h; smash \
         — the largest drift of the total linear momentum from its start (no gravity, no \
         static body: it is conserved exactly), the kinetic energy left at the end, and the \
         deepest any two boxes overlapped after any step (the same separating-axis test on \
         every engine's poses)."
    );

    let _ = writeln!(
        w,
        "\n## pe soft and the peers alone, {PILE_ROUNDS} rounds\n"
    );
    let _ = writeln!(
        w,
        "The table above takes five engines' turns, pe `exact`'s and `auto`'s among them. \
         Here pe `soft`, rapier2d and Box2D v3 take turns alone on the big scenes, {PILE_ROUNDS} \
         times over (`cargo run --release -- pile <scene>`): each round's medians, then the \
         range of the ratios over the rounds.\n"
    );
    let columns: Vec<String> = (1..=PILE_ROUNDS)
        .map(|k| format!("round {k}: pe soft / rapier2d / Box2D v3"))
        .chain(["pe soft ÷ rapier2d".into(), "pe soft ÷ Box2D v3".into()])
        .collect();
    let _ = writeln!(w, "{}", table_head(&["scene"], &columns, "---:"));
    for (scene, rounds) in piles {
        let _ = write!(w, "| {scene} |");
        for r in rounds {
            let _ = write!(
                w,
                " {} / {} / {} |",
                time_cell(&r.pe.timing),
                time_cell(&r.rapier.timing),
                time_cell(&r.box2d.timing)
            );
        }
        let _ = writeln!(
            w,
            " {} | {} |",
            ratio_range(rounds.iter().map(|r| r.ratios().0)),
            ratio_range(rounds.iter().map(|r| r.ratios().1))
        );
    }

    let _ = writeln!(w, "\n## Narrow phase: manifold reuse (pe soft)\n");
    let _ = writeln!(
        w,
        "A pair whose relative pose has moved less than a tenth of the slop since its \
         manifold was found keeps that manifold's features (recomputed at the current \
         poses) instead of a new separating-axis test; `fresh` tests every pair every step. \
         The two runs of a scene take turns.\n"
    );
    let columns: Vec<String> = [
        "reuse: time per step",
        "fresh: time per step",
        "fresh ÷ reuse",
        "reuse: result",
        "fresh: result",
    ]
    .map(String::from)
    .to_vec();
    let _ = writeln!(w, "{}", table_head(&["scene"], &columns, "---:"));
    for r in narrow {
        let _ = writeln!(
            w,
            "| {} | {} | {} | {} | {} | {} |",
            r.scene,
            time_cell(&r.reuse.timing),
            time_cell(&r.fresh.timing),
            ratio(r.fresh.timing.median, r.reuse.timing.median),
            metric_cell(&r.reuse),
            metric_cell(&r.fresh)
        );
    }

    let _ = writeln!(w, "\n## Robots of the default database (pe only)\n");
    let _ = writeln!(
        w,
        "The scenes of data/ as the app and the CLI run them (`robosim::sim::Simulation`, \
         motors on, {} steps at the scene's time step), under each contact solver: median \
         time per step, and in brackets the widest any joint opened during the run (px). \
         The peers have no thesis motors, so there is no peer column.\n",
        robots::STEPS
    );
    let solvers: Vec<String> = robots::SOLVERS
        .iter()
        .map(|s| format!("pe {}", s.name()))
        .collect();
    let _ = writeln!(w, "{}", table_head(&["scene"], &solvers, "---:"));
    for r in robot_rows {
        let _ = write!(w, "| {} |", r.scene);
        for (timing, widest) in &r.runs {
            let _ = write!(w, " {} ({widest:.1e}) |", time_cell(timing));
        }
        let _ = writeln!(w);
    }
    write_throws(w, throw_rows, throws::SEED);
    md
}

/// The random throws' section: each engine's throws that sank, by class, and that gained
/// energy.
fn write_throws(w: &mut String, rows: &[throws::ThrowsRow], seed: u64) {
    let Some(first) = rows.first() else {
        return;
    };
    let _ = writeln!(w, "\n## Random throws\n");
    let _ = writeln!(
        w,
        "The worlds of pe's hard-case tests (`physics/tests/support/random_throws.rs`): 2–23 \
         regular polygons (3–8 sides, radius 0.2–1.5 m, density 1; random poses, velocities \
         up to 5 m/s, spins up to 3 rad/s, restitution 0, 0.3 or 0.8) thrown into a walled \
         box 20 m wide, friction 0.5, g = 10 m/s², 1,000 steps of 1/60 s; the same {} \
         worlds (seed {seed}) in every engine, a pair taking the smaller restitution in \
         each. A throw sinks when, after its first 2 s, two bodies overlap by more than a \
         fifth of its smallest body's radius, by pe's separating-axis test on each \
         engine's poses after every step; it is counted as overlapping from the start (the \
         pair already did in the first 3 steps), in one step (an impact: within the bound \
         the step before) or gradually. A throw gains energy when its bodies' kinetic and \
         potential energy (each body's mass and inertia from its shape) rises after any \
         step by more than 1% of Σ m g × the box's height above its start. pe's length \
         scale is the median radius (as the app sets a scene's); the peers run at their \
         defaults (1 m). The time is the stepping alone, all throws together.\n",
        first.throws
    );
    let columns = [
        "throws that sink",
        "from the start / in one step / gradually",
        "deepest overlap (smallest radii)",
        "throws that gain energy (most gained)",
        "time stepping",
    ]
    .map(String::from);
    let _ = writeln!(w, "{}", table_head(&["engine"], &columns, "---:"));
    for r in rows {
        let [start, impact, gradual] = r.sunk;
        let _ = writeln!(
            w,
            "| {} | {} of {} ({:.1}%) | {start} / {impact} / {gradual} | {:.2} | {} ({:.3}) | {:.1} s |",
            r.engine,
            r.sunk_total(),
            r.throws,
            100.0 * r.sunk_total() as f64 / r.throws as f64,
            r.deepest,
            r.gained,
            r.most_gained,
            r.stepping.as_secs_f64()
        );
    }
}

/// A Markdown table's header row and rule: the `lead` columns left-aligned, then
/// `columns` with the alignment `rule` (`---` or `---:`).
fn table_head(lead: &[&str], columns: &[String], rule: &str) -> String {
    let names: Vec<&str> = lead
        .iter()
        .copied()
        .chain(columns.iter().map(String::as_str))
        .collect();
    let rules: Vec<&str> = lead
        .iter()
        .map(|_| "---")
        .chain(columns.iter().map(|_| rule))
        .collect();
    format!("| {} |\n|{}|", names.join(" | "), rules.join("|"))
}

/// The 1-, 5- and 15-minute load averages: other work on the machine slows every engine.
fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .map(|l| l.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|| "unknown".into())
}

/// The code measured: the repository's commit, and whether pe's or the bench's sources
/// differ from it (a run of work in progress), from `git` at the start of the run.
fn code_version() -> String {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/..");
    let git = |args: &[&str]| {
        let out = std::process::Command::new("git")
            .arg("-C")
            .arg(root)
            .args(args)
            .output()
            .ok()
            .filter(|o| o.status.success())?;
        String::from_utf8(out.stdout).ok()
    };
    let Some(commit) = git(&["rev-parse", "--short", "HEAD"]) else {
        return "code: unknown (no git repository)".into();
    };
    let sources = [
        "physics",
        "bench/src",
        "bench/Cargo.toml",
        "bench/Cargo.lock",
        "bench/.cargo",
    ];
    let status = git(&[&["status", "--porcelain", "--"][..], &sources[..]].concat());
    let changed = match status.as_deref() {
        Some("") => "",
        Some(_) => ", with uncommitted changes to pe or the bench",
        None => ", changes unknown",
    };
    format!("code of commit {}{changed}", commit.trim())
}

/// CPU model and logical core count, from /proc/cpuinfo (Linux).
fn machine() -> String {
    let Ok(info) = std::fs::read_to_string("/proc/cpuinfo") else {
        return "unknown (no /proc/cpuinfo)".into();
    };
    // `name: value`, as /proc/cpuinfo lists its fields ("model" is not "model name").
    let field = |name: &str| {
        info.lines()
            .find_map(|l| l.strip_prefix(name)?.trim_start().strip_prefix(':'))
            .map(str::trim)
    };
    let model = field("model name").unwrap_or("unknown CPU");
    let cores = info.lines().filter(|l| l.starts_with("processor")).count();
    // Same-model names cover several generations (an EPYC with AVX-512 or without), and
    // pe's batches run as wide as the processor allows.
    format!(
        "{model} (family {}, model {}), {cores} logical cores; pe's soft-step batches in {}",
        field("cpu family").unwrap_or("?"),
        field("model").unwrap_or("?"),
        pe::lane_path_name()
    )
}

/// The flags cc added after boxdd's own when it compiled Box2D's C sources (`CFLAGS`, set
/// by bench/.cargo/config.toml unless the shell sets it): the later flags win.
const BOX2D_CFLAGS: Option<&str> = option_env!("CFLAGS");

/// How the peers were built (bench/Cargo.toml, feature `fastest-peers`).
#[derive(Debug, Clone, Copy, PartialEq)]
enum PeerBuild {
    /// Box2D v3 with `BOX2D_AVX2`, rapier2d with eight solver lanes: each one's fastest
    /// on a processor with AVX2.
    Fastest,
    /// Both as their default features build them: four f32 lanes in SSE2.
    Default,
}

impl PeerBuild {
    const CURRENT: Self = if cfg!(feature = "fastest-peers") {
        Self::Fastest
    } else {
        Self::Default
    };

    fn rapier2d(self) -> &'static str {
        match self {
            Self::Fastest => "feature `simd8`: eight solver lanes, in AVX2",
            Self::Default => "default features: four solver lanes",
        }
    }

    /// Box2D's commit, its lanes and its C flags.
    fn box2d(self) -> String {
        let lanes = match self {
            Self::Fastest => "`BOX2D_AVX2`: eight lanes in AVX2",
            Self::Default => "boxdd's default: four lanes in SSE2",
        };
        let flags = match BOX2D_CFLAGS.map(str::trim) {
            Some(f) if !f.is_empty() => format!("C compiled with boxdd's flags and then `{f}`"),
            _ => "C compiled with boxdd's flags (-O2, asserts in)".into(),
        };
        let commit = boxdd_sys::UPSTREAM_SHA.get(..7).unwrap_or("unknown");
        format!("Box2D's sources of commit {commit}, {lanes}, {flags}")
    }

    /// Whether this processor runs the build: Box2D's AVX2 build would stop at its
    /// first vector instruction on one without.
    fn runs_here(self) -> bool {
        #[cfg(target_arch = "x86_64")]
        if self == Self::Fastest {
            return std::arch::is_x86_feature_detected!("avx2");
        }
        true
    }
}

/// The rapier2d version actually built, from this crate's lock file.
fn rapier_version() -> &'static str {
    locked_version("rapier2d")
}

/// A dependency's version as this crate's lock file records it.
fn locked_version(name: &str) -> &'static str {
    let lock = include_str!("../Cargo.lock");
    let wanted = format!("name = \"{name}\"");
    lock.split("[[package]]")
        .find(|p| p.lines().any(|l| l.trim() == wanted))
        .and_then(|p| p.lines().find_map(|l| l.strip_prefix("version = ")))
        .map_or("(unknown version)", |v| v.trim_matches('"'))
}

/// Today's date (UTC) as YYYY-MM-DD, without a date library: days since 1970 to the
/// proleptic Gregorian calendar (H. Hinnant's `civil_from_days`).
fn today() -> String {
    let secs = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let (y, m, d) = civil_from_days((secs / 86_400) as i64);
    format!("{y:04}-{m:02}-{d:02}")
}

fn civil_from_days(days: i64) -> (i64, u32, u32) {
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let m = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    let y = yoe + era * 400 + i64::from(m <= 2);
    (y, m, d)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bench runs from its repository: results.md names the commit it measured, and
    /// says so when pe's or the bench's sources differ from it.
    #[test]
    fn the_code_measured_is_named_by_its_commit() {
        let code = code_version();
        let commit = code.strip_prefix("code of commit ").expect(&code);
        let hash = commit.split(',').next().unwrap();
        assert!(
            hash.len() >= 7 && hash.chars().all(|c| c.is_ascii_hexdigit()),
            "{code}"
        );
        let rest = &commit[hash.len()..];
        assert!(
            ["", ", with uncommitted changes to pe or the bench"].contains(&rest),
            "{code}"
        );
    }

    #[test]
    fn table_heads_align_the_lead_left() {
        let columns = ["a".to_string(), "b".to_string()];
        assert_eq!(
            table_head(&["scene"], &columns, "---:"),
            "| scene | a | b |\n|---|---:|---:|"
        );
    }

    #[test]
    fn civil_dates() {
        assert_eq!(civil_from_days(0), (1970, 1, 1));
        assert_eq!(civil_from_days(11_016), (2000, 2, 29));
        assert_eq!(civil_from_days(20_454), (2026, 1, 1));
    }

    /// results.md names the Box2D commit boxdd built and the C flags it got.
    #[test]
    fn the_box2d_build_names_its_commit_and_flags() {
        let build = PeerBuild::CURRENT.box2d();
        let commit = build
            .strip_prefix("Box2D's sources of commit ")
            .expect(&build);
        assert!(
            commit.chars().take(7).all(|c| c.is_ascii_hexdigit()),
            "{build}"
        );
        assert!(build.contains("C compiled with boxdd's flags"), "{build}");
    }

    #[test]
    fn the_lock_file_names_rapier() {
        assert!(rapier_version().starts_with("0."));
    }
}
