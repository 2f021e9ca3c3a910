//! The desktop app (eframe/egui): a database browser, the canvas, an inspector, plots and a
//! status bar. UI code reads the model and the simulation; physics lives in `pe` and
//! `sim`, files in `db`.

pub mod camera;
pub mod canvas;
pub mod inspector;
pub mod plot_data;
pub mod tools;
pub mod undo;

use crate::db::{Database, Delete, Overwrite, Problem, SaveError};
use crate::model::{Model, Scene, SceneRobot};
use crate::sim::{PlacedBy, Simulation};
use camera::Camera;
use canvas::{DebugDraw, Grab};
use pe::ContactSolver;
use plot_data::PlotData;
use std::path::PathBuf;

/// Runs the app in a native window until it is closed: on `db`, or the embedded default.
pub fn run(db: Option<PathBuf>) -> Result<(), String> {
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("RoboSim")
            .with_inner_size([1280.0, 800.0]),
        ..Default::default()
    };
    eframe::run_native(
        "RoboSim",
        options,
        Box::new(move |cc| {
            let mut app = RoboSimApp::new(db);
            if let Some(storage) = cc.storage {
                app.recent = eframe::get_value(storage, RECENT_KEY).unwrap_or_default();
            }
            app.offer_restore();
            Ok(Box::new(app))
        }),
    )
    .map_err(|e| e.to_string())
}

const RECENT_KEY: &str = "recent folders";

/// What the browser has selected, and so what the canvas shows.
#[derive(Debug, Clone, PartialEq)]
pub enum Selection {
    Scene(String),
    Robot(String),
    Body(String),
}

/// Simulation speeds offered: the physics step never changes, only steps per second.
pub const SPEEDS: [f64; 7] = [0.1, 0.25, 0.5, 1.0, 2.0, 4.0, 8.0];

pub struct RoboSimApp {
    pub db: Database,
    pub problems: Vec<Problem>,
    pub selection: Option<Selection>,
    /// The selected scene running (or a robot or body previewed as a scene of its own).
    pub sim: Option<Simulation>,
    pub solver: ContactSolver,
    /// Whether bodies at rest sleep in the simulations the app runs.
    pub sleeping: bool,
    pub camera: Camera,
    camera_fitted: bool,
    pub running: bool,
    pub speed: f64,
    /// Simulated time owed to the physics: real time × speed, paid in whole steps.
    accumulator: f64,
    pub debug: DebugDraw,
    pub plot_data: PlotData,
    /// Index into `sim.bodies` of the body the inspector and plots follow.
    pub selected_body: Option<usize>,
    grab: Option<Grab>,
    path_input: String,
    pub status: String,
    /// Whether `status` reports a failure (red) rather than news (plain).
    pub status_is_error: bool,
    show_problems: bool,
    pub recent: Vec<String>,
    /// Undo and redo of model edits.
    pub edits: undo::UndoHistory,
    /// The selection's name as it is being typed (applied on Enter).
    name_buffer: String,
    /// A question waiting for the user's answer.
    dialog: Option<Dialog>,
    /// The vertex being dragged in the body editor.
    vertex_drag: Option<usize>,
    /// The window may close: the user answered the unsaved-changes question.
    close_confirmed: bool,
    /// What a click on the canvas does while editing.
    pub tool: tools::Tool,
    /// Grid spacing edits snap to (None: free).
    pub snap_step: Option<f64>,
    /// Where the canvas was drawn last frame (screen points), to map clicks to the world.
    pub canvas_rect: egui::Rect,
}

/// Questions the app asks before doing something that cannot be undone.
#[derive(Debug, Clone, PartialEq)]
enum Dialog {
    /// Saving would overwrite a file changed on disk or drop unreadable records.
    Overwrite(String),
    /// Unsaved changes and the window is closing, or another folder is opening.
    Unsaved(AfterSave),
    /// A delete refused because the item is used; offer the cascade.
    Cascade(Selection, String),
    /// Unsaved work from a session that did not end cleanly was found.
    Restore(Model),
}

#[derive(Debug, Clone, PartialEq)]
enum AfterSave {
    Quit,
    Open(PathBuf),
}

impl RoboSimApp {
    /// The app on `dir`'s database, or on the embedded default; the first scene selected.
    pub fn new(dir: Option<PathBuf>) -> Self {
        let (db, problems) = match &dir {
            Some(dir) => Database::load(dir),
            None => Database::embedded(),
        };
        let mut app = Self {
            db,
            problems,
            selection: None,
            sim: None,
            solver: ContactSolver::default(),
            sleeping: true,
            camera: Camera::default(),
            camera_fitted: false,
            running: true,
            speed: 1.0,
            accumulator: 0.0,
            debug: DebugDraw::default(),
            plot_data: PlotData::default(),
            selected_body: None,
            grab: None,
            path_input: dir.map(|d| d.display().to_string()).unwrap_or_default(),
            status: String::new(),
            status_is_error: false,
            show_problems: false,
            recent: Vec::new(),
            edits: undo::UndoHistory::default(),
            name_buffer: String::new(),
            dialog: None,
            vertex_drag: None,
            close_confirmed: false,
            tool: tools::Tool::Select,
            snap_step: Some(0.5),
            canvas_rect: egui::Rect::NOTHING,
        };
        if let Some(first) = app.db.model.scenes.first().map(|s| s.name.clone()) {
            app.select(Selection::Scene(first));
        }
        app
    }

