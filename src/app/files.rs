//! Asking the user for a folder or a file name. The system's dialog (rfd) may be missing
//! (no desktop portal, no zenity): then the app says so and offers its path field. Tests
//! answer with a script instead.

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
