//! results.md: the tables of the main run, from the rows the runs return.

use crate::format::{pretty, ratio_range, time_ratio};
use crate::harness::{RUN_BUDGET, TURN_STEPS, Timing, WARMUP_STEPS, WARMUP_WALL};
use crate::machine::{PeerBuild, locked_version, machine, rapier_version, today};
use crate::piles::{NarrowRow, PILE_ROUNDS, PileRound};
use crate::{Outcome, PE_SOLVERS, PEERS, Row, box2d_scenes, robots, throws};
use std::fmt::Write as _;
use std::time::Duration;

/// A time cell: the median, flagged when the run was cut short by the budget.
pub fn time_cell(t: &Timing) -> String {
    if t.cut_short() {
        format!("{} † ({} timed)", pretty(t.median), t.timed_steps)
    } else {
        pretty(t.median)
    }
}

/// A metric cell, flagged with how much of the scene was simulated when cut short.
pub fn metric_cell(o: &Outcome) -> String {
    if o.timing.cut_short() {
        format!(
            "{} † (after {} of {} steps)",
            o.metric, o.timing.steps_run, o.timing.planned
        )
    } else {
        o.metric.to_string()
    }
}

pub fn ratio(pe: Duration, peer: Duration) -> String {
    let r = time_ratio(pe, peer);
    if r < 100.0 {
        format!("{r:.2}")
    } else {
        format!("{r:.0}")
    }
}
pub fn report(
    rows: &[Row],
    piles: &[(&str, Vec<PileRound>)],
    narrow: &[NarrowRow],
    robot_rows: &[robots::RobotRow],
    throw_rows: &[throws::ThrowsRow],
    elapsed: Duration,
    (load, code): (&str, &str),
) -> String {
    let mut md = String::new();
    write_setup(&mut md, elapsed, (load, code));
    write_times(&mut md, rows);
    write_accuracy(&mut md, rows);
    write_piles(&mut md, piles);
    write_narrow_phase(&mut md, narrow);
    write_robots(&mut md, robot_rows);
    write_throws(&mut md, throw_rows, throws::SEED);
    md
}

// Writing to a String cannot fail: the sections ignore `writeln!`'s result.

/// The title and how the run was made: machine, date, code, engines, timing, budget.
fn write_setup(w: &mut String, elapsed: Duration, (load, code): (&str, &str)) {
    let names: Vec<&str> = PE_SOLVERS.iter().map(|s| s.name()).collect();
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
}

/// "pe exact", ..., "rapier2d", "Box2D v3": the engines of a `Row`, in its order.
fn engine_names() -> Vec<String> {
    PE_SOLVERS
        .iter()
        .map(|s| format!("pe {}", s.name()))
        .chain(PEERS.iter().map(|p| p.to_string()))
        .collect()
}

/// Each scene's median time per step in every engine, and pe's over the peers'.
fn write_times(w: &mut String, rows: &[Row]) {
    let names: Vec<&str> = PE_SOLVERS.iter().map(|s| s.name()).collect();
    let _ = writeln!(w, "## Time per step (median)\n");
    let engines = engine_names();
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
}

/// Each scene's outcome in every engine beside its known answer.
fn write_accuracy(w: &mut String, rows: &[Row]) {
    let engines = engine_names();
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
}

/// pe soft and the peers alone on the big scenes, round by round.
fn write_piles(w: &mut String, piles: &[(&str, Vec<PileRound>)]) {
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
}

/// pe soft with the narrow phase's manifold reuse on and off.
fn write_narrow_phase(w: &mut String, narrow: &[NarrowRow]) {
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
}

/// The default database's robots under each pe solver.
fn write_robots(w: &mut String, robot_rows: &[robots::RobotRow]) {
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
}

/// The random throws' section: each engine's throws that sank, by class, and that gained
/// energy.
pub fn write_throws(w: &mut String, rows: &[throws::ThrowsRow], seed: u64) {
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
pub fn table_head(lead: &[&str], columns: &[String], rule: &str) -> String {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_heads_align_the_lead_left() {
        let columns = ["a".to_string(), "b".to_string()];
        assert_eq!(
            table_head(&["scene"], &columns, "---:"),
            "| scene | a | b |\n|---|---:|---:|"
        );
    }
}