    /// Shows `selection`: a scene is built and runs; a robot or a body is previewed still.
    pub fn select(&mut self, selection: Selection) {
        let (model, scene, run) = match &selection {
            Selection::Scene(name) => (self.db.model.clone(), name.clone(), true),
            Selection::Robot(name) => (
                preview(&self.db.model, Some(name), None),
                PREVIEW.to_string(),
                false,
            ),
            Selection::Body(name) => (
                preview(&self.db.model, None, Some(name)),
                PREVIEW.to_string(),
                false,
            ),
        };
        let solver = match &selection {
            Selection::Scene(name) => self.db.model.scene(name).and_then(|s| s.solver.as_deref()),
            _ => None,
        }
        .and_then(ContactSolver::from_name)
        .unwrap_or(self.solver);
        self.solver = solver;
        match Simulation::new(&model, &scene, None, Some(solver)) {
            Ok(mut sim) => {
                sim.world.settings.sleeping = self.sleeping;
                self.sim = Some(sim);
                self.inform(String::new());
            }
            Err(e) => {
                self.sim = None;
                self.complain(e.to_string());
            }
        }
        self.running = run;
        self.name_buffer = match &selection {
            Selection::Scene(n) | Selection::Robot(n) | Selection::Body(n) => n.clone(),
        };
        if !matches!(selection, Selection::Robot(_)) {
            self.tool = tools::Tool::Select;
        }
        self.selection = Some(selection);
        self.selected_body = None;
        self.after_rebuild();
        self.camera_fitted = false;
    }

    /// Makes `draft` the model as one undoable edit (merged with the last if `key` is the
    /// same field), re-checks it and rebuilds what the canvas shows, paused at step 0.
    pub fn commit(&mut self, draft: Model, key: &str, now: f64) {
        if draft == self.db.model {
            return;
        }
        self.edits.record(&self.db.model, key, now);
        self.db.model = draft;
        self.model_changed();
    }

    fn model_changed(&mut self) {
        self.problems = self.db.check();
        // Keep the view across an edit, unless it had nothing to frame (a new, empty robot).
        let had_bodies = self.sim.as_ref().is_some_and(|s| !s.bodies.is_empty());
        let (camera, fitted, selected) = (
            self.camera,
            self.camera_fitted && had_bodies,
            self.selected_body,
        );
        if let Some(sel) = self.selection.clone() {
            let still_there = match &sel {
                Selection::Scene(n) => self.db.model.scene(n).is_some(),
                Selection::Robot(n) => self.db.model.robot(n).is_some(),
                Selection::Body(n) => self.db.model.body(n).is_some(),
            };
            if still_there {
                self.select(sel);
                self.running = false;
            } else {
                self.selection = None;
                self.sim = None;
            }
        }
        (self.camera, self.camera_fitted, self.selected_body) = (camera, fitted, selected);
    }

    pub fn undo(&mut self) {
        if self.edits.undo(&mut self.db.model) {
            self.model_changed();
        }
    }

    pub fn redo(&mut self) {
        if self.edits.redo(&mut self.db.model) {
            self.model_changed();
        }
    }

    /// Saves to the database's folder (asking for one if it has none).
    pub fn save(&mut self, overwrite: Overwrite) {
        // Files saved by the editor always say their step (a file without one means 0.05 s,
        // which a reader should not have to know).
        for scene in &mut self.db.model.scenes {
            scene.timestep.get_or_insert(crate::model::DEFAULT_TIMESTEP);
        }
        let result = match self.db.dir.clone() {
            Some(_) => self.db.save(overwrite),
            None => {
                let typed = (!self.path_input.trim().is_empty())
                    .then(|| PathBuf::from(self.path_input.trim()));
                let Some(dir) = typed.or_else(|| {
                    rfd::FileDialog::new()
                        .set_title("Save the database in…")
                        .pick_folder()
                }) else {
                    self.complain("choose a folder to save to (type it in the path field)".into());
                    return;
                };
                self.db.save_to(&dir, overwrite)
            }
        };
        match result {
            Ok(()) => {
                self.inform(format!(
                    "saved to {}",
                    self.db
                        .dir
                        .as_ref()
                        .map_or(String::new(), |d| d.display().to_string())
                ));
                if let Some(dir) = &self.db.dir {
                    self.path_input = dir.display().to_string();
                }
            }
            Err(e @ (SaveError::ChangedOnDisk(_) | SaveError::WouldDropRecords(_))) => {
                self.dialog = Some(Dialog::Overwrite(e.to_string()));
            }
            Err(e) => self.complain(e.to_string()),
        }
    }

    /// Reloads the database from disk, dropping unsaved edits (undoable).
    pub fn revert(&mut self) {
        let Some(dir) = self.db.dir.clone() else {
            return;
        };
        let (db, problems) = Database::load(&dir);
        self.edits.record(&self.db.model, "revert", f64::NAN);
        self.db = db;
        self.problems = problems;
        self.model_changed();
    }

    fn new_item(&mut self, kind: &str, now: f64) {
        let mut draft = self.db.model.clone();
        let selection = match kind {
            "body" => {
                let names: Vec<String> = draft.bodies.iter().map(|b| b.name.clone()).collect();
                let name = inspector::unique(&names, "new body");
                draft.bodies.push(crate::model::BodyDef {
                    name: name.clone(),
                    density: 1.0,
                    cor: 0.2,
                    vertices: vec![[-20.0, -10.0], [20.0, -10.0], [20.0, 10.0], [-20.0, 10.0]],
                    ..Default::default()
                });
                Selection::Body(name)
            }
            "robot" => {
                let names: Vec<String> = draft.robots.iter().map(|r| r.name.clone()).collect();
                let name = inspector::unique(&names, "new robot");
                draft.robots.push(crate::model::Robot {
                    name: name.clone(),
                    ..Default::default()
                });
                Selection::Robot(name)
            }
            _ => {
                let names: Vec<String> = draft.scenes.iter().map(|s| s.name.clone()).collect();
                let name = inspector::unique(&names, "new scene");
                draft.scenes.push(Scene {
                    name: name.clone(),
                    gravitation: 200.0,
                    friction: 0.5,
                    timestep: Some(1.0 / 60.0),
                    ..Scene::default()
                });
                Selection::Scene(name)
            }
        };
        self.commit(draft, &format!("new {kind}"), now);
        self.select(selection);
        self.running = false;
    }

