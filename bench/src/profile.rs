//! Profiling commands: `pe <scene> ...` (one scene in pe alone, optionally with its stage
//! clock) and `stages <scene>` (pe soft's stages beside rapier2d's and Box2D v3's own
//! profiles of the same scene).

use crate::piles::{pile_jobs, pile_scenes};
use crate::scene::{H, PYRAMIDS, joint_grid, smash};
use crate::{box2d_scenes, harness, pe_scenes, rapier_scenes};
use pe::ContactSolver;
use pe::Stage;
use pe_scenes::PeConfig;

/// `pe <scene> [solver] [fresh] [forwards] [substeps=S] [steps=N] [stages [from=K]]`: one
/// pile, grid or smash scene in pe alone, so that a profiler sees only pe's step (`fresh`:
/// no manifold reuse; `forwards`: the soft step sweeps its colours in one order only;
/// `substeps=S`: the soft step's substeps instead of the default 4; `steps=N`:
/// exactly N steps, with no time budget, so that two builds' instruction counts compare;
/// `stages`, in a build with the feature `stages`: the fewest and the median cycles of each
/// stage of the step, over the steps from the K-th, by default from half way).
pub fn run_pe_alone() {
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
    let stages = flags.iter().any(|f| f == "stages");
    if stages {
        if !cfg!(feature = "stages") {
            eprintln!("stages: build with `--features stages` to count them");
            std::process::exit(2);
        }
        pe_scenes::PROFILES.keep();
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
    if stages {
        let from = flags
            .iter()
            .find_map(|f| f.strip_prefix("from=")?.parse().ok());
        print_stage_cycles(from);
    }
}

/// The table of `pe <scene> ... stages`: each stage's fewest and median cycles a step over
/// the steps from `from` on (half way by default), from pe's profiles (`World::profile`).
fn print_stage_cycles(from: Option<usize>) {
    let steps: Vec<_> = pe_scenes::PROFILES.take().iter().map(|p| p.ticks).collect();
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
/// `pe::ticks_per_microsecond` measures.
pub fn run_stages_beside_peers() {
    let args: Vec<String> = std::env::args().skip(2).collect();
    let scene = args.first().cloned().unwrap_or_default();
    let Some(mut jobs) = pile_jobs(&scene) else {
        eprintln!("stages: one of {}", pile_scenes().join(", "));
        std::process::exit(2);
    };
    if !cfg!(feature = "stages") {
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
    pe_scenes::PROFILES.keep();
    let pe_run = jobs.swap_remove(0)();
    let pe_steps: Vec<_> = pe_scenes::PROFILES.take().iter().map(|p| p.ticks).collect();
    let ticks_per_microsecond = pe::ticks_per_microsecond().expect("enabled");
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
    let rapier_time = |fields: RapierFields| median(rapier[from..].iter().map(fields).collect());
    let box2d_time = |fields: Box2dFields| {
        median(
            box2d[from..]
                .iter()
                .map(|p| 1000.0 * f64::from(fields(p)))
                .collect(),
        )
    };
    let rows = stage_rows();
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

type RapierFields = fn(&rapier_scenes::Profile) -> f64;
type Box2dFields = fn(&boxdd::Profile) -> f32;

/// One row of the `stages` table: pe's stages and each peer's fields that time the same
/// work, with the peers' names for them.
struct StageRow {
    name: &'static str,
    pe: &'static [Stage],
    rapier: RapierFields,
    rapier_names: &'static str,
    box2d: Box2dFields,
    box2d_names: &'static str,
}

/// The `stages` table's rows, in the order of the step.
fn stage_rows() -> [StageRow; 8] {
    [
        StageRow {
            name: "broad phase",
            pe: &[Stage::BroadPhase],
            rapier: |p| p.broad_phase,
            rapier_names: "broad phase (both)",
            box2d: |p| p.pairs + p.refit,
            box2d_names: "pairs + refit",
        },
        StageRow {
            name: "narrow phase and contacts",
            pe: &[Stage::NarrowPhase, Stage::Contacts],
            rapier: |p| p.narrow_phase,
            rapier_names: "narrow phase",
            box2d: |p| p.collide,
            box2d_names: "collide",
        },
        StageRow {
            name: "preparing",
            pe: &[Stage::Preparing],
            rapier: |p| p.islands + p.assembly,
            rapier_names: "islands + velocity assembly",
            box2d: |p| p.solver_setup + p.prepare_constraints,
            box2d_names: "solverSetup + prepareConstraints",
        },
        StageRow {
            name: "velocities integrated",
            pe: &[],
            rapier: |p| p.update,
            rapier_names: "update (bodies and forces)",
            box2d: |p| p.integrate_velocities,
            box2d_names: "integrateVelocities (pe: in the rest)",
        },
        StageRow {
            name: "warm start",
            pe: &[Stage::WarmStart],
            rapier: |_| 0.0,
            rapier_names: "(in velocity resolution)",
            box2d: |p| p.warm_start,
            box2d_names: "warmStart",
        },
        StageRow {
            name: "solve",
            pe: &[Stage::Solve],
            rapier: |p| p.resolution,
            rapier_names: "velocity resolution (passes, integration, writeback)",
            box2d: |p| p.solve_impulses + p.integrate_positions + p.relax_impulses,
            box2d_names: "solveImpulses + integratePositions + relaxImpulses",
        },
        StageRow {
            name: "storing",
            pe: &[Stage::Storing],
            rapier: |_| 0.0,
            rapier_names: "(in velocity resolution)",
            box2d: |p| p.store_impulses + p.transforms,
            box2d_names: "storeImpulses + transforms",
        },
        StageRow {
            name: "continuous collision",
            pe: &[Stage::Continuous],
            rapier: |p| p.ccd,
            rapier_names: "ccd",
            box2d: |p| p.bullets,
            box2d_names: "bullets (other fast bodies: in transforms)",
        },
    ]
}
