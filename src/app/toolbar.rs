//! The menu bar and the toolbar under it: files, edits, the simulation's clock and
//! solver, tools, snapping and what the canvas draws. Every entry has a tooltip and, where
//! it has one, shows its shortcut.

use super::canvas::DebugDraw;
use super::command::{AfterSave, Export, ImageFormat};
use super::runner::SPEEDS;
use super::shortcuts::{self, Action};
use super::tools::{self, Tool};
use super::{Command, Selection};
use pe::ContactSolver;
use std::path::PathBuf;

/// What the bars show, read from the app each frame.
#[derive(Debug, Clone, Copy)]
pub struct State<'a> {
    pub dirty: bool,
    pub has_folder: bool,
    pub can_undo: bool,
    pub can_redo: bool,
    pub running: bool,
    pub speed: f64,
    pub solver: ContactSolver,
    pub sleeping: bool,
    pub selection: Option<&'a Selection>,
    /// A placement is selected on the canvas at step 0 (it can be copied or cut).
    pub placement_selected: bool,
    pub can_paste: bool,
    pub tool: Tool,
    pub snap_step: Option<f64>,
    pub shape: tools::ShapeOptions,
    pub debug: DebugDraw,
}

/// The toolbar's own state: the folder being typed, and the recent folders.
#[derive(Debug, Default)]
pub struct Toolbar {
    pub path_input: String,
    pub recent: Vec<String>,
}

/// A menu entry that shows the shortcut of `action` and returns whether it was clicked.
fn entry(ui: &mut egui::Ui, enabled: bool, text: &str, action: Option<Action>, tip: &str) -> bool {
    let mut button = egui::Button::new(text);
    if let Some(shortcut) = action.and_then(shortcuts::of) {
        button = button.shortcut_text(ui.ctx().format_shortcut(&shortcut));
    }
    ui.add_enabled(enabled, button).on_hover_text(tip).clicked()
}

impl Toolbar {
    /// Remembers `folder` first among the recent folders.
    pub fn opened(&mut self, folder: Option<&std::path::Path>) {
        let Some(folder) = folder else {
            self.path_input.clear();
            return;
        };
        let label = folder.display().to_string();
        self.recent.retain(|r| r != &label);
        self.recent.insert(0, label.clone());
        self.recent.truncate(8);
        self.path_input = label;
    }

    pub fn menu_bar(&mut self, ui: &mut egui::Ui, s: State<'_>) -> Vec<Command> {
        let mut out = Vec::new();
        egui::MenuBar::new().ui(ui, |ui| {
            ui.menu_button("File", |ui| self.file_menu(ui, s, &mut out));
            ui.menu_button("Edit", |ui| edit_menu(ui, s, &mut out));
            ui.menu_button("View", |ui| view_menu(ui, s, &mut out));
            ui.menu_button("Tools", |ui| tools_menu(ui, s, &mut out));
            ui.menu_button("Help", |ui| {
                if entry(
                    ui,
                    true,
                    "Keyboard shortcuts",
                    Some(Action::ShowShortcuts),
                    "Every shortcut",
                ) {
                    out.push(Command::ShowShortcuts);
                }
                if entry(
                    ui,
                    true,
                    "User guide",
                    None,
                    "How to draw, build, run and share",
                ) {
                    out.push(Command::ShowGuide);
                }
                if entry(ui, true, "About RoboSim", None, "Version and licence") {
                    out.push(Command::ShowAbout);
                }
            });
        });
        out
    }