    fn duplicate(&mut self, now: f64) {
        let Some(sel) = self.selection.clone() else {
            return;
        };
        let mut draft = self.db.model.clone();
        let selection = match sel {
            Selection::Body(n) => {
                push_copy(&mut draft.bodies, &n, |b| &mut b.name).map(Selection::Body)
            }
            Selection::Robot(n) => {
                push_copy(&mut draft.robots, &n, |r| &mut r.name).map(Selection::Robot)
            }
            Selection::Scene(n) => {
                push_copy(&mut draft.scenes, &n, |s| &mut s.name).map(Selection::Scene)
            }
        };
        let Some(selection) = selection else {
            return;
        };
        self.commit(draft, "duplicate", now);
        self.select(selection);
    }

    fn delete(&mut self, mode: Delete, now: f64) {
        let Some(sel) = self.selection.clone() else {
            return;
        };
        let mut draft = self.db.model.clone();
        let result = match &sel {
            Selection::Body(n) => draft.delete_body(n, mode),
            Selection::Robot(n) => draft.delete_robot(n, mode),
            Selection::Scene(n) => draft.delete_scene(n),
        };
        match result {
            Ok(()) => self.commit(draft, "delete", now),
            Err(e @ crate::db::EditError::InUse { .. }) => {
                self.dialog = Some(Dialog::Cascade(sel, e.to_string()))
            }
            Err(e) => self.complain(e.to_string()),
        }
    }

    fn rename(&mut self, sel: Selection, new: String, now: f64) {
        let mut draft = self.db.model.clone();
        let (result, renamed) = match &sel {
            Selection::Body(n) => (draft.rename_body(n, &new), Selection::Body(new.clone())),
            Selection::Robot(n) => (draft.rename_robot(n, &new), Selection::Robot(new.clone())),
            Selection::Scene(n) => (draft.rename_scene(n, &new), Selection::Scene(new.clone())),
        };
        match result {
            Ok(()) => {
                self.commit(draft, "rename", now);
                self.select(renamed);
                self.running = false;
            }
            Err(e) => self.complain(format!("cannot rename: {e}")),
        }
    }

    fn after_rebuild(&mut self) {
        self.accumulator = 0.0;
        self.grab = None;
        self.plot_data.clear();
        if let Some(sim) = &self.sim {
            self.plot_data.record(sim, self.selected_body);
        }
    }

    /// Back to step 0, paused: where the canvas edits placements and joints.
    fn stop_at_start(&mut self) {
        self.running = false;
        if self.sim.as_ref().is_some_and(|s| s.step_count() > 0) {
            self.reset();
        }
    }

    pub fn reset(&mut self) {
        if let Some(sim) = &mut self.sim {
            sim.reset();
        }
        self.after_rebuild();
    }

    /// One physics step, with the mouse spring applied first.
    pub fn single_step(&mut self) {
        let Some(sim) = &mut self.sim else { return };
        if let Some(grab) = &self.grab {
            grab.apply(sim);
        }
        sim.step();
        self.plot_data.record(sim, self.selected_body);
    }

    /// Advances by `frame_seconds` of real time at the chosen speed, in whole fixed steps.
    fn advance(&mut self, frame_seconds: f64) {
        let Some(dt) = self.sim.as_ref().map(|s| s.dt) else {
            return;
        };
        if !self.running {
            return;
        }
        // Cap the work per frame so a slow scene cannot spiral into ever longer frames.
        self.accumulator =
            (self.accumulator + frame_seconds * self.speed).min(0.25 * self.speed.max(1.0));
        while self.accumulator >= dt {
            self.single_step();
            self.accumulator -= dt;
        }
    }

    fn open(&mut self, dir: PathBuf) {
        if self.db.is_dirty() {
            self.dialog = Some(Dialog::Unsaved(AfterSave::Open(dir)));
        } else {
            self.open_now(dir);
        }
    }

    fn open_now(&mut self, dir: PathBuf) {
        self.edits.clear();
        let (db, problems) = Database::load(&dir);
        self.db = db;
        self.problems = problems;
        let label = dir.display().to_string();
        self.recent.retain(|r| r != &label);
        self.recent.insert(0, label.clone());
        self.recent.truncate(8);
        self.path_input = label;
        self.sim = None;
        self.selection = None;
        if let Some(first) = self.db.model.scenes.first().map(|s| s.name.clone()) {
            self.select(Selection::Scene(first));
        }
    }

