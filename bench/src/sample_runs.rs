//! Box2D v3's Stacking and Robustness samples (`physics/tests/support/samples.rs`, shared
//! with pe's tests) in every engine: pe under `auto` (its default), `soft` and `exact`,
//! rapier2d and Box2D v3, each stepped and timed as the other scenes are (`measure`,
//! taking turns), with its moving bodies' centroids (y up), angles and velocities fed to
//! the sample's `Tracker` after every step, so that every engine is judged by the same code
//! against the same criterion.
//!
//! Each engine gets the sample's bodies as convex polygons with their own friction, mixed
//! by the geometric mean in all three (pe's rule and Box2D's; rapier2d's default is the
//! average, so its colliders ask for `GeometricMean`). Restitution is 0 throughout, so its
//! rule does not matter. pe scales its tolerances to the sample's bodies (`length_scale`
//! = the median moving body's size), as the app and pe's tests do; the peers keep their
//! defaults (Box2D's length unit and rapier2d's `length_unit`: 1 m), as their users would.
//! Sleeping is off everywhere, as in the other scenes.

#[path = "../../physics/tests/support/samples.rs"]
mod samples;

use crate::harness::{Timing, interleaved, measure};
use crate::{box2d_scenes, rapier_scenes};
use pe::{BodyDef, BodyHandle, ContactSolver, ConvexPolygon, IslandMethod, World};
use samples::{BodyState, Criterion, H, NAMES, Sample, SampleBody, Tracker, Verdict};
use std::fmt::Write as _;
use std::time::Duration;

/// The pe solvers run, pe's default first: the ratio columns are its.
const PE_SOLVERS: [ContactSolver; 3] = [
    ContactSolver::Auto,
    ContactSolver::Soft,
    ContactSolver::Exact,
];

/// A sample with at most this many moving bodies should step in at most `SMALL_BUDGET`
/// under pe's default solver.
const SMALL_SAMPLE: usize = 100;
const SMALL_BUDGET: Duration = Duration::from_millis(1);

/// Where pe's `auto` solves an island exactly, `exact` should cost at most this many times
/// `soft` on the same sample.
const EXACT_OVER_SOFT: f64 = 5.0;

/// One engine's run of a sample.
#[derive(Debug, Clone)]
pub struct SampleRun {
    pub timing: Timing,
    pub verdict: Verdict,
    /// The steps in which some island was solved by pivoting (pe only).
    pub pivoted_steps: usize,
}

/// One sample in every engine.
pub struct SampleRow {
    pub name: &'static str,
    pub moving: usize,
    pub criterion: Criterion,
    /// In the order of `PE_SOLVERS`.
    pub pe: Vec<SampleRun>,
    /// rapier2d, then Box2D v3.
    pub peers: Vec<SampleRun>,
}

/// Every sample named in `names` (all of them when empty), each in every engine taking
/// turns, in Box2D's order. Progress goes to stderr.
pub fn run(names: &[String]) -> Vec<SampleRow> {
    NAMES
        .iter()
        .filter(|n| names.is_empty() || names.iter().any(|m| m == *n))
        .map(|&name| {
            let sample = samples::sample(name).expect("a sample of that name");
            eprint!("sample {name}: pe auto, soft, exact, rapier2d, Box2D v3 taking turns…");
            let started = std::time::Instant::now();
            let sample = &sample;
            let mut jobs: Vec<Box<dyn FnOnce() -> SampleRun + Send + '_>> = PE_SOLVERS
                .iter()
                .map(|&s| Box::new(move || run_pe(sample, s)) as Box<dyn FnOnce() -> _ + Send>)
                .collect();
            jobs.push(Box::new(move || run_rapier(sample)));
            jobs.push(Box::new(move || run_box2d(sample)));
            let mut pe = interleaved(jobs);
            let peers = pe.split_off(PE_SOLVERS.len());
            eprintln!(" {:.1} s", started.elapsed().as_secs_f64());
            SampleRow {
                name,
                moving: sample.moving().count(),
                criterion: sample.criterion,
                pe,
                peers,
            }
        })
        .collect()
}