    fn file_menu(&mut self, ui: &mut egui::Ui, s: State<'_>, out: &mut Vec<Command>) {
        if entry(
            ui,
            true,
            "New database",
            None,
            "An empty database, saved where you choose",
        ) {
            out.push(Command::NewDatabase);
        }
        if entry(
            ui,
            true,
            "Open…",
            Some(Action::Open),
            "Open a database folder",
        ) {
            out.push(Command::AskOpen);
        }
        if entry(
            ui,
            true,
            "Open the examples",
            None,
            "The database built into the app",
        ) {
            out.push(Command::Open(AfterSave::OpenExamples));
        }
        ui.add_enabled_ui(!self.recent.is_empty(), |ui| {
            ui.menu_button("Recent", |ui| {
                for r in &self.recent {
                    if ui.button(r).clicked() {
                        out.push(Command::Open(AfterSave::Open(PathBuf::from(r))));
                    }
                }
            });
        });
        ui.separator();
        if entry(
            ui,
            s.dirty || !s.has_folder,
            "Save",
            Some(Action::Save),
            "Save every file atomically",
        ) {
            out.push(Command::Save);
        }
        if entry(
            ui,
            true,
            "Save As…",
            Some(Action::SaveAs),
            "Save the database in another folder",
        ) {
            out.push(Command::SaveAs);
        }
        if entry(
            ui,
            s.has_folder && s.dirty,
            "Revert",
            None,
            "Read the files again, dropping unsaved edits (undoable)",
        ) {
            out.push(Command::Revert);
        }
        ui.separator();
        if entry(
            ui,
            true,
            "Export plots as CSV…",
            None,
            "Every plotted series, one row per step",
        ) {
            out.push(Command::Export(Export::Plots));
        }
        if entry(
            ui,
            true,
            "Export view as SVG…",
            None,
            "The canvas as a vector drawing",
        ) {
            out.push(Command::Export(Export::View(ImageFormat::Svg)));
        }
        if entry(
            ui,
            true,
            "Export view as PNG…",
            None,
            "The canvas as a picture",
        ) {
            out.push(Command::Export(Export::View(ImageFormat::Png)));
        }
        if entry(
            ui,
            true,
            "Export run as GIF…",
            None,
            "The run from step 0 to the step shown (the first 10 s at step 0) as an animated GIF, 640 × 480, to share",
        ) {
            out.push(Command::Export(Export::Gif));
        }
        ui.separator();
        if entry(
            ui,
            true,
            "Quit",
            None,
            "Close RoboSim (asks about unsaved changes)",
        ) {
            out.push(Command::Quit);
        }
    }

    pub fn toolbar(&mut self, ui: &mut egui::Ui, s: State<'_>) -> Vec<Command> {
        let mut out = Vec::new();
        ui.horizontal_wrapped(|ui| {
            self.files(ui, s, &mut out);
            ui.separator();
            clock(ui, s, &mut out);
            ui.separator();
            tools_and_view(ui, s, &mut out);
        });
        out
    }

    fn files(&mut self, ui: &mut egui::Ui, s: State<'_>, out: &mut Vec<Command>) {
        if ui
            .button("Open…")
            .on_hover_text("Open a database folder (bodies.xml, robots.xml, scenes.xml) (Ctrl+O)")
            .clicked()
        {
            out.push(Command::AskOpen);
        }
        let label = ui.label("folder");
        let typed = ui
            .add(
                egui::TextEdit::singleline(&mut self.path_input)
                    .hint_text("database folder")
                    .desired_width(100.0),
            )
            .labelled_by(label.id)
            .on_hover_text("Type a database folder and press Enter to open it");
        if typed.lost_focus()
            && ui.input(|i| i.key_pressed(egui::Key::Enter))
            && !self.path_input.trim().is_empty()
        {
            let folder = PathBuf::from(self.path_input.trim());
            out.push(Command::Open(AfterSave::Open(folder)));
        }
        ui.separator();
        let save = egui::Button::new(if s.dirty { "Save*" } else { "Save" });
        if ui
            .add_enabled(s.dirty || !s.has_folder, save)
            .on_hover_text("Save the database, each file atomically (Ctrl+S)")
            .clicked()
        {
            out.push(Command::Save);
        }
        for (enabled, text, tip, command) in [
            (
                s.can_undo,
                "Undo",
                "Undo the last edit (Ctrl+Z)",
                Command::Undo,
            ),
            (
                s.can_redo,
                "Redo",
                "Redo (Ctrl+Shift+Z or Ctrl+Y)",
                Command::Redo,
            ),
        ] {
            if ui
                .add_enabled(enabled, egui::Button::new(text))
                .on_hover_text(tip)
                .clicked()
            {
                out.push(command);
            }
        }
    }
}