    fn toolbar(&mut self, ui: &mut egui::Ui) {
        ui.horizontal_wrapped(|ui| {
            if ui.button("Open…").on_hover_text("Open a database folder (bodies.xml, robots.xml, scenes.xml)").clicked()
                && let Some(dir) = rfd::FileDialog::new().pick_folder()
            {
                self.open(dir);
            }
            let typed = ui.add(
                egui::TextEdit::singleline(&mut self.path_input)
                    .hint_text("database folder")
                    .desired_width(140.0),
            );
            let typed = typed.on_hover_text("Type a folder and press Enter (for machines without a file dialog)");
            if typed.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter)) && !self.path_input.is_empty() {
                self.open(PathBuf::from(self.path_input.clone()));
            }
            if !self.recent.is_empty() {
                egui::ComboBox::from_id_salt("recent").selected_text("Recent").show_ui(ui, |ui| {
                    for r in self.recent.clone() {
                        if ui.button(&r).clicked() {
                            self.open(PathBuf::from(r));
                        }
                    }
                });
            }
            ui.separator();
            let dirty = self.db.is_dirty();
            if ui.add_enabled(dirty || self.db.dir.is_none(), egui::Button::new(if dirty { "Save*" } else { "Save" }))
                .on_hover_text("Save the database, each file atomically (Ctrl+S)")
                .clicked()
            {
                self.save(Overwrite::Never);
            }
            if ui.add_enabled(self.edits.can_undo(), egui::Button::new("Undo")).on_hover_text("Undo the last edit (Ctrl+Z)").clicked() {
                self.undo();
            }
            if ui.add_enabled(self.edits.can_redo(), egui::Button::new("Redo")).on_hover_text("Redo (Ctrl+Shift+Z or Ctrl+Y)").clicked() {
                self.redo();
            }
            if ui.add_enabled(self.db.dir.is_some() && dirty, egui::Button::new("Revert")).on_hover_text("Reload the files, dropping unsaved edits (undoable)").clicked() {
                self.revert();
            }
            ui.separator();
            let label = if self.running { "Pause" } else { "Play" };
            if ui.button(label).on_hover_text("Start or stop the simulation (Space)").clicked() {
                self.running = !self.running;
            }
            if ui.button("Step").on_hover_text("Advance one physics step (S)").clicked() {
                self.running = false;
                self.single_step();
            }
            if ui.button("Reset").on_hover_text("Start the scene again (R)").clicked() {
                self.reset();
            }
            egui::ComboBox::from_id_salt("speed")
                .width(56.0)
                .selected_text(format!("{}×", self.speed))
                .show_ui(ui, |ui| {
                    for s in SPEEDS {
                        ui.selectable_value(&mut self.speed, s, format!("{s}×"));
                    }
                })
                .response
                .on_hover_text("Slow motion and fast-forward: more or fewer steps per second, the step h never changes");
            let before = self.solver;
            egui::ComboBox::from_id_salt("solver")
                .width(80.0)
                .selected_text(self.solver.name())
                .show_ui(ui, |ui| {
                    for s in ContactSolver::ALL {
                        ui.selectable_value(&mut self.solver, s, s.name());
                    }
                })
                .response
                .on_hover_text("The contact solver: exact (coupled LCP, the default), thesis (two-stage LCP as in the thesis), soft (iterative, fast on piles; experimental: its pin joints do not hold yet), sequential (one contact at a time)");
            if self.solver != before
                && let Some(sim) = &mut self.sim
            {
                sim.world.settings.contact_solver = self.solver;
            }
            if ui
                .checkbox(&mut self.sleeping, "Sleep")
                .on_hover_text("Bodies at rest for half a second sleep and cost nothing until something touches them, a motor on them starts or you drag them")
                .changed()
                && let Some(sim) = &mut self.sim
            {
                sim.world.settings.sleeping = self.sleeping;
            }
            ui.separator();
            if matches!(self.selection, Some(Selection::Robot(_))) {
                let joint = self.tool == tools::Tool::Joint;
                if ui
                    .selectable_label(joint, "Add joint")
                    .on_hover_text("Pin two bodies together: click a point where they overlap (paused at step 0)")
                    .clicked()
                {
                    self.tool = if joint { tools::Tool::Select } else { tools::Tool::Joint };
                    if self.tool == tools::Tool::Joint {
                        self.stop_at_start();
                    }
                }
            }
            egui::ComboBox::from_id_salt("snap")
                .width(72.0)
                .selected_text(match self.snap_step {
                    Some(s) => format!("snap {s}"),
                    None => "snap off".into(),
                })
                .show_ui(ui, |ui| {
                    for step in tools::SNAP_STEPS {
                        let label = step.map_or("off".to_string(), |s| s.to_string());
                        ui.selectable_value(&mut self.snap_step, step, label);
                    }
                })
                .response
                .on_hover_text("Grid spacing that vertices, placements and joints snap to");
            ui.toggle_value(&mut self.debug.follow, "Follow").on_hover_text("Keep the moving bodies in view (panning turns it off)");
            ui.menu_button("Debug draw", |ui| {
                ui.checkbox(&mut self.debug.contacts, "Contact points and normals");
                ui.checkbox(&mut self.debug.joints, "Joint anchors and gaps");
                ui.checkbox(&mut self.debug.bounds, "Bounding boxes");
                ui.checkbox(&mut self.debug.centres, "Centres of mass");
                ui.checkbox(&mut self.debug.velocities, "Velocities");
                ui.checkbox(&mut self.debug.grid, "Grid");
                ui.checkbox(&mut self.debug.sleeping, "Sleeping bodies (faded, \"z\")");

            });
        });
    }

    fn browser(&mut self, ui: &mut egui::Ui) {
        let now = ui.input(|i| i.time);
        ui.horizontal_wrapped(|ui| {
            ui.menu_button("New", |ui| {
                for kind in ["body", "robot", "scene"] {
                    if ui.button(kind).clicked() {
                        self.new_item(kind, now);
                    }
                }
            })
            .response
            .on_hover_text("Create a body, robot or scene");
            if ui
                .add_enabled(self.selection.is_some(), egui::Button::new("Duplicate"))
                .on_hover_text("Copy the selected item under a new name")
                .clicked()
            {
                self.duplicate(now);
            }
            if ui
                .add_enabled(self.selection.is_some(), egui::Button::new("Delete"))
                .on_hover_text("Delete the selected item (refused while it is used)")
                .clicked()
            {
                self.delete(Delete::IfUnused, now);
            }
        });
        ui.separator();
        let mut chosen = None;
        egui::ScrollArea::vertical().show(ui, |ui| {
            let m = &self.db.model;
            egui::CollapsingHeader::new(format!("Scenes ({})", m.scenes.len()))
                .default_open(true)
                .show(ui, |ui| {
                    for s in &m.scenes {
                        let sel = Selection::Scene(s.name.clone());
                        if ui
                            .selectable_label(self.selection.as_ref() == Some(&sel), &s.name)
                            .clicked()
                        {
                            chosen = Some(sel);
                        }
                    }
                });
            egui::CollapsingHeader::new(format!("Robots ({})", m.robots.len()))
                .default_open(true)
                .show(ui, |ui| {
                    for r in &m.robots {
                        let sel = Selection::Robot(r.name.clone());
                        let text = format!(
                            "{} · {} bodies, {} joints",
                            r.name,
                            r.bodies.len(),
                            r.joints.len()
                        );
                        if ui
                            .selectable_label(self.selection.as_ref() == Some(&sel), text)
                            .clicked()
                        {
                            chosen = Some(sel);
                        }
                    }
                });
            egui::CollapsingHeader::new(format!("Bodies ({})", m.bodies.len()))
                .default_open(false)
                .show(ui, |ui| {
                    for b in &m.bodies {
                        let sel = Selection::Body(b.name.clone());
                        let kind = if b.density == 0.0 {
                            "static"
                        } else {
                            "dynamic"
                        };
                        if ui
                            .selectable_label(
                                self.selection.as_ref() == Some(&sel),
                                format!("{} · {kind}", b.name),
                            )
                            .clicked()
                        {
                            chosen = Some(sel);
                        }
                    }
                });
        });
        if let Some(sel) = chosen {
            self.select(sel);
        }
    }

    fn inspector(&mut self, ui: &mut egui::Ui) {
        let now = ui.input(|i| i.time);
        egui::ScrollArea::vertical().show(ui, |ui| {
            ui.heading("Inspector");
            let Some(sel) = self.selection.clone() else {
                ui.label("Select a scene, robot or body.");
                return;
            };
            let mut draft = self.db.model.clone();
            let change = inspector::show(ui, &sel, &mut draft, &mut self.name_buffer);
            if let Some((sel, new)) = change.rename {
                self.rename(sel, new, now);
            } else if let Some(key) = change.key {
                self.commit(draft, &key, now);
            }
            if !matches!(self.selection, Some(Selection::Body(_))) {
                self.followed_body(ui);
            }
        });
    }

    fn followed_body(&mut self, ui: &mut egui::Ui) {
        ui.separator();
        let (Some(sim), Some(i)) = (&self.sim, self.selected_body) else {
            ui.label("Click a body on the canvas to follow it.");
            return;
        };
        let Some(b) = sim
            .bodies
            .get(i)
            .and_then(|b| sim.world.body(b.handle).map(|body| (b, body)))
        else {
            return;
        };
        let (id, body) = b;
        let o = body.origin();
        let v = body.velocity_at(o);
        egui::Grid::new("selected").num_columns(2).show(ui, |ui| {
            for (k, val) in [
                ("body", id.id.clone()),
                ("mass", format!("{:.4}", body.mass())),
                ("inertia", format!("{:.5e}", body.inertia())),
                ("x, y", format!("{:.3}, {:.3}", o.x, o.y)),
                ("angle", format!("{:.4} rad", body.angle)),
                ("vx, vy", format!("{:.3}, {:.3}", v.x, v.y)),
                ("ω", format!("{:.4} rad/s", body.angular_velocity)),
            ] {
                ui.label(k);
                ui.label(val);
                ui.end_row();
            }
        });
    }

    fn plots(&mut self, ui: &mut egui::Ui) {
        use egui_plot::{Legend, Line, Plot};
        let h = &self.plot_data;
        // At least a second of time axis, so that a run's first sample does not blow the
        // x range up around a single point.
        let t0 = h.samples.first().map_or(0.0, |s| s.time);
        let body_title = match self
            .selected_body
            .and_then(|i| self.sim.as_ref()?.bodies.get(i))
        {
            Some(b) => format!("body {}: position, angle, velocity", b.id),
            None => "click a body on the canvas to plot it".to_string(),
        };
        ui.columns(3, |cols| {
            cols[0].label("energy");
            cols[1].label(body_title);
            cols[2].label("motor torques, joint gap");
            Plot::new("energy")
                .legend(Legend::default())
                .height(136.0)
                .include_x(t0)
                .include_x(t0 + 1.0)
                .show(&mut cols[0], |p| {
                    p.line(Line::new("kinetic", h.series(|s| Some(s.kinetic))));
                    p.line(Line::new("potential", h.series(|s| Some(s.potential))));
                    p.line(Line::new(
                        "total",
                        h.series(|s| Some(s.kinetic + s.potential)),
                    ));
                });
            Plot::new("body")
                .legend(Legend::default())
                .height(136.0)
                .include_x(t0)
                .include_x(t0 + 1.0)
                .show(&mut cols[1], |p| {
                    for (k, name) in ["x", "y", "angle", "vx", "vy", "ω"].iter().enumerate() {
                        p.line(Line::new(*name, h.series(|s| s.body.map(|b| b[k]))));
                    }
                });
            Plot::new("motors")
                .legend(Legend::default())
                .height(136.0)
                .include_x(t0)
                .include_x(t0 + 1.0)
                .show(&mut cols[2], |p| {
                    for (k, name) in h.motor_names.iter().enumerate() {
                        p.line(Line::new(
                            format!("τ {name}"),
                            h.series(|s| s.torques.get(k).copied()),
                        ));
                    }
                    p.line(Line::new(
                        "joint gap ×1e6",
                        h.series(|s| Some(s.max_joint_gap * 1e6)),
                    ));
                });
        });
    }

    fn inform(&mut self, news: String) {
        self.status = news;
        self.status_is_error = false;
    }

    fn complain(&mut self, problem: String) {
        self.status = problem;
        self.status_is_error = true;
    }

    fn status_bar(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            let errors = self.problems.iter().filter(|p| p.is_error()).count();
            let warnings = self.problems.len() - errors;
            let text = format!("{errors} errors, {warnings} warnings");
            let colour = if errors > 0 {
                egui::Color32::LIGHT_RED
            } else if warnings > 0 {
                egui::Color32::YELLOW
            } else {
                egui::Color32::LIGHT_GREEN
            };
            if ui
                .add(egui::Button::new(egui::RichText::new(text).color(colour)))
                .on_hover_text("Show every problem")
                .clicked()
            {
                self.show_problems = !self.show_problems;
            }
            if let Some(first) = self.problems.first() {
                ui.label(first.to_string());
            }
            if !self.status.is_empty() {
                if self.status_is_error {
                    ui.colored_label(egui::Color32::LIGHT_RED, &self.status);
                } else {
                    ui.label(&self.status);
                }
            }
            ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
                if let Some(sim) = &self.sim {
                    let m = sim.metrics();
                    ui.label(format!(
                        "step {} · t = {:.3} s · h = {:.4} s · {} contacts · {}",
                        m.step,
                        m.time,
                        sim.dt,
                        m.contacts,
                        self.solver.name()
                    ));
                }
            });
        });
    }
}

