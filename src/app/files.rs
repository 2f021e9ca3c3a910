//! Asking the user for a folder or a file name. The system's dialog (rfd) may be missing
//! (no desktop portal, no zenity): then the app asks in a chooser of its own, drawn in its
//! window (egui_file), and carries on when that is answered. Tests answer with a script.

use super::command::{AfterSave, Command, Export};
use std::collections::VecDeque;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// How a question for a path ended.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Answer {
    Chosen(PathBuf),
    Cancelled,
    /// No dialog could be shown.
    Unavailable,
}

/// What the app asks for paths through.
pub trait FileChooser {
    fn folder(&mut self, title: &str, start: Option<&Path>) -> Answer;
    /// A file to write, `extension` without its dot.
    fn new_file(
        &mut self,
        title: &str,
        name: &str,
        extension: &str,
        start: Option<&Path>,
    ) -> Answer;
}

/// The desktop's own dialogs.
#[derive(Debug, Default)]
pub struct SystemDialogs;

/// A dialog that comes back empty sooner than this never opened: nobody cancels that fast.
const NO_DIALOG: Duration = Duration::from_millis(400);

fn answer(picked: Option<PathBuf>, asked: Instant) -> Answer {
    match picked {
        Some(path) => Answer::Chosen(path),
        None if asked.elapsed() < NO_DIALOG => Answer::Unavailable,
        None => Answer::Cancelled,
    }
}

impl FileChooser for SystemDialogs {
    fn folder(&mut self, title: &str, start: Option<&Path>) -> Answer {
        let mut dialog = rfd::FileDialog::new().set_title(title);
        if let Some(start) = start {
            dialog = dialog.set_directory(start);
        }
        let asked = Instant::now();
        answer(dialog.pick_folder(), asked)
    }

    fn new_file(
        &mut self,
        title: &str,
        name: &str,
        extension: &str,
        start: Option<&Path>,
    ) -> Answer {
        let mut dialog = rfd::FileDialog::new()
            .set_title(title)
            .set_file_name(name)
            .add_filter(extension, &[extension]);
        if let Some(start) = start {
            dialog = dialog.set_directory(start);
        }
        let asked = Instant::now();
        answer(dialog.save_file(), asked)
    }
}

/// Answers given in advance, in order (then `Cancelled`): for tests.
#[derive(Debug, Default)]
pub struct Scripted(pub VecDeque<Answer>);

impl Scripted {
    pub fn new(answers: impl IntoIterator<Item = Answer>) -> Self {
        Self(answers.into_iter().collect())
    }
}

impl FileChooser for Scripted {
    fn folder(&mut self, _: &str, _: Option<&Path>) -> Answer {
        self.0.pop_front().unwrap_or(Answer::Cancelled)
    }

    fn new_file(&mut self, _: &str, _: &str, _: &str, _: Option<&Path>) -> Answer {
        self.0.pop_front().unwrap_or(Answer::Cancelled)
    }
}

/// What a path chosen in the app's own chooser is for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PathFor {
    OpenDatabase,
    SaveDatabase,
    Export(Export),
}

impl PathFor {
    /// The command that carries on with `path`.
    fn command(self, path: PathBuf) -> Command {
        match self {
            PathFor::OpenDatabase => Command::Open(AfterSave::Open(path)),
            PathFor::SaveDatabase => Command::SaveIn(path),
            PathFor::Export(export) => Command::ExportTo(export, path),
        }
    }
}

/// The app's own file chooser, shown where the system has no dialog: a window listing
/// folders, with a path field, a parent-folder button and a new-folder button.
pub struct InAppChooser {
    dialog: egui_file::FileDialog,
    purpose: PathFor,
}

impl std::fmt::Debug for InAppChooser {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("InAppChooser")
            .field("purpose", &self.purpose)
            .field("directory", &self.dialog.directory())
            .finish()
    }
}

impl InAppChooser {
    /// Asks for a folder, starting in `start` (or the working folder).
    pub fn folder(title: &str, start: Option<&Path>, purpose: PathFor) -> Self {
        let dialog = egui_file::FileDialog::select_folder()
            .open_button_text("Choose this folder".into())
            .file_label_text("New folder:".into())
            .default_filename("new database");
        Self::opened(dialog, title, start, purpose)
    }

    /// Asks for the file to write `export` to, offering `name`; lists only files of its
    /// kind.
    pub fn export_file(title: &str, name: &str, start: Option<&Path>, export: Export) -> Self {
        let suffix = format!(".{}", export.extension());
        let dialog = egui_file::FileDialog::save_file()
            .save_button_text("Export".into())
            .default_filename(name)
            .show_files_filter(Box::new(move |path: &Path| {
                path.to_string_lossy().ends_with(suffix.as_str())
            }));
        Self::opened(dialog, title, start, PathFor::Export(export))
    }

    fn opened(
        dialog: egui_file::FileDialog,
        title: &str,
        start: Option<&Path>,
        purpose: PathFor,
    ) -> Self {
        let start = start
            .map(Path::to_path_buf)
            .or_else(|| std::env::current_dir().ok())
            .unwrap_or_default();
        let mut dialog = dialog
            .title(title)
            .initial_path(start)
            .show_rename(false)
            .keep_on_top(true);
        dialog.open();
        Self { dialog, purpose }
    }

    /// Draws the chooser. None while it is open; once answered, the command that carries
    /// on (Some(None) when the user cancelled).
    pub fn show(&mut self, ctx: &egui::Context) -> Option<Option<Command>> {
        self.dialog.show(ctx);
        match self.dialog.state() {
            egui_file::State::Open => None,
            egui_file::State::Selected => Some(
                self.dialog
                    .path()
                    .map(|path| self.purpose.command(path.to_path_buf())),
            ),
            egui_file::State::Cancelled | egui_file::State::Closed => Some(None),
        }
    }
}