fn edit_menu(ui: &mut egui::Ui, s: State<'_>, out: &mut Vec<Command>) {
    let items = [
        (
            s.can_undo,
            "Undo",
            Action::Undo,
            "Undo the last edit",
            Command::Undo,
        ),
        (
            s.can_redo,
            "Redo",
            Action::Redo,
            "Redo the last undone edit",
            Command::Redo,
        ),
        (
            s.placement_selected,
            "Cut",
            Action::Cut,
            "Remove the selected placements, keeping a copy",
            Command::CutPlacement,
        ),
        (
            s.placement_selected,
            "Copy",
            Action::Copy,
            "Copy the selected placements",
            Command::CopyPlacement,
        ),
        (
            s.can_paste,
            "Paste",
            Action::Paste,
            "Paste the copied placements in free space at the view's centre",
            Command::PastePlacement,
        ),
        (
            s.selection.is_some(),
            "Duplicate",
            Action::Duplicate,
            "Copy the selected placements beside them (at step 0), or else the selected item under a new name",
            Command::Duplicate,
        ),
    ];
    for (enabled, text, action, tip, command) in items {
        if entry(ui, enabled, text, Some(action), tip) {
            out.push(command);
        }
    }
    if entry(
        ui,
        s.selection.is_some(),
        "Delete",
        Some(Action::Delete),
        "Delete the selected placements, or else the selected item (refused while it is used)",
    ) {
        out.push(Command::DeleteSelected);
    }
}

fn view_menu(ui: &mut egui::Ui, s: State<'_>, out: &mut Vec<Command>) {
    if entry(
        ui,
        true,
        "Fit to view",
        Some(Action::Fit),
        "Frame the scene, the robot or the body",
    ) {
        out.push(Command::Fit);
    }
    let mut debug = s.debug;
    ui.checkbox(&mut debug.grid, "Grid");
    ui.checkbox(&mut debug.follow, "Follow the moving bodies");
    ui.separator();
    debug_checkboxes(ui, &mut debug);
    if debug != s.debug {
        out.push(Command::SetDebug(debug));
    }
}

/// The polygon's sides and the terrain box, beside the drawing tools.
fn shape_options(ui: &mut egui::Ui, s: State<'_>, out: &mut Vec<Command>) {
    let mut options = s.shape;
    if s.tool == Tool::Polygon {
        let label = ui.label("sides");
        ui.add(egui::DragValue::new(&mut options.sides).range(tools::POLYGON_SIDES))
            .labelled_by(label.id)
            .on_hover_text("The polygon tool's number of sides");
    }
    if matches!(s.selection, Some(Selection::Scene(_))) {
        ui.checkbox(&mut options.terrain, "static")
            .on_hover_text("Draw static terrain (density 0) instead of a moving body (density 1)");
    }
    if options != s.shape {
        out.push(Command::SetShapeOptions(options));
    }
}

fn debug_checkboxes(ui: &mut egui::Ui, debug: &mut DebugDraw) {
    ui.checkbox(&mut debug.contacts, "Contact points and normals");
    ui.checkbox(&mut debug.joints, "Joint anchors and gaps");
    ui.checkbox(&mut debug.bounds, "Bounding boxes");
    ui.checkbox(&mut debug.centres, "Centres of mass");
    ui.checkbox(&mut debug.velocities, "Velocities");
    ui.checkbox(&mut debug.sleeping, "Sleeping bodies (faded, \"z\")");
    ui.checkbox(&mut debug.islands, "Physics islands")
        .on_hover_text("How the last step solved each group of touching or pinned bodies");
}

/// Play, step, reset, speed, solver and sleeping.
fn clock(ui: &mut egui::Ui, s: State<'_>, out: &mut Vec<Command>) {
    let label = if s.running { "Pause" } else { "Play" };
    let buttons = [
        (
            label,
            "Start or stop the simulation (Space)",
            Command::TogglePlay,
        ),
        ("Step", "Advance one physics step (S)", Command::Step),
        (
            "Reset",
            "Back to step 0, with the view fitted (R)",
            Command::Reset,
        ),
        ("Fit", "Fit the view to the scene (F)", Command::Fit),
    ];
    for (text, tip, command) in buttons {
        if ui.button(text).on_hover_text(tip).clicked() {
            out.push(command);
        }
    }
    let mut speed = s.speed;
    egui::ComboBox::from_id_salt("speed")
        .width(56.0)
        .selected_text(format!("{}×", s.speed))
        .show_ui(ui, |ui| {
            for v in SPEEDS {
                ui.selectable_value(&mut speed, v, format!("{v}×"));
            }
        })
        .response
        .on_hover_text("Slow motion and fast-forward: more or fewer steps per second, the step h never changes");
    if speed != s.speed {
        out.push(Command::SetSpeed(speed));
    }
    let mut solver = s.solver;
    egui::ComboBox::from_id_salt("solver")
        .width(80.0)
        .selected_text(s.solver.name())
        .show_ui(ui, |ui| {
            for v in ContactSolver::ALL {
                ui.selectable_value(&mut solver, v, v.name());
            }
        })
        .response
        .on_hover_text("The contact solver: auto (exact where it is needed, fast elsewhere), exact (coupled LCP), thesis (two-stage LCP as in the thesis), soft (iterative), sequential (one contact at a time)");
    if solver != s.solver {
        out.push(Command::SetSolver(solver));
    }
    let mut sleeping = s.sleeping;
    if ui
        .checkbox(&mut sleeping, "Sleep")
        .on_hover_text("Bodies at rest for half a second sleep and cost nothing until something touches them, a motor on them starts or you drag them")
        .changed()
    {
        out.push(Command::SetSleeping(sleeping));
    }
}