impl RoboSimApp {
    fn central(&mut self, ui: &mut egui::Ui, now: f64) {
        self.canvas_rect = ui.available_rect_before_wrap();
        let fit = !self.camera_fitted;
        if let Some(Selection::Body(name)) = self.selection.clone() {
            let vertices = self
                .db
                .model
                .body(&name)
                .map(|b| b.vertices.clone())
                .unwrap_or_default();
            match canvas::edit_vertices(
                ui,
                &vertices,
                &mut self.camera,
                fit,
                &mut self.vertex_drag,
                self.snap_step,
            ) {
                canvas::VertexEdit::Changed(new) => {
                    let mut draft = self.db.model.clone();
                    if let Some(b) = draft.body_mut(&name) {
                        b.vertices = new;
                    }
                    let key = format!("vertex {:?}", self.vertex_drag);
                    self.inform(String::new());
                    self.commit(draft, &key, now);
                }
                canvas::VertexEdit::Refused(why) => self.complain(why),
                canvas::VertexEdit::None => {}
            }
            self.camera_fitted = true;
            return;
        }
        let editing = !self.running && self.sim.as_ref().is_some_and(|s| s.step_count() == 0);
        let outcome = canvas::show(
            ui,
            self.sim.as_mut(),
            &mut self.camera,
            canvas::Mode {
                fit,
                editing,
                tool: self.tool,
            },
            &mut self.debug,
            &mut self.grab,
            &mut self.selected_body,
        );
        if outcome.fitted {
            self.camera_fitted = true;
        }
        if outcome.selection_changed {
            self.plot_data.clear();
            if let Some(sim) = &self.sim {
                self.plot_data.record(sim, self.selected_body);
            }
        }
        if let Some((index, wanted)) = outcome.moved {
            self.move_placement(index, wanted, now);
        }
        if let Some(p) = outcome.tool_click {
            self.use_tool(p, now);
        }
        if editing
            && let Some(i) = self.selected_body
            && !ui.ctx().text_edit_focused()
        {
            let turn = ui
                .input(|i| i.key_pressed(egui::Key::E) as i32 - i.key_pressed(egui::Key::Q) as i32);
            if turn != 0 {
                self.rotate_placement(i, turn as f64 * 15f64.to_radians(), now);
            }
        }
    }

