//! The runner: the simulation of what the canvas shows and its clock. It builds the
//! selected scene (or a robot or body previewed in a scene of its own), pays real time ×
//! speed in whole fixed steps, applies the mouse spring, keeps bodies inside the world
//! bound and records what the plots show.

use super::Selection;
use super::canvas::Grab;
use super::placing;
use super::plot_data::PlotData;
use super::world_bound::{self, WorldBound};
use crate::model::{Model, Placement, Scene, SceneRobot, same_name};
use crate::sim::Simulation;
use pe::{Aabb, ContactSolver};
use std::collections::VecDeque;

/// Simulation speeds offered: the physics step never changes, only steps per second.
pub const SPEEDS: [f64; 7] = [0.1, 0.25, 0.5, 1.0, 2.0, 4.0, 8.0];

/// The name of the synthetic scene a robot or body is previewed in.
pub const PREVIEW: &str = "\u{0}preview";

/// How far back a run can be scrubbed, and in how many snapshots.
const HISTORY_SECONDS: f64 = 10.0;
const SNAPSHOTS: usize = 100;

/// The motors' speed factors the arrow keys step through while a scene runs.
pub const THROTTLES: [f64; 9] = [-2.0, -1.5, -1.0, -0.5, 0.0, 0.5, 1.0, 1.5, 2.0];

/// Something a step did that the user should hear about.
#[derive(Debug, Clone, PartialEq)]
pub struct RunNote {
    pub text: String,
    /// Everything that moved has left the scene: the run paused; show this area.
    pub scene_to_show: Option<Aabb>,
}

/// The runner's state the canvas reads, and the grab it moves.
pub struct CanvasParts<'a> {
    pub sim: Option<&'a Simulation>,
    pub grab: &'a mut Option<Grab>,
    pub overlaps: &'a [(usize, usize)],
    pub bound: Option<&'a WorldBound>,
}

#[derive(Debug)]
pub struct Runner {
    sim: Option<Simulation>,
    pub running: bool,
    pub speed: f64,
    /// Simulated time owed to the physics: real time × speed, paid in whole steps.
    accumulator: f64,
    pub solver: ContactSolver,
    /// What the solver was chosen for: the scene (or preview) shown, and the solver its
    /// file names. Another one shown, or its own solver changed, takes up its own solver
    /// (or the default), not the last one's choice.
    solver_for: Option<(Selection, Option<ContactSolver>)>,
    /// Whether bodies at rest sleep in the simulations the app runs.
    pub sleeping: bool,
    /// The body held by the mouse while running.
    pub grab: Option<Grab>,
    world_bound: Option<WorldBound>,
    pub plot_data: PlotData,
    /// Bodies that overlap at step 0 (indices into `sim.bodies`), found when it is built.
    overlaps: Vec<(usize, usize)>,
    /// Snapshots of the last seconds of the run, oldest first, to scrub back through.
    history: VecDeque<(Simulation, Option<WorldBound>)>,
    /// The snapshot shown after scrubbing back, until the run goes on from it.
    scrubbed_to: Option<usize>,
    /// Joint motors run at this multiple of their speed in the files (arrow keys).
    throttle: f64,
}

impl Default for Runner {
    fn default() -> Self {
        Self {
            sim: None,
            running: false,
            speed: 1.0,
            accumulator: 0.0,
            solver: ContactSolver::default(),
            solver_for: None,
            sleeping: true,
            grab: None,
            world_bound: None,
            plot_data: PlotData::default(),
            overlaps: Vec::new(),
            history: VecDeque::new(),
            scrubbed_to: None,
            throttle: 1.0,
        }
    }
}

impl Runner {
    pub fn sim(&self) -> Option<&Simulation> {
        self.sim.as_ref()
    }

    pub fn sim_mut(&mut self) -> Option<&mut Simulation> {
        self.sim.as_mut()
    }

