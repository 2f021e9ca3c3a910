//! Unsaved work kept on disk between saves, so that a crash or a kill loses seconds, not
//! a session. Each database folder has its own slot, so work on one folder is never
//! offered back when another is opened.

use crate::db::{Database, Overwrite, SaveError};
use crate::model::Model;
use std::path::{Path, PathBuf};

/// Seconds after an edit before it is written out: long enough that a drag or typing is
/// written once, short enough that a kill loses little.
pub const DELAY: f64 = 2.0;

/// The file in a slot naming the database folder it belongs to.
const FOLDER_FILE: &str = "folder.txt";

/// Autosave slots under one folder (eframe's per-user data folder in the app).
#[derive(Debug, Clone, Default)]
pub struct Autosave {
    root: Option<PathBuf>,
    /// When the work now unsaved should be written out (app time, s).
    due: Option<f64>,
}

impl Autosave {
    /// Slots under `root`; `None` keeps nothing.
    pub fn new(root: Option<PathBuf>) -> Self {
        Self { root, due: None }
    }

    /// The slot of the database in `folder` (`None`: a database not yet saved anywhere).
    fn slot(&self, folder: Option<&Path>) -> Option<PathBuf> {
        let root = self.root.as_ref()?;
        Some(root.join(slot_name(folder)))
    }

    /// An edit was made at `now`: write it out `DELAY` seconds later.
    pub fn edited(&mut self, now: f64) {
        self.due = Some(now + DELAY);
    }

    /// Seconds until the pending write, if one is pending (for a repaint timer).
    pub fn seconds_left(&self, now: f64) -> Option<f64> {
        self.due.map(|due| (due - now).max(0.0))
    }

    /// Whether the pending write is due at `now`.
    pub fn is_due(&self, now: f64) -> bool {
        self.due.is_some_and(|due| now >= due)
    }

    /// Writes `db`'s model to its slot if it has unsaved changes, or clears the slot if it
    /// has none.
    pub fn keep(&mut self, db: &Database) -> Result<(), SaveError> {
        self.due = None;
        if !db.is_dirty() {
            self.clear(db.dir.as_deref());
            return Ok(());
        }
        let Some(slot) = self.slot(db.dir.as_deref()) else {
            return Ok(());
        };
        let mut copy = Database::new(db.model.clone());
        copy.save_to(&slot, Overwrite::Confirmed)?;
        let folder = db.dir.as_deref().map_or(String::new(), absolute);
        std::fs::write(slot.join(FOLDER_FILE), folder).map_err(|source| SaveError::Io {
            path: slot.join(FOLDER_FILE),
            source,
        })
    }

    /// Forgets the work kept for `folder`.
    pub fn clear(&mut self, folder: Option<&Path>) {
        self.due = None;
        if let Some(slot) = self.slot(folder) {
            let _ = std::fs::remove_dir_all(slot);
        }
    }

    /// The work kept for `folder`, if any was kept and it differs from `current`.
    pub fn find(&self, folder: Option<&Path>, current: &Model) -> Option<Model> {
        let slot = self.slot(folder).filter(|s| s.is_dir())?;
        let recorded = std::fs::read_to_string(slot.join(FOLDER_FILE)).ok()?;
        let expected = folder.map_or(String::new(), absolute);
        if recorded != expected {
            return None;
        }
        let (kept, _) = Database::load(&slot);
        (kept.model != *current).then_some(kept.model)
    }
}

/// `folder` as an absolute path, so that one folder reached two ways has one slot.
fn absolute(folder: &Path) -> String {
    std::fs::canonicalize(folder)
        .unwrap_or_else(|_| folder.to_path_buf())
        .display()
        .to_string()
}

/// A folder name for `folder`'s slot: a hash of its absolute path (the path itself may be
/// long or hold characters a file name cannot).
fn slot_name(folder: Option<&Path>) -> String {
    let Some(folder) = folder else {
        return "unsaved database".to_string();
    };
    let hash = absolute(folder)
        .bytes()
        .fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
            (h ^ b as u64).wrapping_mul(0x100_0000_01b3)
        });
    format!("{hash:016x}")
}