    /// Applies the current tool at world point `p` (the robot preview puts the robot's
    /// frame at the world origin, so world and robot coordinates agree).
    fn use_tool(&mut self, p: pe::Vec2, now: f64) {
        let (tools::Tool::Joint, Some(Selection::Robot(robot))) =
            (self.tool, self.selection.clone())
        else {
            return;
        };
        let p = pe::Vec2::new(
            tools::snap(p.x, self.snap_step),
            tools::snap(p.y, self.snap_step),
        );
        let mut draft = self.db.model.clone();
        match tools::add_joint(&mut draft, &robot, p) {
            Ok(j) => {
                self.inform(format!(
                    "pinned {} to {} at ({}, {})",
                    j.body_b, j.body_a, p.x, p.y
                ));
                self.commit(draft, "add joint", now);
            }
            Err(why) => self.complain(why),
        }
    }

    /// Moves the placement behind simulated body `index` so that its reference point goes
    /// to `wanted` (snapped to the grid): a scene body, a whole robot in a scene, or a body
    /// within a robot.
    fn move_placement(&mut self, index: usize, wanted: pe::Vec2, now: f64) {
        let Some(origin) = self.sim.as_ref().and_then(|s| {
            let b = s.bodies.get(index)?;
            Some(s.world.body(b.handle)?.origin())
        }) else {
            return;
        };
        let snapped = pe::Vec2::new(
            tools::snap(wanted.x, self.snap_step),
            tools::snap(wanted.y, self.snap_step),
        );
        let delta = snapped - origin;
        if delta.norm() < 1e-12 {
            return;
        }
        self.edit_placement(index, now, |x, y, _| {
            *x += delta.x;
            *y += delta.y;
        });
    }

