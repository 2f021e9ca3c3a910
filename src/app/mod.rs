//! The desktop app (eframe/egui): a database browser, the canvas, an inspector, plots and a
//! status bar. UI code reads the model and the simulation; physics lives in `pe` and
//! `sim`, files in `db`.

pub mod camera;
pub mod canvas;
pub mod history;

use crate::db::{Database, Problem};
use crate::model::{Model, Scene, SceneRobot};
use crate::sim::Simulation;
use camera::Camera;
use canvas::{DebugDraw, Grab};
use history::History;
use pe::ContactSolver;
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
    pub camera: Camera,
    camera_fitted: bool,
    pub running: bool,
    pub speed: f64,
    /// Simulated time owed to the physics: real time × speed, paid in whole steps.
    accumulator: f64,
    pub debug: DebugDraw,
    pub history: History,
    /// Index into `sim.bodies` of the body the inspector and plots follow.
    pub selected_body: Option<usize>,
    grab: Option<Grab>,
    path_input: String,
    pub status: String,
    show_problems: bool,
    pub recent: Vec<String>,
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
            camera: Camera::default(),
            camera_fitted: false,
            running: true,
            speed: 1.0,
            accumulator: 0.0,
            debug: DebugDraw::default(),
            history: History::default(),
            selected_body: None,
            grab: None,
            path_input: dir.map(|d| d.display().to_string()).unwrap_or_default(),
            status: String::new(),
            show_problems: false,
            recent: Vec::new(),
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
            Ok(sim) => {
                self.sim = Some(sim);
                self.status.clear();
            }
            Err(e) => {
                self.sim = None;
                self.status = e.to_string();
            }
        }
        self.running = run;
        self.selection = Some(selection);
        self.after_rebuild();
        self.camera_fitted = false;
    }

    fn after_rebuild(&mut self) {
        self.accumulator = 0.0;
        self.grab = None;
        self.history.clear();
        if let Some(sim) = &self.sim {
            self.history.record(sim, self.selected_body);
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
        self.history.record(sim, self.selected_body);
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
                    .desired_width(180.0),
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
                .selected_text(self.solver.name())
                .show_ui(ui, |ui| {
                    for s in ContactSolver::ALL {
                        ui.selectable_value(&mut self.solver, s, s.name());
                    }
                })
                .response
                .on_hover_text("The contact solver: exact (coupled LCP), thesis (two-stage LCP), soft (iterative), sequential");
            if self.solver != before
                && let Some(sim) = &mut self.sim
            {
                sim.world.settings.contact_solver = self.solver;
            }
            ui.separator();
            ui.toggle_value(&mut self.debug.follow, "Follow").on_hover_text("Keep the moving bodies in view (panning turns it off)");
            ui.menu_button("Debug draw", |ui| {
                ui.checkbox(&mut self.debug.contacts, "Contact points and normals");
                ui.checkbox(&mut self.debug.joints, "Joint anchors and gaps");
                ui.checkbox(&mut self.debug.bounds, "Bounding boxes");
                ui.checkbox(&mut self.debug.centres, "Centres of mass");
                ui.checkbox(&mut self.debug.velocities, "Velocities");
                ui.checkbox(&mut self.debug.grid, "Grid");

            });
        });
    }

    fn browser(&mut self, ui: &mut egui::Ui) {
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
        ui.heading("Inspector");
        match &self.selection {
            Some(Selection::Scene(name)) => {
                if let Some(s) = self.db.model.scene(name) {
                    egui::Grid::new("scene").num_columns(2).show(ui, |ui| {
                        ui.label("scene");
                        ui.label(&s.name);
                        ui.end_row();
                        ui.label("gravitation");
                        ui.label(format!("{} px/s²", s.gravitation));
                        ui.end_row();
                        ui.label("friction μ");
                        ui.label(format!("{}", s.friction));
                        ui.end_row();
                        ui.label("timestep h");
                        ui.label(format!(
                            "{:.5} s{}",
                            s.timestep(),
                            if s.timestep.is_none() {
                                " (default)"
                            } else {
                                ""
                            }
                        ));
                        ui.end_row();
                    });
                }
            }
            Some(Selection::Body(name)) => {
                if let Some(def) = self.db.model.body(name) {
                    ui.label(format!("body \"{}\"", def.name));
                    match crate::db::polygon(def) {
                        Ok(poly) => {
                            let mp = poly.mass_properties();
                            egui::Grid::new("body").num_columns(2).show(ui, |ui| {
                                for (k, v) in [
                                    ("density", format!("{}", def.density)),
                                    ("cor", format!("{}", def.cor)),
                                    ("vertices", format!("{}", def.vertices.len())),
                                    ("area", format!("{:.4}", mp.area)),
                                    ("mass", format!("{:.4}", mp.area * def.density)),
                                    (
                                        "centroid",
                                        format!("({:.3}, {:.3})", mp.centroid.x, mp.centroid.y),
                                    ),
                                    ("inertia", format!("{:.5e}", mp.second_moment * def.density)),
                                ] {
                                    ui.label(k);
                                    ui.label(v);
                                    ui.end_row();
                                }
                            });
                        }
                        Err(e) => {
                            ui.colored_label(egui::Color32::LIGHT_RED, e.to_string());
                        }
                    }
                }
            }
            Some(Selection::Robot(name)) => {
                if let Some(r) = self.db.model.robot(name) {
                    ui.label(format!("robot \"{}\"", r.name));
                    for b in &r.bodies {
                        let motors = if b.motors.is_empty() {
                            String::new()
                        } else {
                            format!(" · {} motor(s)", b.motors.len())
                        };
                        ui.label(format!(
                            "• {} ({}){motors}",
                            b.placement.alias, b.placement.source
                        ));
                    }
                    for j in &r.joints {
                        let motor = if j.motor.is_some() { " · motor" } else { "" };
                        ui.label(format!("⊙ {}–{}{motor}", j.body_a, j.body_b));
                    }
                }
            }
            None => {
                ui.label("Select a scene, robot or body.");
            }
        }
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
        let h = &self.history;
        ui.columns(3, |cols| {
            Plot::new("energy")
                .legend(Legend::default())
                .height(150.0)
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
                .height(150.0)
                .show(&mut cols[1], |p| {
                    for (k, name) in ["x", "y", "angle", "vx", "vy", "ω"].iter().enumerate() {
                        p.line(Line::new(*name, h.series(|s| s.body.map(|b| b[k]))));
                    }
                });
            Plot::new("motors")
                .legend(Legend::default())
                .height(150.0)
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
                ui.colored_label(egui::Color32::LIGHT_RED, &self.status);
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
        self.advance(frame_seconds);
        egui::Panel::top("toolbar").show(ui, |ui| self.toolbar(ui));
        egui::Panel::bottom("status").show(ui, |ui| self.status_bar(ui));
        egui::Panel::bottom("plots")
            .resizable(true)
            .default_size(180.0)
            .show(ui, |ui| self.plots(ui));
        egui::Panel::left("browser")
            .resizable(true)
            .default_size(230.0)
            .show(ui, |ui| self.browser(ui));
        egui::Panel::right("inspector")
            .resizable(true)
            .default_size(260.0)
            .show(ui, |ui| self.inspector(ui));
        egui::CentralPanel::default().show(ui, |ui| {
            let fit = !self.camera_fitted;
            let outcome = canvas::show(
                ui,
                self.sim.as_mut(),
                &mut self.camera,
                fit,
                &mut self.debug,
                &mut self.grab,
                &mut self.selected_body,
            );
            if outcome.fitted {
                self.camera_fitted = true;
            }
            if outcome.selection_changed {
                self.history.clear();
                if let Some(sim) = &self.sim {
                    self.history.record(sim, self.selected_body);
                }
            }
        });
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
        eframe::set_value(storage, RECENT_KEY, &self.recent);
    }
}