/// Steps a world through the sample under `measure`, judging it after every step from the
/// states `read` gives (`&mut` for boxdd's sake), and counting the steps `pivoted` says
/// were solved by pivoting.
fn run_engine<W>(
    sample: &Sample,
    world: &mut W,
    step: impl FnMut(&mut W),
    mut read: impl FnMut(&mut W) -> Vec<BodyState>,
    mut pivoted: impl FnMut(&W) -> bool,
) -> SampleRun {
    let mut tracker = Tracker::new(sample);
    let mut pivoted_steps = 0;
    let timing = measure(world, sample.steps(), step, |w, _| {
        tracker.update(read(w).into_iter());
        pivoted_steps += usize::from(pivoted(w));
    });
    SampleRun {
        timing,
        verdict: tracker.finish(),
        pivoted_steps,
    }
}

/// As pe's own sample tests build it (`physics/tests/samples.rs`).
fn run_pe(sample: &Sample, solver: ContactSolver) -> SampleRun {
    let mut world = World::new(pe::Vec2::new(0.0, -sample.gravity));
    world.settings.contact_solver = solver;
    world.settings.length_scale = sample.typical_size();
    let mut moving = Vec::new();
    for body in &sample.bodies {
        let handle = world.add_body(pe_body(body)).expect("a valid sample body");
        if !body.is_static() {
            moving.push(handle);
        }
    }
    let read = |w: &mut World| {
        let state = |&h: &BodyHandle| {
            let b = w.body(h).expect("bodies are never removed");
            BodyState {
                x: b.position.x,
                y: b.position.y,
                angle: b.angle,
                vx: b.velocity.x,
                vy: b.velocity.y,
            }
        };
        moving.iter().map(state).collect()
    };
    let pivoted = |w: &World| {
        w.island_reports()
            .iter()
            .any(|r| r.method == IslandMethod::Pivoting)
    };
    run_engine(sample, &mut world, |w| w.step(H), read, pivoted)
}

fn pe_body(body: &SampleBody) -> BodyDef {
    let points: Vec<pe::Vec2> = body
        .vertices
        .iter()
        .map(|&(x, y)| pe::Vec2::new(x, y))
        .collect();
    let polygon = ConvexPolygon::new(&points).expect("sample outlines are convex");
    let (vx, vy) = body.velocity;
    BodyDef::new(polygon, body.density)
        .friction(body.friction)
        .at(pe::Vec2::new(body.position.0, body.position.1), body.angle)
        .velocity(pe::Vec2::new(vx, vy), body.spin)
}

/// rapier2d with the main scenes' parameters (`rapier_scenes`: defaults but the step),
/// every outline a convex polygon (`convex_hull`), its friction mixed by the geometric mean.
fn run_rapier(sample: &Sample) -> SampleRun {
    use rapier2d::prelude::*;
    let mut world = PhysicsWorld::new();
    world.gravity = Vector::new(0.0, -sample.gravity as Real);
    world.integration_parameters.dt = H as Real;
    world.integration_parameters.num_solver_iterations = rapier_scenes::ITERATIONS;
    let mut moving = Vec::new();
    for body in &sample.bodies {
        let v = |(x, y): (f64, f64)| Vector::new(x as Real, y as Real);
        let builder = if body.is_static() {
            RigidBodyBuilder::fixed()
        } else {
            RigidBodyBuilder::dynamic().can_sleep(false)
        };
        let builder = builder
            .translation(v(body.position))
            .rotation(body.angle as Real)
            .linvel(v(body.velocity))
            .angvel(body.spin as Real);
        let collider = rapier_polygon(body)
            .friction(body.friction as Real)
            .friction_combine_rule(CoefficientCombineRule::GeometricMean);
        let collider = if body.is_static() {
            collider
        } else {
            collider.density(body.density as Real)
        };
        let (handle, _) = world.insert(builder, collider);
        if !body.is_static() {
            moving.push(handle);
        }
    }
    let read = |w: &mut PhysicsWorld| {
        let state = |&h: &RigidBodyHandle| {
            let b = &w.bodies[h];
            let (c, v) = (b.center_of_mass(), b.linvel());
            BodyState {
                x: f64::from(c.x),
                y: f64::from(c.y),
                angle: f64::from(b.rotation().angle()),
                vx: f64::from(v.x),
                vy: f64::from(v.y),
            }
        };
        moving.iter().map(state).collect()
    };
    run_engine(sample, &mut world, PhysicsWorld::step, read, |_| false)
}