    /// What the canvas reads, and the grab it moves.
    pub fn canvas_parts(&mut self) -> CanvasParts<'_> {
        CanvasParts {
            sim: self.sim.as_ref(),
            grab: &mut self.grab,
            overlaps: &self.overlaps,
            bound: self.world_bound.as_ref(),
        }
    }

    pub fn overlaps(&self) -> &[(usize, usize)] {
        &self.overlaps
    }

    pub fn world_bound(&self) -> Option<&WorldBound> {
        self.world_bound.as_ref()
    }

    /// Paused at step 0: where the canvas edits placements and joints.
    pub fn editing(&self) -> bool {
        !self.running && self.sim.as_ref().is_some_and(|s| s.step_count() == 0)
    }

    /// Builds what `selection` shows from `model`, paused at step 0: a scene, or a robot
    /// or a body previewed. A scene's own solver is taken up. Err: why it cannot be built.
    pub fn show(
        &mut self,
        model: &Model,
        selection: &Selection,
        followed: Option<usize>,
    ) -> Result<(), String> {
        let (model, scene) = match selection {
            Selection::Scene(name) => (model.clone(), name.clone()),
            Selection::Robot(name) => (preview(model, Some(name), None), PREVIEW.to_string()),
            Selection::Body(name) => (preview(model, None, Some(name)), PREVIEW.to_string()),
        };
        let own = model
            .scene(&scene)
            .and_then(|s| s.solver.as_deref())
            .and_then(|name| ContactSolver::from_name(name.trim()));
        // The toolbar's choice stays with what it was made for (through edits and
        // resets); another scene shown starts from its own solver.
        let shown = (selection.clone(), own);
        if self.solver_for.as_ref() != Some(&shown) {
            self.solver = own.unwrap_or_default();
            self.solver_for = Some(shown);
        }
        // Shown paused at step 0, scenes too: the user looks, then presses Play (Space).
        self.running = false;
        let built = Simulation::new(&model, &scene, None, Some(self.solver));
        let result = match built {
            Ok(mut sim) => {
                sim.world.settings.sleeping = self.sleeping;
                self.sim = Some(sim);
                Ok(())
            }
            Err(e) => {
                self.sim = None;
                // The preview's scene is an internal one: the message names what it shows.
                let shown = match selection {
                    Selection::Robot(name) => format!("robot \"{}\"", crate::db::clip(name)),
                    Selection::Body(name) => format!("body \"{}\"", crate::db::clip(name)),
                    Selection::Scene(_) => String::new(),
                };
                let internal = format!("scene \"{}\"", crate::db::clip(PREVIEW));
                let e = e.to_string();
                let e = match selection {
                    Selection::Scene(_) => e,
                    // `body "b": b: body "b": why`, said once.
                    Selection::Body(_) => e.rfind(&shown).map_or(e.clone(), |i| e[i..].to_string()),
                    Selection::Robot(_) => e.replace(&internal, &shown),
                };
                Err(e)
            }
        };
        self.restarted(followed);
        result
    }

    pub fn clear(&mut self) {
        self.sim = None;
        self.restarted(None);
    }

    /// Back to step 0.
    pub fn reset(&mut self, followed: Option<usize>) {
        if let Some(sim) = &mut self.sim {
            sim.reset();
        }
        self.restarted(followed);
    }

    /// The steps that can be gone back to: the oldest and newest snapshot.
    pub fn history(&self) -> Option<(u64, u64)> {
        let oldest = self.history.front()?.0.step_count();
        let newest = self.history.back()?.0.step_count();
        Some((oldest, newest))
    }

    /// Back to the latest snapshot at or before `step`, paused; later ones are dropped.
    /// Shows the snapshot at `step` (or the last before it), paused. The history stays
    /// whole while the user scrubs, so that the slider's range, and the step under the
    /// pointer, hold still; the run from there is dropped only when it goes on
    /// (`leave_scrub`).
    pub fn scrub_to(&mut self, step: u64) {
        let Some(k) = self
            .history
            .iter()
            .rposition(|(s, _)| s.step_count() <= step)
        else {
            return;
        };
        let (sim, bound) = self.history[k].clone();
        self.sim = Some(sim);
        self.world_bound = bound;
        self.scrubbed_to = Some(k);
        self.running = false;
        self.grab = None;
        self.accumulator = 0.0;
    }

    /// Going on from a scrubbed-to step: the snapshots and plot samples after it go.
    fn leave_scrub(&mut self) {
        let Some(k) = self.scrubbed_to.take() else {
            return;
        };
        self.history.truncate(k + 1);
        if let Some(time) = self.sim.as_ref().map(Simulation::time) {
            self.plot_data.samples.retain(|s| s.time <= time + 1e-9);
        }
    }

    pub fn throttle(&self) -> f64 {
        self.throttle
    }

    /// Steps the joint motors' speed factor by `by` places in `THROTTLES`.
    pub fn change_throttle(&mut self, by: i32) {
        let at = THROTTLES
            .iter()
            .position(|&t| t >= self.throttle)
            .unwrap_or(THROTTLES.len() - 1) as i32;
        let to = (at + by).clamp(0, THROTTLES.len() as i32 - 1) as usize;
        self.throttle = THROTTLES[to];
        self.apply_throttle();
    }

    /// Takes up an edit of `model` without starting again where the scene shown has run
    /// (see `Simulation::follow_live_edit`: gravity, friction, the step, joint motors);
    /// false where it must be built again.
    pub fn follow_live_edit(&mut self, model: &Model) -> bool {
        let Some(sim) = &mut self.sim else {
            return false;
        };
        if sim.step_count() == 0 || !sim.follow_live_edit(model) {
            return false;
        }
        self.apply_throttle();
        true
    }

    /// Every joint motor at `throttle` × its speed in the files (rad/step ÷ h).
    fn apply_throttle(&mut self) {
        if let Some(sim) = &mut self.sim {
            sim.motor_throttle = self.throttle;
        }
    }

    fn remember(&mut self) {
        let Some(sim) = &self.sim else {
            return;
        };
        let every = ((HISTORY_SECONDS / SNAPSHOTS as f64 / sim.dt).round() as u64).max(1);
        if sim.step_count() % every == 0 {
            self.history
                .push_back((sim.clone(), self.world_bound.clone()));
            if self.history.len() > SNAPSHOTS {
                self.history.pop_front();
            }
        }
    }

    fn restarted(&mut self, followed: Option<usize>) {
        self.history.clear();
        self.scrubbed_to = None;
        self.throttle = 1.0;
        let at_start = self.sim.as_ref().filter(|s| s.step_count() == 0);
        self.overlaps = at_start.map_or_else(Vec::new, placing::overlapping_pairs);
        self.world_bound = at_start.and_then(WorldBound::around);
        self.accumulator = 0.0;
        self.grab = None;
        self.plot_data.clear();
        if let Some(sim) = &self.sim {
            self.plot_data.record(sim, followed);
        }
        self.remember();
    }

    /// The plots show `followed` from now on; every series is kept (choosing a body
    /// changes what is shown, not what was recorded).
    pub fn show_in_plots(&mut self, followed: Option<usize>) {
        self.plot_data.show_body(followed);
    }

    pub fn set_solver(&mut self, solver: ContactSolver) {
        self.solver = solver;
        if let Some(sim) = &mut self.sim {
            sim.set_solver(solver);
        }
    }

    pub fn set_sleeping(&mut self, sleeping: bool) {
        self.sleeping = sleeping;
        if let Some(sim) = &mut self.sim {
            sim.world.settings.sleeping = sleeping;
        }
    }

    /// Advances by `frame_seconds` of real time at the chosen speed, in whole fixed steps.
    pub fn advance(&mut self, frame_seconds: f64, followed: Option<usize>) -> Option<RunNote> {
        let dt = self.sim.as_ref()?.dt;
        if !self.running {
            return None;
        }
        // Cap the work per frame so a slow scene cannot spiral into ever longer frames.
        self.accumulator =
            (self.accumulator + frame_seconds * self.speed).min(0.25 * self.speed.max(1.0));
        let mut note = None;
        while self.running && self.accumulator >= dt {
            note = self.step(followed).or(note);
            self.accumulator -= dt;
        }
        note
    }

    /// One physics step, with the mouse spring applied first and the world bound after.
    pub fn step(&mut self, followed: Option<usize>) -> Option<RunNote> {
        self.leave_scrub();
        let sim = self.sim.as_mut()?;
        if let Some(grab) = &self.grab {
            grab.apply(sim);
        }
        sim.step();
        let mut note = None;
        if let Some(bound) = &mut self.world_bound {
            let stopped = bound.enforce(sim);
            if !stopped.is_empty() {
                let mut text = world_bound::note(&stopped, sim.time());
                let everything = bound.all_stopped(sim);
                if everything {
                    self.running = false;
                    text.push_str(" · paused: nothing in the scene moves any more");
                }
                note = Some(RunNote {
                    text,
                    scene_to_show: everything.then(|| bound.scene_and_stopped(sim)),
                });
            }
        }
        self.plot_data.record(sim, followed);
        self.remember();
        note
    }
}

/// `model` plus a scene holding just `robot` or `body` at the origin, without gravity.
pub fn preview(model: &Model, robot: Option<&str>, body: Option<&str>) -> Model {
    let mut m = model.clone();
    let mut scene = Scene {
        name: PREVIEW.to_string(),
        friction: 0.5,
        ..Scene::default()
    };
    if let Some(r) = robot {
        // At the step of the scenes that use the robot, as its motors' speeds are shown.
        scene.timestep = model
            .scenes
            .iter()
            .find(|s| s.robots.iter().any(|p| same_name(&p.source, r)))
            .and_then(|s| s.timestep);
        scene.robots.push(SceneRobot {
            source: r.to_string(),
            ..SceneRobot::default()
        });
    }
    if let Some(b) = body {
        scene.bodies.push(Placement {
            alias: b.to_string(),
            source: b.to_string(),
            ..Default::default()
        });
    }
    m.scenes.push(scene);
    m
}