    /// Turns the placement behind simulated body `index` by `angle` about its origin.
    fn rotate_placement(&mut self, index: usize, angle: f64, now: f64) {
        self.edit_placement(index, now, |_, _, o| *o += angle);
    }

    /// Edits (x, y, orientation) of the placement that puts simulated body `index` where it
    /// is: in a scene, the scene body or the whole robot; in a robot, the body's place in it.
    fn edit_placement(
        &mut self,
        index: usize,
        now: f64,
        edit: impl FnOnce(&mut f64, &mut f64, &mut f64),
    ) {
        let Some(body) = self.sim.as_ref().and_then(|s| s.bodies.get(index)).cloned() else {
            return;
        };
        let mut draft = self.db.model.clone();
        match (&self.selection, body.placed_by) {
            (Some(Selection::Scene(name)), placed_by) => {
                let Some(scene) = draft.scene_mut(name) else {
                    return;
                };
                let placement = match placed_by {
                    PlacedBy::SceneBody(k) => scene
                        .bodies
                        .get_mut(k)
                        .map(|b| (&mut b.x, &mut b.y, &mut b.orientation)),
                    PlacedBy::RobotBody { robot, .. } => scene
                        .robots
                        .get_mut(robot)
                        .map(|r| (&mut r.x, &mut r.y, &mut r.orientation)),
                };
                let Some((x, y, o)) = placement else {
                    return;
                };
                edit(x, y, o);
            }
            // The robot preview places the robot alone at the origin.
            (Some(Selection::Robot(name)), PlacedBy::RobotBody { body: k, .. }) => {
                let Some(b) = draft.robot_mut(name).and_then(|r| r.bodies.get_mut(k)) else {
                    return;
                };
                let p = &mut b.placement;
                edit(&mut p.x, &mut p.y, &mut p.orientation);
            }
            _ => return,
        }
        self.commit(draft, &format!("place {}", body.id), now);
    }

    fn dialogs(&mut self, ctx: &egui::Context, now: f64) {
        let Some(dialog) = self.dialog.clone() else {
            return;
        };
        let mut close = false;
        egui::Window::new("RoboSim")
            .collapsible(false)
            .resizable(false)
            .anchor(egui::Align2::CENTER_CENTER, [0.0, 0.0])
            .show(ctx, |ui| match &dialog {
                Dialog::Overwrite(why) => {
                    ui.label(why);
                    ui.horizontal(|ui| {
                        if ui.button("Overwrite").clicked() {
                            close = true;
                            self.save(Overwrite::Confirmed);
                        }
                        if ui.button("Cancel").clicked() {
                            close = true;
                        }
                    });
                }
                Dialog::Unsaved(after) => {
                    ui.label("The database has unsaved changes.");
                    ui.horizontal(|ui| {
                        if ui.button("Save").clicked() {
                            close = true;
                            self.save(Overwrite::Never);
                            if !self.db.is_dirty() {
                                self.finish(after.clone(), ctx);
                            }
                        }
                        if ui.button("Discard").clicked() {
                            close = true;
                            self.finish(after.clone(), ctx);
                        }
                        if ui.button("Cancel").clicked() {
                            close = true;
                        }
                    });
                }
                Dialog::Restore(model) => {
                    ui.label(
                        "Unsaved work from a session that ended unexpectedly was kept. Restore it?",
                    );
                    ui.horizontal(|ui| {
                        if ui.button("Restore").clicked() {
                            close = true;
                            self.commit(model.clone(), "restore", now);
                        }
                        if ui.button("Discard it").clicked() {
                            close = true;
                            self.clear_autosave();
                        }
                    });
                }
                Dialog::Cascade(_, why) => {
                    ui.label(why);
                    ui.horizontal(|ui| {
                        if ui.button("Delete it and its placements").clicked() {
                            close = true;
                            self.delete(Delete::Cascade, now);
                        }
                        if ui.button("Cancel").clicked() {
                            close = true;
                        }
                    });
                }
            });
        if close && self.dialog.as_ref() == Some(&dialog) {
            self.dialog = None;
        }
    }

    /// Where unsaved work is kept between saves (eframe's per-user data folder).
    fn autosave_dir() -> Option<PathBuf> {
        eframe::storage_dir("RoboSim").map(|d| d.join("autosave"))
    }

    /// Keeps a copy of unsaved work, to be offered back after a crash; called by eframe
    /// every 30 s and on exit.
    fn autosave(&mut self) {
        let Some(dir) = Self::autosave_dir() else {
            return;
        };
        if !self.db.is_dirty() || self.close_confirmed {
            self.clear_autosave();
            return;
        }
        let mut copy = Database::new(self.db.model.clone());
        if copy.save_to(&dir, Overwrite::Confirmed).is_err() {
            self.complain(format!("could not autosave to {}", dir.display()));
        }
    }

    fn clear_autosave(&self) {
        if let Some(dir) = Self::autosave_dir() {
            let _ = std::fs::remove_dir_all(dir);
        }
    }

    /// Offers back work autosaved by a session that ended without saving or discarding.
    fn offer_restore(&mut self) {
        let Some(dir) = Self::autosave_dir().filter(|d| d.is_dir()) else {
            return;
        };
        let (saved, _) = Database::load(&dir);
        if saved.model != self.db.model {
            self.dialog = Some(Dialog::Restore(saved.model));
        }
    }