/// A sample body's outline as a rapier2d collider.
fn rapier_polygon(body: &SampleBody) -> rapier2d::prelude::ColliderBuilder {
    use rapier2d::prelude::*;
    let points: Vec<Vector> = body
        .vertices
        .iter()
        .map(|&(x, y)| Vector::new(x as Real, y as Real))
        .collect();
    ColliderBuilder::convex_hull(&points).expect("sample outlines are convex")
}

/// Box2D v3 with the main scenes' settings (`box2d_scenes`: defaults, 4 substeps).
fn run_box2d(sample: &Sample) -> SampleRun {
    use boxdd::{BodyType, ShapeDef, SurfaceMaterial, Vec2, World};
    let mut world = box2d_scenes::world_with_gravity(-sample.gravity);
    let mut moving = Vec::new();
    for body in &sample.bodies {
        let kind = if body.is_static() {
            BodyType::Static
        } else {
            BodyType::Dynamic
        };
        // Box2D's starting velocity is its body origin's; the samples start moving only
        // bodies centred on their origin, where that is the centroid's.
        let (vx, vy) = body.velocity;
        let def = box2d_scenes::body_builder(kind)
            .position(box2d_scenes::point(body.position))
            .angle(body.angle as f32)
            .linear_velocity(Vec2::new(vx as f32, vy as f32))
            .angular_velocity(body.spin as f32)
            .build()
            .expect("a valid body");
        let id = world.create_body(def).expect("a new body");
        let material = SurfaceMaterial::default()
            .with_friction(body.friction as f32)
            .expect("a valid friction");
        // A static body's density is never used; Box2D only asks that it be valid.
        let density = if body.is_static() { 1.0 } else { body.density };
        let shape = ShapeDef::builder()
            .material(material)
            .density(density as f32)
            .build()
            .expect("a valid shape");
        world
            .body(id)
            .and_then(|mut b| b.create_polygon(&shape, &box2d_polygon(body)))
            .expect("a new shape");
        if !body.is_static() {
            moving.push(id);
        }
    }
    let read = |w: &mut World| {
        let state = |&id: &boxdd::BodyId| {
            box2d_scenes::read(w, id, |b| {
                let (c, v) = (b.world_center_of_mass()?, b.linear_velocity()?);
                Ok(BodyState {
                    x: f64::from(c.x),
                    y: f64::from(c.y),
                    angle: f64::from(b.rotation()?.angle()),
                    vx: f64::from(v.x),
                    vy: f64::from(v.y),
                })
            })
        };
        moving.iter().map(state).collect()
    };
    let step = |w: &mut World| box2d_scenes::step(w, H, box2d_scenes::SUBSTEPS);
    run_engine(sample, &mut world, step, read, |_| false)
}

/// A sample body's outline as a Box2D polygon (at most eight vertices). A box centred on
/// its origin is made as Box2D's own `b2MakeBox` makes it: Box2D's hull welds points
/// closer than its linear slop (5 mm), which the card house's 2 mm cards are.
fn box2d_polygon(body: &SampleBody) -> boxdd::Polygon {
    // boxdd makes no polygon before its foundation is set up.
    box2d_scenes::foundation();
    let v = &body.vertices;
    let centred_box = v.len() == 4
        && v[0] == (-v[2].0, -v[2].1)
        && v[1] == (v[2].0, -v[2].1)
        && v[3] == (-v[2].0, v[2].1);
    let polygon = if centred_box {
        boxdd::shapes::box_polygon(v[2].0 as f32, v[2].1 as f32)
    } else {
        let points = v.iter().map(|&(x, y)| boxdd::Vec2::new(x as f32, y as f32));
        boxdd::shapes::polygon_from_points(points, 0.0)
    };
    polygon.expect("sample outlines are valid Box2D polygons")
}

