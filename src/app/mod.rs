//! The desktop app (eframe/egui), built the way egui's demo app is: a document (the
//! database, its undo history and files), a runner (the simulation and its clock), and
//! panels that each draw themselves with their own `ui` and return commands, which
//! `RoboSimApp::apply` carries out in one place. Physics lives in `pe` and `sim`, files in
//! `db`.

pub mod autosave;
pub mod browser;
pub mod camera;
pub mod canvas;
pub mod command;
pub mod dialogs;
pub mod document;
mod edit_commands;
mod file_commands;
pub mod files;
pub mod inspector;
mod placements;
pub mod placing;
pub mod plot_data;
pub mod plots;
pub mod runner;
pub mod shortcuts;
pub mod status;
pub mod toolbar;
pub mod tools;
pub mod undo;
pub mod world_bound;

use crate::db::Problem;
use crate::model::Model;
use crate::sim::Simulation;
use command::AfterSave;
pub use command::Command;
use dialogs::Dialog;
use document::Document;
use runner::Runner;
use std::path::PathBuf;

/// The window's icon, shipped in `assets/`.
const ICON: &[u8] = include_bytes!("../../assets/robosim.png");

/// Runs the app in a native window until it is closed: on `db`, or the embedded default.
pub fn run(db: Option<PathBuf>) -> Result<(), String> {
    let mut viewport = egui::ViewportBuilder::default()
        .with_title("RoboSim")
        .with_app_id("robosim")
        .with_inner_size([1280.0, 800.0]);
    if let Ok(icon) = eframe::icon_data::from_png_bytes(ICON) {
        viewport = viewport.with_icon(icon);
    }
    let options = eframe::NativeOptions {
        viewport,
        ..Default::default()
    };
    eframe::run_native(
        "RoboSim",
        options,
        Box::new(move |cc| {
            let autosave_root = eframe::storage_dir("RoboSim").map(|d| d.join("autosave"));
            let mut app = RoboSimApp::new(db).with_autosave(autosave_root);
            if let Some(storage) = cc.storage {
                app.toolbar.recent = eframe::get_value(storage, RECENT_KEY).unwrap_or_default();
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

/// One placement as Ctrl+C copies it (the clipboard, `placements::Clipboard`, holds
/// several), to paste into a scene or a robot.
#[derive(Debug, Clone, PartialEq)]
pub enum Copied {
    SceneRobot(crate::model::SceneRobot),
    SceneBody(crate::model::Placement),
    RobotBody(crate::model::RobotBody),
}

pub struct RoboSimApp {
    doc: Document,
    runner: Runner,
    view: canvas::CanvasView,
    selection: Option<Selection>,
    /// The body the inspector and the plots follow (index into the simulation's bodies).
    followed: Option<usize>,
    /// The bodies selected on the canvas (indices into the simulation's bodies): every
    /// body of each selected placement, the followed one among them. Edits at step 0
    /// (move, nudge, turn, delete, copy, duplicate) apply to the placements behind them.
    picked: Vec<usize>,
    toolbar: toolbar::Toolbar,
    inspector: inspector::Inspector,
    plots: plots::PlotsPanel,
    dialog: Option<Dialog>,
    message: status::Message,
    show_problems: bool,
    show_shortcuts: bool,
    show_about: bool,
    show_guide: bool,
    /// How the app asks for folders and file names.
    files: Box<dyn files::FileChooser>,
    /// The system has no file dialog (it came back at once): ask in the app's own.
    no_system_dialog: bool,
    /// The app's own file chooser, while it asks.
    in_app_chooser: Option<files::InAppChooser>,
    /// Where the last export went: the next one is offered there.
    export_folder: Option<PathBuf>,
    /// The user guide's Markdown, laid out once.
    guide_markdown: egui_commonmark::CommonMarkCache,
    copied: Option<placements::Clipboard>,
    /// Text for the system clipboard, put there at the end of the frame (Ctrl+C, X).
    clipboard_out: Option<String>,
    /// The text of this frame's paste event, if any: placements copied in this window or
    /// another are pasted from it, others from `copied`.
    pasted: Option<String>,
    /// The window may close: the user answered the unsaved-changes question.
    close_confirmed: bool,
    /// What an export finished on another thread (a PNG of the view, a GIF of the run)
    /// has to say: what it wrote, or why not.
    export_news: std::sync::Arc<std::sync::Mutex<Option<Result<String, String>>>>,
}

impl RoboSimApp {
    /// The app on `dir`'s database, or on the embedded default; the first scene selected.
    /// A folder that does not exist is asked about.
    pub fn new(dir: Option<PathBuf>) -> Self {
        let mut app = Self {
            doc: Document::open(dir.as_deref()),
            runner: Runner::default(),
            view: canvas::CanvasView::default(),
            selection: None,
            followed: None,
            picked: Vec::new(),
            toolbar: toolbar::Toolbar::default(),
            inspector: inspector::Inspector::default(),
            plots: plots::PlotsPanel::default(),
            dialog: None,
            message: status::Message::default(),
            show_problems: false,
            show_shortcuts: false,
            show_about: false,
            show_guide: false,
            files: Box::new(files::SystemDialogs),
            no_system_dialog: false,
            in_app_chooser: None,
            export_folder: None,
            guide_markdown: Default::default(),
            copied: None,
            clipboard_out: None,
            pasted: None,
            close_confirmed: false,
            export_news: Default::default(),
        };
        app.toolbar.path_input = dir
            .as_ref()
            .map(|d| d.display().to_string())
            .unwrap_or_default();
        app.select_first_scene();
        if let Some(missing) = dir.filter(|d| !d.exists()) {
            app.dialog = Some(Dialog::MissingFolder(missing));
        }
        app
    }

    /// Asks for folders and file names through `files` instead of the system's dialogs.
    pub fn with_file_chooser(mut self, files: Box<dyn files::FileChooser>) -> Self {
        self.files = files;
        self
    }

    /// Keeps unsaved work under `root` (None: nowhere), and offers back what an earlier
    /// session kept there for this database.
    pub fn with_autosave(mut self, root: Option<PathBuf>) -> Self {
        self.doc.keep_unsaved_work_under(root);
        self.offer_restore();
        self
    }

    // What tests and the screenshots read.

    pub fn model(&self) -> &Model {
        self.doc.model()
    }

    pub fn db(&self) -> &crate::db::Database {
        self.doc.db()
    }

    pub fn selection(&self) -> Option<&Selection> {
        self.selection.as_ref()
    }

    pub fn sim(&self) -> Option<&Simulation> {
        self.runner.sim()
    }

    pub fn problems(&self) -> &[Problem] {
        self.doc.problems()
    }

    /// The last message in the status bar.
    pub fn status(&self) -> &str {
        &self.message.text
    }

    pub fn is_running(&self) -> bool {
        self.runner.running
    }

    pub fn set_speed(&mut self, speed: f64) {
        self.runner.speed = speed;
    }

    pub fn camera(&self) -> &camera::Camera {
        &self.view.camera
    }

    pub fn camera_mut(&mut self) -> &mut camera::Camera {
        &mut self.view.camera
    }

    /// Where the canvas was drawn last frame (screen points).
    pub fn canvas_rect(&self) -> egui::Rect {
        self.view.rect
    }

    /// Pairs of bodies that overlap at step 0 (indices into the simulation's bodies).
    pub fn overlaps(&self) -> &[(usize, usize)] {
        self.runner.overlaps()
    }

    pub fn world_bound(&self) -> Option<&world_bound::WorldBound> {
        self.runner.world_bound()
    }

    pub fn plot_data(&self) -> &plot_data::PlotData {
        &self.runner.plot_data
    }

    pub fn followed(&self) -> Option<usize> {
        self.followed
    }

    /// The bodies selected on the canvas (indices into the simulation's bodies).
    pub fn picked(&self) -> &[usize] {
        &self.picked
    }

    // Applying commands.

    fn inform(&mut self, news: String) {
        self.message = status::Message {
            text: news,
            is_error: false,
        };
    }

    fn complain(&mut self, problem: String) {
        self.message = status::Message {
            text: problem,
            is_error: true,
        };
    }

    fn select_first_scene(&mut self) {
        match self.doc.model().scenes.first().map(|s| s.name.clone()) {
            Some(first) => self.select(Selection::Scene(first)),
            None => {
                self.selection = None;
                self.runner.clear();
            }
        }
    }

    /// Shows `selection`: a scene is built and runs; a robot or a body is previewed still.
    pub fn select(&mut self, selection: Selection) {
        self.followed = None;
        self.picked.clear();
        match self.runner.show(self.doc.model(), &selection, None) {
            Ok(()) => self.inform(String::new()),
            Err(e) => self.complain(e),
        }
        if !tool_fits(self.view.tool, Some(&selection)) {
            self.view.tool = tools::Tool::Select;
        }
        self.selection = Some(selection);
        self.view.fit();
    }

    /// After the model changed: rebuilds what the canvas shows, paused at step 0, keeping
    /// the view (unless it had nothing to frame, a new empty robot) and the followed body.
    fn model_changed(&mut self) {
        let had_bodies = self.sim().is_some_and(|s| !s.bodies.is_empty());
        let (camera, fitted, followed) = (self.view.camera, self.view.fitted, self.followed);
        let picked = std::mem::take(&mut self.picked);
        let message = self.message.clone();
        match self.selection.clone() {
            Some(sel) if self.doc.has(&sel) => {
                // The body editor keeps its view while an outline is drawn: a body of fewer
                // than three vertices has no simulated body, and refitting when the third
                // made one moved the next click off target.
                let keep_view = had_bodies || matches!(sel, Selection::Body(_));
                self.select(sel);
                if !self.message.is_error && !message.is_error {
                    // What the edit said ("pinned a to b") outlives the rebuild it caused; a
                    // complaint the edit answered (a dent refused) does not.
                    self.message = message;
                }
                self.runner.running = false;
                self.view.camera = camera;
                self.view.fitted = fitted && keep_view;
                let count = self.sim().map_or(0, |s| s.bodies.len());
                self.followed = followed.filter(|&i| i < count);
                self.picked = picked.into_iter().filter(|&i| i < count).collect();
            }
            _ => {
                self.selection = None;
                self.runner.clear();
            }
        }
    }

    /// Makes `draft` the model as one undoable edit (merged with the last if `key` is the
    /// same field soon after) and rebuilds what the canvas shows.
    fn commit(&mut self, draft: Model, key: &str, now: f64) {
        // An edit a scene that has run cannot take up as it runs is asked about first.
        let has_run = matches!(self.selection, Some(Selection::Scene(_)))
            && self.sim().is_some_and(|s| s.step_count() > 0);
        if has_run
            && draft != *self.doc.model()
            && !self.sim().is_some_and(|s| s.can_follow_live_edit(&draft))
        {
            if self.dialog.is_none() {
                self.dialog = Some(dialogs::Dialog::RestartForEdit(
                    Box::new(draft),
                    key.to_string(),
                ));
            }
            return;
        }
        if self.doc.commit(draft, key, now) {
            self.model_edited();
        }
    }

    /// After an edit (or its undo): a running scene takes it up as it runs where it can
    /// (gravity, friction, the step, joint motors), else what the canvas shows is built
    /// again.
    pub(super) fn model_edited(&mut self) {
        let showing_scene = matches!(self.selection, Some(Selection::Scene(_)));
        if !(showing_scene && self.runner.follow_live_edit(self.doc.model())) {
            self.model_changed();
        }
    }

    fn apply(&mut self, command: Command, ctx: &egui::Context, now: f64) {
        use Command as C;
        match command {
            C::AskOpen
            | C::Open(_)
            | C::NewDatabase
            | C::Discard(_)
            | C::SaveThen(_)
            | C::Save
            | C::SaveAs
            | C::SaveAnyway
            | C::SaveOverwriting
            | C::Revert
            | C::Quit
            | C::SaveIn(_)
            | C::Export(_)
            | C::ExportTo(..)
            | C::Restore(..)
            | C::DiscardKeptWork(_) => self.apply_file_command(command, ctx, now),
            C::SetRunning(on) => self.runner.running = on,
            C::CommitRestarting(draft, key) => {
                if self.doc.commit(*draft, &key, now) {
                    self.model_changed();
                }
            }
            C::TogglePlay if matches!(self.selection, Some(Selection::Body(_))) => {
                self.inform(
                    "a body alone has nothing to run: place it in a scene or a robot".into(),
                );
            }
            C::TogglePlay => {
                self.runner.running = !self.runner.running;
                // What the run said when it stopped ("paused: nothing moves") is stale now.
                if self.runner.running && !self.message.is_error {
                    self.inform(String::new());
                }
            }
            C::Step => {
                self.runner.running = false;
                let note = self.runner.step(self.followed);
                self.run_note(note);
            }
            C::Reset => {
                self.runner.reset(self.followed);
                self.view.fit();
                // "left the scene", "paused": the run they spoke of is gone.
                self.inform(String::new());
            }
            C::SetSpeed(speed) => self.runner.speed = speed,
            C::SetSolver(solver) => self.runner.set_solver(solver),
            C::SetSleeping(on) => self.runner.set_sleeping(on),
            C::ScrubTo(step) => self.runner.scrub_to(step),
            C::Fit => self.view.fit(),
            C::SetTool(tool) => {
                if !tool_fits(tool, self.selection.as_ref()) {
                    return self.complain(match tool {
                        tools::Tool::Joint => "the joint tool works in a robot".into(),
                        _ => "the drawing tools draw into a scene or a robot".into(),
                    });
                }
                self.view.tool = tool;
                if tool != tools::Tool::Select {
                    self.stop_at_start();
                }
            }
            C::SetSnap(step) => self.view.snap_step = step,
            C::SetShapeOptions(options) => self.view.shape = options,
            C::SetDebug(debug) => self.view.debug = debug,
            C::Follow(body) => self.follow(body),
            C::ToggleProblems => self.show_problems = !self.show_problems,
            // F1 (or the menu) opens the sheet and closes it again.
            C::ShowShortcuts => self.show_shortcuts = !self.show_shortcuts,
            C::ShowAbout => self.show_about = true,
            C::ShowGuide => self.show_guide = true,
            C::Inform(text) => self.inform(text),
            C::Complain(text) => self.complain(text),
            edit => self.apply_edit(edit, now),
        }
    }

    fn run_note(&mut self, note: Option<runner::RunNote>) {
        let Some(note) = note else {
            return;
        };
        if let Some(area) = note.scene_to_show {
            // Nothing left to watch: bring the scene back into view.
            self.view.fitted = false;
            self.view.fit_area = Some(area);
        }
        self.inform(note.text);
    }

    /// Back to step 0, paused: where the canvas edits placements and joints.
    fn stop_at_start(&mut self) {
        self.runner.running = false;
        if self.sim().is_some_and(|s| s.step_count() > 0) {
            self.runner.reset(self.followed);
        }
    }

    fn action(&mut self, action: shortcuts::Action) -> Option<Command> {
        use shortcuts::Action as A;
        Some(match action {
            A::Save => Command::Save,
            A::SaveAs => Command::SaveAs,
            A::Open => Command::AskOpen,
            A::Undo => Command::Undo,
            A::Redo => Command::Redo,
            A::Cut => Command::CutPlacement,
            A::Copy => Command::CopyPlacement,
            A::Paste => Command::PastePlacement,
            A::Duplicate => Command::Duplicate,
            A::Delete => Command::DeleteSelected,
            A::PlayPause => Command::TogglePlay,
            A::Step => Command::Step,
            A::Reset => Command::Reset,
            A::Fit => Command::Fit,
            A::ShowShortcuts => Command::ShowShortcuts,
            A::SelectTool => Command::SetTool(tools::Tool::Select),
            A::BoxTool => Command::SetTool(tools::Tool::Box),
            A::PolygonTool => Command::SetTool(tools::Tool::Polygon),
            A::RotateLeft | A::RotateRight => {
                let i = self.followed.filter(|_| self.runner.editing())?;
                let turn = if action == A::RotateRight { 1.0 } else { -1.0 };
                Command::TurnPlacement {
                    body: i,
                    angle: turn * 15f64.to_radians(),
                }
            }
            A::Left | A::Right if self.runner.editing() => {
                let step = if action == A::Right { 1.0 } else { -1.0 };
                Command::Nudge(pe::Vec2::new(step * self.nudge_step(), 0.0))
            }
            A::Up | A::Down if self.runner.editing() => {
                // y points down, as on screen: Up moves to smaller y.
                let step = if action == A::Down { 1.0 } else { -1.0 };
                Command::Nudge(pe::Vec2::new(0.0, step * self.nudge_step()))
            }
            A::Left | A::Right => return None,
            A::Up | A::Down => {
                if !self.runner.running {
                    return None;
                }
                self.runner
                    .change_throttle(if action == A::Up { 1 } else { -1 });
                Command::Inform(format!(
                    "joint motors at {}× their speed (Up / Down change it, R resets)",
                    self.runner.throttle()
                ))
            }
        })
    }

    /// How far an arrow key moves the selection: one grid step, or one unit unsnapped.
    fn nudge_step(&self) -> f64 {
        self.view.snap_step.unwrap_or(1.0)
    }

    fn bar_state(&self) -> toolbar::State<'_> {
        toolbar::State {
            dirty: self.doc.is_dirty(),
            has_folder: self.doc.folder().is_some(),
            can_undo: self.doc.can_undo(),
            can_redo: self.doc.can_redo(),
            running: self.runner.running,
            speed: self.runner.speed,
            solver: self.runner.solver,
            sleeping: self.runner.sleeping,
            selection: self.selection.as_ref(),
            placement_selected: self.followed.is_some() && self.runner.editing(),
            can_paste: self.copied.is_some(),
            tool: self.view.tool,
            snap_step: self.view.snap_step,
            shape: self.view.shape,
            debug: self.view.debug,
        }
    }

    /// The panels, each returning what it asks for.
    fn panels(&mut self, ui: &mut egui::Ui) -> Vec<Command> {
        let mut commands = Vec::new();
        let mut toolbar = std::mem::take(&mut self.toolbar);
        let state = self.bar_state();
        egui::Panel::top("menu").show(ui, |ui| commands.extend(toolbar.menu_bar(ui, state)));
        egui::Panel::top("toolbar").show(ui, |ui| commands.extend(toolbar.toolbar(ui, state)));
        self.toolbar = toolbar;
        egui::Panel::bottom("status").show(ui, |ui| {
            commands.extend(status::ui(
                ui,
                status::Status {
                    problems: self.doc.problems(),
                    message: &self.message,
                    sim: self.runner.sim(),
                    solver: self.runner.solver,
                    history: self.runner.history(),
                },
            ));
        });
        // A body on its own has nothing to plot: its editor gets the room.
        if !matches!(self.selection, Some(Selection::Body(_))) {
            egui::Panel::bottom("plots")
                .resizable(true)
                .default_size(200.0)
                .show(ui, |ui| {
                    let body = self
                        .followed
                        .and_then(|i| self.runner.sim()?.bodies.get(i))
                        .map(|b| b.id.clone());
                    if let Some(plots::PlotsCommand::ExportCsv) =
                        self.plots.ui(ui, &self.runner.plot_data, body.as_deref())
                    {
                        commands.push(Command::Export(command::Export::Plots));
                    }
                });
        }
        egui::Panel::left("browser")
            .resizable(true)
            .default_size(230.0)
            .show(ui, |ui| {
                commands.extend(browser::ui(ui, self.doc.model(), self.selection.as_ref()));
            });
        egui::Panel::right("inspector")
            .resizable(true)
            .default_size(280.0)
            .show(ui, |ui| {
                let running = inspector::Running {
                    sim: self.runner.sim(),
                    followed: self.followed,
                    items_picked: self.picked_owners().len(),
                };
                let model = self.doc.model();
                commands.extend(
                    self.inspector
                        .ui(ui, model, self.selection.as_ref(), running),
                );
            });
        egui::CentralPanel::default().show(ui, |ui| commands.extend(self.central(ui)));
        commands
    }

    fn central(&mut self, ui: &mut egui::Ui) -> Vec<Command> {
        if let Some(Selection::Body(name)) = &self.selection {
            let vertices = self
                .doc
                .model()
                .body(name)
                .map(|b| b.vertices.clone())
                .unwrap_or_default();
            return self.view.body_ui(ui, &vertices);
        }
        let editing = self.runner.editing();
        let parts = self.runner.canvas_parts();
        let Some(sim) = parts.sim else {
            self.view.nothing(ui, "nothing to show");
            return Vec::new();
        };
        let scene = canvas::Scene {
            sim,
            editing,
            followed: self.followed,
            picked: &self.picked,
            overlaps: parts.overlaps,
            bound: parts.bound,
        };
        self.view.scene_ui(ui, scene, parts.grab)
    }

    fn windows(&mut self, ctx: &egui::Context) -> Vec<Command> {
        let mut commands = Vec::new();
        if let Some(dialog) = self.dialog.clone()
            && let Some(answer) = dialogs::ui(ctx, &dialog)
        {
            if self.dialog.as_ref() == Some(&dialog) {
                self.dialog = None;
            }
            commands.extend(answer);
        }
        if let Some(chooser) = &mut self.in_app_chooser
            && let Some(answer) = chooser.show(ctx)
        {
            self.in_app_chooser = None;
            commands.extend(answer);
        }
        if self.show_problems {
            status::problems_window(ctx, self.doc.problems(), &mut self.show_problems);
        }
        if self.show_shortcuts {
            let motor_keys: Vec<(String, [String; 2])> = self
                .runner
                .sim()
                .map(|sim| {
                    let bound = |j: &crate::sim::SimJoint| {
                        let keys = j.motor.as_ref()?.keys.clone()?;
                        Some((j.id.clone(), keys))
                    };
                    sim.joints.iter().filter_map(bound).collect()
                })
                .unwrap_or_default();
            dialogs::shortcut_sheet(ctx, &mut self.show_shortcuts, &motor_keys);
        }
        if self.show_guide {
            dialogs::user_guide(ctx, &mut self.show_guide, &mut self.guide_markdown);
        }
        if self.show_about {
            dialogs::about(ctx, &mut self.show_about);
        }
        if self.view.debug.islands {
            egui::Window::new("Physics islands")
                .open(&mut self.view.debug.islands)
                .default_pos([980.0, 120.0])
                .show(ctx, |ui| {
                    egui::ScrollArea::vertical()
                        .max_height(360.0)
                        .show(ui, |ui| inspector::islands(ui, self.runner.sim()));
                });
        }
        commands
    }

    /// Sets each key-bound joint motor's drive from the keys held (the first: −1, the
    /// second: +1); returns the keys bound, which shortcuts then leave alone.
    fn drive_motors_by_keys(&mut self, ui: &egui::Ui) -> Vec<egui::Key> {
        let Some(sim) = self.runner.sim_mut() else {
            return Vec::new();
        };
        let mut bound = Vec::new();
        for j in &mut sim.joints {
            let Some([first, second]) = j.motor.as_ref().and_then(|m| m.keys.clone()) else {
                continue;
            };
            let (Some(back), Some(forth)) =
                (egui::Key::from_name(&first), egui::Key::from_name(&second))
            else {
                continue;
            };
            let (back_held, forth_held) = ui.input(|i| (i.key_down(back), i.key_down(forth)));
            j.drive = i8::from(forth_held) - i8::from(back_held);
            bound.extend([back, forth]);
        }
        bound
    }

    /// The unsaved-changes guard on closing the window.
    fn guard_close(&mut self, ctx: &egui::Context) {
        if ctx.input(|i| i.viewport().close_requested())
            && !self.close_confirmed
            && self.doc.is_dirty()
        {
            ctx.send_viewport_cmd(egui::ViewportCommand::CancelClose);
            self.dialog = Some(Dialog::Unsaved(AfterSave::Quit));
        }
    }
}

/// Whether `tool` works on what `selection` shows: joints in robots, drawing in scenes
/// and robots.
fn tool_fits(tool: tools::Tool, selection: Option<&Selection>) -> bool {
    match tool {
        tools::Tool::Select => true,
        tools::Tool::Joint => matches!(selection, Some(Selection::Robot(_))),
        tools::Tool::Box | tools::Tool::Polygon => {
            matches!(selection, Some(Selection::Robot(_) | Selection::Scene(_)))
        }
    }
}

impl eframe::App for RoboSimApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        let typing = ctx.text_edit_focused();
        let (frame_seconds, now) = ui.input(|i| (i.stable_dt as f64, i.time));
        let tool_on = self.view.tool != tools::Tool::Select;
        self.pasted = (!typing)
            .then(|| {
                ui.input(|i| {
                    i.events.iter().find_map(|e| match e {
                        egui::Event::Paste(text) => Some(text.clone()),
                        _ => None,
                    })
                })
            })
            .flatten();
        // While a scene runs, the keys its motors are bound to drive them, not shortcuts.
        let motor_keys = if self.runner.running && !typing {
            self.drive_motors_by_keys(ui)
        } else {
            Vec::new()
        };
        let actions = ui.input_mut(|i| shortcuts::pressed(i, typing, tool_on, &motor_keys));
        for action in actions {
            if let Some(command) = self.action(action) {
                self.apply(command, &ctx, now);
            }
        }
        self.guard_close(&ctx);
        let note = self.runner.advance(frame_seconds, self.followed);
        self.run_note(note);
        self.autosave_tick(&ctx, now);
        self.export_news();
        // A PNG export asked for last frame is drawn in this one, then taken.
        let png_frame = self.view.png_pending.is_some();
        let mut commands = self.panels(ui);
        commands.extend(self.windows(&ctx));
        for command in commands {
            self.apply(command, &ctx, now);
        }
        if let Some(text) = self.clipboard_out.take() {
            ctx.copy_text(text);
        }
        if png_frame {
            self.take_png(&ctx);
        }
        if self.runner.running || self.runner.grab.is_some() {
            ctx.request_repaint();
        }
    }

    fn save(&mut self, storage: &mut dyn eframe::Storage) {
        self.keep_unsaved_work();
        eframe::set_value(storage, RECENT_KEY, &self.toolbar.recent);
    }
}