    fn finish(&mut self, after: AfterSave, ctx: &egui::Context) {
        match after {
            AfterSave::Quit => {
                self.close_confirmed = true;
                self.clear_autosave();
                ctx.send_viewport_cmd(egui::ViewportCommand::Close);
            }
            AfterSave::Open(dir) => self.open_now(dir),
        }
    }
}

/// Appends a copy of the item named `name` under a free "… copy" name; returns that name.
fn push_copy<T: Clone>(
    items: &mut Vec<T>,
    name: &str,
    name_of: fn(&mut T) -> &mut String,
) -> Option<String> {
    let taken: Vec<String> = items.iter_mut().map(|i| name_of(i).clone()).collect();
    let index = taken.iter().position(|t| t == name)?;
    let mut copy = items[index].clone();
    let new_name = inspector::unique(&taken, &format!("{name} copy"));
    *name_of(&mut copy) = new_name.clone();
    items.push(copy);
    Some(new_name)
}

/// The name of the synthetic scene a robot or body is previewed in.
const PREVIEW: &str = "\u{0}preview";

/// `model` plus a scene holding just `robot` or `body` at the origin, without gravity.
fn preview(model: &Model, robot: Option<&str>, body: Option<&str>) -> Model {
    let mut m = model.clone();
    let mut scene = Scene {
        name: PREVIEW.to_string(),
        friction: 0.5,
        ..Scene::default()
    };
    if let Some(r) = robot {
        scene.robots.push(SceneRobot {
            source: r.to_string(),
            ..SceneRobot::default()
        });
    }
    if let Some(b) = body {
        scene.bodies.push(crate::model::Placement {
            alias: b.to_string(),
            source: b.to_string(),
            ..Default::default()
        });
    }
    m.scenes.push(scene);
    m
}

impl eframe::App for RoboSimApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let typing = ui.ctx().text_edit_focused();
        let (frame_seconds, space, step, reset) = ui.input(|i| {
            (
                i.stable_dt as f64,
                !typing && i.key_pressed(egui::Key::Space),
                !typing && i.key_pressed(egui::Key::S),
                !typing && i.key_pressed(egui::Key::R),
            )
        });
        if space {
            self.running = !self.running;
        }
        if step {
            self.running = false;
            self.single_step();
        }
        if reset {
            self.reset();
        }
        let now = ui.input(|i| i.time);
        let (save, undo, redo, delete) = ui.input_mut(|i| {
            let redo_y = i.consume_key(egui::Modifiers::COMMAND, egui::Key::Y);
            let redo_z = i.consume_key(
                egui::Modifiers::COMMAND | egui::Modifiers::SHIFT,
                egui::Key::Z,
            );
            (
                i.consume_key(egui::Modifiers::COMMAND, egui::Key::S),
                i.consume_key(egui::Modifiers::COMMAND, egui::Key::Z),
                redo_y || redo_z,
                !typing && i.key_pressed(egui::Key::Delete),
            )
        });
        if save {
            self.save(Overwrite::Never);
        }
        if undo && !typing {
            self.undo();
        }
        if redo && !typing {
            self.redo();
        }
        if delete {
            self.delete(Delete::IfUnused, now);
        }
        // The unsaved-changes guard on quit.
        if ui.input(|i| i.viewport().close_requested())
            && !self.close_confirmed
            && self.db.is_dirty()
        {
            ui.ctx()
                .send_viewport_cmd(egui::ViewportCommand::CancelClose);
            self.dialog = Some(Dialog::Unsaved(AfterSave::Quit));
        }
        self.advance(frame_seconds);
        egui::Panel::top("toolbar").show(ui, |ui| self.toolbar(ui));
        egui::Panel::bottom("status").show(ui, |ui| self.status_bar(ui));
        // A body on its own has nothing to plot: its editor gets the room.
        if !matches!(self.selection, Some(Selection::Body(_))) {
            egui::Panel::bottom("plots")
                .resizable(true)
                .default_size(180.0)
                .show(ui, |ui| self.plots(ui));
        }
        egui::Panel::left("browser")
            .resizable(true)
            .default_size(230.0)
            .show(ui, |ui| self.browser(ui));
        egui::Panel::right("inspector")
            .resizable(true)
            .default_size(260.0)
            .show(ui, |ui| self.inspector(ui));
        egui::CentralPanel::default().show(ui, |ui| self.central(ui, now));
        self.dialogs(ui.ctx(), now);
        if self.show_problems {
            let mut open = true;
            egui::Window::new("Problems")
                .open(&mut open)
                .show(ui.ctx(), |ui| {
                    egui::ScrollArea::vertical().show(ui, |ui| {
                        for p in &self.problems {
                            ui.label(p.to_string());
                        }
                    });
                });
            self.show_problems = open;
        }
        if self.running || self.grab.is_some() {
            ui.ctx().request_repaint();
        }
    }

    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        self.autosave();
        eframe::set_value(storage, RECENT_KEY, &self.recent);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::BodyDef;

    #[test]
    fn a_duplicate_gets_the_first_free_copy_name_and_the_same_contents() {
        let body = |name: &str| BodyDef {
            name: name.to_string(),
            density: 2.0,
            ..BodyDef::default()
        };
        let mut bodies = vec![body("box"), body("box copy")];
        assert_eq!(
            push_copy(&mut bodies, "box", |b| &mut b.name).as_deref(),
            Some("box copy 2")
        );
        assert_eq!(bodies[2], body("box copy 2"));
        assert_eq!(push_copy(&mut bodies, "nothing", |b| &mut b.name), None);
        assert_eq!(bodies.len(), 3);
    }
}