/// The samples' sections of a report: time per step and ratios, what each run showed, and
/// the two targets (exact against soft where `auto` pivots; small samples within 1 ms).
pub fn write(w: &mut String, rows: &[SampleRow]) {
    let engines: Vec<String> = PE_SOLVERS
        .iter()
        .map(|s| format!("pe {}", s.name()))
        .chain(["rapier2d".into(), "Box2D v3".into()])
        .collect();
    let _ = writeln!(w, "\n## Box2D v3's samples\n");
    let _ = writeln!(
        w,
        "Box2D v3's 13 Stacking and Robustness samples as convex polygons \
         (`physics/tests/support/samples.rs`, which pe's tests judge too; `cargo run \
         --release -- samples`), in pe `auto` (its default), `soft` and `exact`, \
         rapier2d and Box2D v3, the engines of a sample taking turns as above. Every body's \
         own friction, mixed by the geometric mean in every engine; pe's tolerances scaled \
         to the sample's median moving body, the peers at their defaults (1 m); sleeping off. \
         After every step each engine's moving bodies (centroid, angle, velocity) go to the \
         sample's tracker, which judges the run by its criterion.\n"
    );
    let mut columns: Vec<String> = vec!["moving bodies".into(), "steps (timed)".into()];
    columns.extend(engines.iter().cloned());
    columns.extend(["pe auto ÷ rapier2d".into(), "pe auto ÷ Box2D v3".into()]);
    let _ = writeln!(
        w,
        "{}",
        crate::report::table_head(&["sample"], &columns, "---:")
    );
    for r in rows {
        let t = &r.pe[0].timing;
        let _ = write!(
            w,
            "| {} | {} | {} ({}) |",
            r.name, r.moving, t.planned, t.timed_steps
        );
        for run in r.pe.iter().chain(&r.peers) {
            let _ = write!(w, " {} |", crate::report::time_cell(&run.timing));
        }
        for peer in &r.peers {
            let _ = write!(
                w,
                " {} |",
                crate::report::ratio(r.pe[0].timing.median, peer.timing.median)
            );
        }
        let _ = writeln!(w);
    }

    let _ = writeln!(
        w,
        "\nWhat each run showed, against the sample's criterion:\n"
    );
    let mut columns = vec!["criterion".to_string()];
    columns.extend(engines.iter().cloned());
    let _ = writeln!(
        w,
        "{}",
        crate::report::table_head(&["sample"], &columns, "---")
    );
    for r in rows {
        let _ = write!(w, "| {} | {} |", r.name, criterion_text(&r.criterion));
        for run in r.pe.iter().chain(&r.peers) {
            let _ = write!(w, " {} |", verdict_cell(run));
        }
        let _ = writeln!(w);
    }

    let soft = PE_SOLVERS.iter().position(|&s| s == ContactSolver::Soft);
    let exact = PE_SOLVERS.iter().position(|&s| s == ContactSolver::Exact);
    let pivoting: Vec<&SampleRow> = rows.iter().filter(|r| r.pe[0].pivoted_steps > 0).collect();
    if let (Some(soft), Some(exact), false) = (soft, exact, pivoting.is_empty()) {
        let _ = writeln!(
            w,
            "\nWhere `auto` solved an island by pivoting (`exact`'s method), `exact` beside \
             `soft` on the whole sample (the target: at most {EXACT_OVER_SOFT}× `soft`):\n"
        );
        let columns = [
            "steps `auto` pivoted",
            "pe exact",
            "pe soft",
            "exact ÷ soft",
            "within the target",
        ]
        .map(String::from);
        let _ = writeln!(
            w,
            "{}",
            crate::report::table_head(&["sample"], &columns, "---:")
        );
        for r in pivoting {
            let (e, s) = (&r.pe[exact].timing, &r.pe[soft].timing);
            let over = crate::format::time_ratio(e.median, s.median);
            let _ = writeln!(
                w,
                "| {} | {} of {} | {} | {} | {over:.2} | {} |",
                r.name,
                r.pe[0].pivoted_steps,
                r.pe[0].timing.steps_run,
                crate::report::time_cell(e),
                crate::report::time_cell(s),
                if over <= EXACT_OVER_SOFT { "yes" } else { "no" }
            );
        }
    }

    let small: Vec<&SampleRow> = rows.iter().filter(|r| r.moving <= SMALL_SAMPLE).collect();
    if let Some(slowest) = small.iter().max_by_key(|r| r.pe[0].timing.median) {
        let over: Vec<&str> = small
            .iter()
            .filter(|r| r.pe[0].timing.median > SMALL_BUDGET)
            .map(|r| r.name)
            .collect();
        let verdict = if over.is_empty() {
            "every one does".to_string()
        } else {
            format!("not all: {} do not", over.join(", "))
        };
        let _ = writeln!(
            w,
            "\nSamples with at most {SMALL_SAMPLE} moving bodies stepping in at most {} ms \
             under pe `{}`: {verdict} (the slowest, {}, {} a step).",
            SMALL_BUDGET.as_secs_f64() * 1e3,
            PE_SOLVERS[0].name(),
            slowest.name,
            crate::format::pretty(slowest.pe[0].timing.median)
        );
    }
}