/// A tool as the Tools menu and the toolbar offer it.
struct ToolEntry {
    tool: Tool,
    /// Whether it works on what is shown.
    enabled: bool,
    /// In the menu, and (short) in the toolbar.
    text: &'static str,
    short: &'static str,
    action: Option<Action>,
    tip: &'static str,
}

fn tool_entries(s: State<'_>) -> [ToolEntry; 4] {
    let robot = matches!(s.selection, Some(Selection::Robot(_)));
    let scene_or_robot = robot || matches!(s.selection, Some(Selection::Scene(_)));
    [
        ToolEntry {
            tool: Tool::Select,
            enabled: true,
            text: "Select",
            short: "Select",
            action: Some(Action::SelectTool),
            tip: "Click a body to select it, drag on empty space to select several; drag to move them",
        },
        ToolEntry {
            tool: Tool::Box,
            enabled: scene_or_robot,
            text: "Draw box",
            short: "Box",
            action: Some(Action::BoxTool),
            tip: "Draw a box: drag from corner to corner on the canvas for a new body of that size, placed there (paused at step 0)",
        },
        ToolEntry {
            tool: Tool::Polygon,
            enabled: scene_or_robot,
            text: "Draw polygon",
            short: "Polygon",
            action: Some(Action::PolygonTool),
            tip: "Draw a regular polygon: drag from the centre out for a new body of that radius, placed there (paused at step 0)",
        },
        ToolEntry {
            tool: Tool::Joint,
            enabled: robot,
            text: "Add joint",
            short: "Add joint",
            action: None,
            tip: "Pin two bodies together: click a point where they overlap (paused at step 0)",
        },
    ]
}

fn tools_menu(ui: &mut egui::Ui, s: State<'_>, out: &mut Vec<Command>) {
    for t in tool_entries(s) {
        if entry(ui, t.enabled, t.text, t.action, t.tip) {
            out.push(Command::SetTool(t.tool));
        }
    }
}

/// The tools, the drawing tools' options, snapping and Follow.
fn tools_and_view(ui: &mut egui::Ui, s: State<'_>, out: &mut Vec<Command>) {
    // No Select button, to keep the bar on one line: a tool's button (or Esc) turns it off.
    for t in tool_entries(s) {
        if !t.enabled || t.tool == Tool::Select {
            continue;
        }
        let key = t
            .action
            .and_then(shortcuts::of)
            .map(|k| format!(" ({})", ui.ctx().format_shortcut(&k)))
            .unwrap_or_default();
        let on = s.tool == t.tool;
        if ui
            .selectable_label(on, t.short)
            .on_hover_text(format!("{}{key}; click again to select", t.tip))
            .clicked()
        {
            out.push(Command::SetTool(if on { Tool::Select } else { t.tool }));
        }
    }
    if s.tool.draws() {
        shape_options(ui, s, out);
    }
    let mut snap = s.snap_step;
    egui::ComboBox::from_id_salt("snap")
        .width(72.0)
        .selected_text(match s.snap_step {
            Some(step) => format!("snap {step}"),
            None => "snap off".into(),
        })
        .show_ui(ui, |ui| {
            for step in tools::SNAP_STEPS {
                let label = step.map_or("off".to_string(), |v| v.to_string());
                ui.selectable_value(&mut snap, step, label);
            }
        })
        .response
        .on_hover_text("Grid spacing that vertices, placements and joints snap to");
    if snap != s.snap_step {
        out.push(Command::SetSnap(snap));
    }
    // The debug overlays are in the View menu: the bar keeps to one line at 1280 points.
    let mut debug = s.debug;
    ui.toggle_value(&mut debug.follow, "Follow")
        .on_hover_text("Keep the moving bodies in view (panning turns it off)");
    if debug != s.debug {
        out.push(Command::SetDebug(debug));
    }
}
