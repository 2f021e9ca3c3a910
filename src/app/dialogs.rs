//! Questions the app asks before doing something that cannot be undone, and the help
//! windows (the shortcut sheet, About). Answers come back as commands.

use super::Command;
use super::command::AfterSave;
use super::shortcuts::SHORTCUTS;
use crate::db::Delete;
use crate::model::Model;
use std::path::PathBuf;

#[derive(Debug, Clone, PartialEq)]
pub enum Dialog {
    /// Saving would overwrite a file changed on disk or drop unreadable records.
    Overwrite(String),
    /// Some body cannot be simulated as it is; what that means, before saving it.
    SaveUnusable(String),
    /// The folder the app was started on does not exist.
    MissingFolder(PathBuf),
    /// Unsaved changes, and the user is leaving this database.
    Unsaved(AfterSave),
    /// A delete refused because the item is used; offer the cascade.
    Cascade(String),
    /// Unsaved work from a session that did not end cleanly was found for the database in
    /// this folder.
    Restore(Option<PathBuf>, Model),
    /// An edit (the model it makes, and its undo key) that a running scene cannot take
    /// up as it runs: it starts the run again at step 0.
    RestartForEdit(Box<Model>, String),
}

/// Shows `dialog`; once a button answers it, the commands that answer gives.
pub fn ui(ctx: &egui::Context, dialog: &Dialog) -> Option<Vec<Command>> {
    let mut answered = None;
    egui::Window::new("RoboSim")
        .collapsible(false)
        .resizable(false)
        .anchor(egui::Align2::CENTER_CENTER, [0.0, 0.0])
        .show(ctx, |ui| {
            ui.set_max_width(520.0);
            let (question, answers) = question(dialog);
            ui.label(question);
            ui.horizontal(|ui| {
                for (text, tip, commands) in answers {
                    let button = ui.button(text);
                    let button = if tip.is_empty() {
                        button
                    } else {
                        button.on_hover_text(tip)
                    };
                    if button.clicked() {
                        answered = Some(commands);
                    }
                }
            });
        });
    answered
}

type Answer = (&'static str, &'static str, Vec<Command>);

/// The text of `dialog` and its buttons: label, tooltip, what each does.
fn question(dialog: &Dialog) -> (String, Vec<Answer>) {
    let cancel = ("Cancel", "", Vec::new());
    match dialog {
        Dialog::Overwrite(why) => (
            why.clone(),
            vec![("Overwrite", "", vec![Command::SaveOverwriting]), cancel],
        ),
        Dialog::SaveUnusable(why) => (
            why.clone(),
            vec![("Save anyway", "", vec![Command::SaveAnyway]), cancel],
        ),
        Dialog::MissingFolder(folder) => (
            format!("The folder {} does not exist.", folder.display()),
            vec![
                (
                    "Start a new database there",
                    "An empty database; the first Save creates the folder",
                    Vec::new(),
                ),
                (
                    "Open the examples instead",
                    "The database built into the app",
                    vec![Command::Open(AfterSave::OpenExamples)],
                ),
                ("Choose another folder…", "", vec![Command::AskOpen]),
            ],
        ),
        Dialog::Unsaved(after) => (
            "The database has unsaved changes.".to_string(),
            vec![
                ("Save", "", vec![Command::SaveThen(after.clone())]),
                ("Discard", "", vec![Command::Discard(after.clone())]),
                cancel,
            ],
        ),
        Dialog::Cascade(why) => (
            why.clone(),
            vec![
                (
                    "Delete it and its placements",
                    "",
                    vec![Command::Delete(Delete::Cascade)],
                ),
                cancel,
            ],
        ),
        Dialog::RestartForEdit(draft, key) => (
            "This edit starts the run again at step 0 (gravity, friction, the step and joint \
             motors change as it runs; other edits do not). Make it?"
                .to_string(),
            vec![
                (
                    "Edit and restart",
                    "",
                    vec![Command::CommitRestarting(draft.clone(), key.clone())],
                ),
                cancel,
            ],
        ),
        Dialog::Restore(folder, model) => (
            "Unsaved work from a session that ended unexpectedly was kept. Restore it?".to_string(),
            vec![
                (
                    "Restore",
                    "",
                    vec![Command::Restore(folder.clone(), model.clone())],
                ),
                (
                    "Discard it",
                    "",
                    vec![Command::DiscardKeptWork(folder.clone())],
                ),
            ],
        ),
    }
}