/// A criterion in a few words.
fn criterion_text(c: &Criterion) -> String {
    match *c {
        Criterion::Stands { from, creep, sag } => format!(
            "stands: creeps ≤ {} mm after {from} s, ends ≤ {sag} m from rest",
            1e3 * creep
        ),
        Criterion::SlidesTo { x, tolerance } => format!("stops at x = {x:.4} ± {tolerance} m"),
        Criterion::Topples { angle, at_least } => {
            format!("≥ {at_least} turn past {angle} rad")
        }
        Criterion::ColumnsFall { height } => format!("every column's top ends below {height} m"),
        Criterion::LeavesLedges { height, launch } => {
            format!("all end below {height} m, none rising over {launch} m")
        }
        Criterion::Recovers { speed, rest, .. } => {
            format!("never over {speed} m/s, stays in its box, ≤ {rest} m/s at the end")
        }
    }
}

/// PASS or FAIL and what the run showed, without the criterion's bounds (the criterion
/// column has them); a run the budget cut short is not judged.
fn verdict_cell(run: &SampleRun) -> String {
    let t = &run.timing;
    if t.cut_short() {
        return format!("† not judged: {} of {} steps", t.steps_run, t.planned);
    }
    let mark = if run.verdict.passed { "PASS" } else { "FAIL" };
    format!("{mark}: {}", without_bounds(&run.verdict.summary))
}

/// A verdict's summary with its parenthesised bounds left out: "creeps 0.004 mm (at most
/// 0.050)" becomes "creeps 0.004 mm".
fn without_bounds(summary: &str) -> String {
    let mut out = String::with_capacity(summary.len());
    let mut depth = 0_usize;
    for c in summary.chars() {
        match c {
            '(' => depth += 1,
            ')' => depth = depth.saturating_sub(1),
            _ if depth == 0 => out.push(c),
            _ => {}
        }
    }
    out.replace(" ;", ";").trim().to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tables call the first solver pe's default and take their ratios from it.
    #[test]
    fn pe_s_default_solver_comes_first() {
        assert_eq!(pe::StepSettings::default().contact_solver, PE_SOLVERS[0]);
    }

    #[test]
    fn bounds_are_left_out_of_summaries() {
        assert_eq!(
            without_bounds("creeps 0.004 mm (at most 0.050); 0.300 m from rest (at most 0.5)"),
            "creeps 0.004 mm; 0.300 m from rest"
        );
        assert_eq!(
            without_bounds("stops at x = 2.0800 m (2.0833 ± 0.045)"),
            "stops at x = 2.0800 m"
        );
    }

    /// Every outline reaches each peer whole: no vertex merged away by a hull (Box2D welds
    /// points closer than its linear slop) and none beyond Box2D's eight.
    #[test]
    fn every_outline_reaches_the_peers_whole() {
        for sample in samples::all() {
            for body in &sample.bodies {
                let n = body.vertices.len();
                assert_eq!(box2d_polygon(body).count(), n, "{}", sample.name);
                let collider = rapier_polygon(body).build();
                let polygon = collider
                    .shape()
                    .as_convex_polygon()
                    .expect("a convex polygon");
                assert_eq!(polygon.points().len(), n, "{}", sample.name);
            }
        }
    }

    /// A short run of the smallest sample in every engine: each one judges it, and the
    /// single box slides to where friction stops it in each.
    #[test]
    fn the_single_box_slides_to_its_stop_in_every_engine() {
        let rows = run(&["single_box".to_string()]);
        let row = &rows[0];
        assert_eq!(row.moving, 1);
        for run in row.pe.iter().chain(&row.peers) {
            assert!(run.verdict.passed, "{}", run.verdict.summary);
        }
    }
}