/// The shortcut sheet: every shortcut of `shortcuts::SHORTCUTS`, and the mouse.
/// Every shortcut, the mouse's gestures, and the keys the shown scene's motors are bound
/// to (`motor_keys`: each motor's name and its two keys).
pub fn shortcut_sheet(ctx: &egui::Context, open: &mut bool, motor_keys: &[(String, [String; 2])]) {
    if ctx.input(|i| i.key_pressed(egui::Key::Escape)) {
        *open = false;
        return;
    }
    egui::Window::new("Keyboard shortcuts")
        .open(open)
        .resizable(false)
        .show(ctx, |ui| {
            egui::Grid::new("shortcut sheet")
                .striped(true)
                .show(ui, |ui| {
                    for (_, shortcut, what) in SHORTCUTS {
                        ui.monospace(ctx.format_shortcut(shortcut));
                        ui.label(*what);
                        ui.end_row();
                    }
                    for (how, what) in [
                        (
                            "Left drag",
                            "Move a body at step 0; pull it on a spring while running",
                        ),
                        (
                            "Handle drag",
                            "Turn the selected placement (Shift: 15° steps)",
                        ),
                        ("Right or middle drag", "Pan the view"),
                        ("Wheel", "Zoom about the pointer"),
                        (
                            "Shift+click",
                            "Body editor: add a vertex even if it dents the outline",
                        ),
                    ] {
                        ui.monospace(how);
                        ui.label(what);
                        ui.end_row();
                    }
                    for (motor, [back, forth]) in motor_keys {
                        ui.monospace(format!("{back} / {forth}"));
                        ui.label(format!("While running: hold to drive {motor} back / forth"));
                        ui.end_row();
                    }
                });
        });
}

/// docs/user-guide.md in a window, its Markdown drawn (headings, lists, tables, links);
/// its screenshots left out (the window shows the app itself).
pub fn user_guide(
    ctx: &egui::Context,
    open: &mut bool,
    cache: &mut egui_commonmark::CommonMarkCache,
) {
    if ctx.input(|i| i.key_pressed(egui::Key::Escape)) {
        *open = false;
        return;
    }
    static GUIDE: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    let guide = GUIDE.get_or_init(|| {
        // Arrows as the default fonts can draw them.
        let arrows = [("←", "<-"), ("→", "->"), ("↑", "up"), ("↓", "down")];
        include_str!("../../docs/user-guide.md")
            .lines()
            .filter(|l| !l.starts_with("!["))
            .map(|l| {
                arrows
                    .iter()
                    .fold(l.to_string(), |l, (from, to)| l.replace(from, to))
            })
            .collect::<Vec<_>>()
            .join("\n")
    });
    egui::Window::new("User guide")
        .open(open)
        .default_size([640.0, 520.0])
        .show(ctx, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| {
                egui_commonmark::CommonMarkViewer::new().show(ui, cache, guide);
            });
        });
}

pub fn about(ctx: &egui::Context, open: &mut bool) {
    egui::Window::new("About RoboSim")
        .open(open)
        .resizable(false)
        .show(ctx, |ui| {
            ui.heading(format!("RoboSim {}", env!("CARGO_PKG_VERSION")));
            ui.label(env!("CARGO_PKG_DESCRIPTION"));
            ui.label(format!("Licence: {}", env!("CARGO_PKG_LICENSE")));
        });
}
