//! The database: a directory of three XML files (thesis §4.3) — bodies.xml, robots.xml,
//! scenes.xml — loaded whatever they contain, checked with messages that name file, line
//! and element, and saved atomically without ever overwriting what changed on disk.

mod check;
mod problem;
mod read;
pub mod write;
mod xml;

pub use check::{
    TIMESTEP_RANGE, beyond_all, body_motor_problems, check, joint_limit_problems,
    joint_motor_problems, joint_spring_problems, limits, outline_polygon, polygon,
    scene_number_problems, timestep_problem,
};
pub use problem::{Problem, Severity, one_line};
pub use xml::{MAX_DEPTH, clip};

use crate::model::{Model, same_name};
use crate::paths::resolve_links;
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The default database, embedded so the app runs anywhere (`data/` in the repository).
pub const EMBEDDED: [(FileKind, &str); 3] = [
    (FileKind::Bodies, include_str!("../../data/bodies.xml")),
    (FileKind::Robots, include_str!("../../data/robots.xml")),
    (FileKind::Scenes, include_str!("../../data/scenes.xml")),
];

#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum FileKind {
    Bodies,
    Robots,
    Scenes,
}

impl FileKind {
    pub const ALL: [FileKind; 3] = [FileKind::Bodies, FileKind::Robots, FileKind::Scenes];

    pub fn file_name(self) -> &'static str {
        match self {
            FileKind::Bodies => "bodies.xml",
            FileKind::Robots => "robots.xml",
            FileKind::Scenes => "scenes.xml",
        }
    }

    fn index(self) -> usize {
        self as usize
    }
}

/// What a file held when it was loaded, to notice changes made behind our back.
#[derive(Debug, Clone, PartialEq, Default)]
struct Loaded {
    /// The bytes on disk (None: the file did not exist).
    bytes: Option<Vec<u8>>,
    /// Some record could not be read: saving this file would drop it.
    lossy: bool,
    /// The file is there but could not be read at all (too large, not a regular file, no
    /// permission): it loaded as empty, and is never written over unless the user says so.
    unreadable: bool,
}

#[derive(Debug, Clone, PartialEq, Default)]
pub struct Database {
    /// Where it was loaded from and saves to (None: embedded or new).
    pub dir: Option<PathBuf>,
    pub model: Model,
    loaded: [Loaded; 3],
    /// The model as last loaded or saved: what "unsaved changes" are measured against.
    clean: Model,
    /// Each file's records' text as it is in the file, aligned with `clean`'s records:
    /// a record unchanged since is saved as it was, byte for byte.
    sources: [Vec<Option<Arc<str>>>; 3],
}

#[derive(Debug, thiserror::Error)]
pub enum SaveError {
    #[error("{0} changed on disk since it was loaded; save again with overwrite to replace it")]
    ChangedOnDisk(PathBuf),
    #[error(
        "{0} had records that could not be read; saving would drop them (save with overwrite to accept)"
    )]
    WouldDropRecords(PathBuf),
    #[error("the database has no folder: choose one to save to")]
    NoFolder,
    #[error("cannot write {path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    /// Every file is in place, but the folder could not be synced: a power cut now might
    /// still undo the save.
    #[error("saved, but {path} could not be synced to disk: {source}")]
    NotDurable {
        path: PathBuf,
        source: std::io::Error,
    },
}

/// Whether a save may replace files that changed on disk or lost records on load.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Overwrite {
    /// Refuse (the default: ask the user first).
    Never,
    /// The user confirmed.
    Confirmed,
}

impl Database {
    /// A new database holding `model`, not yet saved anywhere.
    pub fn new(model: Model) -> Self {
        Self {
            model,
            ..Self::default()
        }
    }

    /// Loads `dir`. Never fails: a missing file is an empty collection; a file that cannot
    /// be parsed loads as empty with an error; bad records are skipped with an error.
    /// The problems include [`Database::check`]'s.
    pub fn load(dir: &Path) -> (Self, Vec<Problem>) {
        let mut files = Vec::new();
        let mut problems = Vec::new();
        let mut unreadable = Vec::new();
        for kind in FileKind::ALL {
            let path = dir.join(kind.file_name());
            let bytes = match read_file(&path) {
                Ok(bytes) => Some(bytes),
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => None,
                Err(e) => {
                    problems.push(Problem::error(
                        &path.display().to_string(),
                        "file",
                        format!("cannot read: {e}"),
                    ));
                    unreadable.push(kind);
                    None
                }
            };
            files.push((kind, path.display().to_string(), bytes));
        }
        let mut db = Self::from_files(files, &mut problems);
        for kind in unreadable {
            let loaded = &mut db.loaded[kind.index()];
            loaded.unreadable = true;
            loaded.lossy = true;
        }
        db.dir = Some(dir.to_path_buf());
        problems.extend(db.check());
        (db, problems)
    }

    /// The default database in `data/`, as compiled into the binary.
    pub fn embedded() -> (Self, Vec<Problem>) {
        let files = EMBEDDED
            .iter()
            .map(|(kind, text)| {
                (
                    *kind,
                    format!("data/{}", kind.file_name()),
                    Some(text.as_bytes().to_vec()),
                )
            })
            .collect();
        let mut problems = Vec::new();
        let db = Self::from_files(files, &mut problems);
        problems.extend(db.check());
        (db, problems)
    }

    fn from_files(
        files: Vec<(FileKind, String, Option<Vec<u8>>)>,
        problems: &mut Vec<Problem>,
    ) -> Self {
        let mut db = Database::default();
        for (kind, name, bytes) in files {
            let loaded = &mut db.loaded[kind.index()];
            loaded.bytes = bytes;
            let Some(bytes) = &loaded.bytes else { continue };
            let decoded = match xml::decode(bytes, &name) {
                Ok(decoded) => decoded,
                Err(p) => {
                    problems.push(p);
                    loaded.lossy = true;
                    continue;
                }
            };
            problems.extend(decoded.warning);
            let text = decoded.text;
            let (root, syntax_skipped) = match xml::parse(&text, &name) {
                Ok(parsed) => {
                    problems.extend(parsed.problems);
                    (parsed.root, parsed.skipped)
                }
                Err(file_problems) => {
                    problems.extend(file_problems);
                    loaded.lossy = true;
                    continue;
                }
            };
            let (skipped, spans) = match kind {
                FileKind::Bodies => {
                    let r = read::bodies(&root, &name);
                    db.model.bodies = r.records;
                    problems.extend(r.problems);
                    (r.skipped, r.spans)
                }
                FileKind::Robots => {
                    let r = read::robots(&root, &name);
                    db.model.robots = r.records;
                    problems.extend(r.problems);
                    (r.skipped, r.spans)
                }
                FileKind::Scenes => {
                    let r = read::scenes(&root, &name);
                    db.model.scenes = r.records;
                    problems.extend(r.problems);
                    (r.skipped, r.spans)
                }
            };
            let sources = spans
                .into_iter()
                .map(|span| span.and_then(|r| text.get(r)).map(Arc::from))
                .collect();
            drop(text);
            db.sources[kind.index()] = sources;
            db.loaded[kind.index()].lossy = skipped || syntax_skipped;
        }
        db.clean = db.model.clone();
        db
    }

    /// A file's path as messages show it.
    pub fn file_label(&self, kind: FileKind) -> String {
        match &self.dir {
            Some(dir) => dir.join(kind.file_name()).display().to_string(),
            None => format!("data/{}", kind.file_name()),
        }
    }

    /// Every problem of the model as it is now (ranges, shapes, names, references).
    pub fn check(&self) -> Vec<Problem> {
        check(&self.model, |kind| self.file_label(kind))
    }

    /// The problems of what scene `name` uses: the scenes of that name, the robots they
    /// place and the bodies they and their robots place (every record of each name, so
    /// that a name used twice is still reported). A scene can run whatever is wrong with
    /// the records it does not use.
    pub fn scene_problems(&self, name: &str) -> Vec<Problem> {
        let model = &self.model;
        let scenes: Vec<_> = model
            .scenes
            .iter()
            .filter(|s| same_name(&s.name, name))
            .cloned()
            .collect();
        let placed_robots: std::collections::HashSet<&str> = scenes
            .iter()
            .flat_map(|s| s.robots.iter().map(|r| r.source.trim()))
            .collect();
        let robots: Vec<_> = model
            .robots
            .iter()
            .filter(|r| placed_robots.contains(r.name.trim()))
            .cloned()
            .collect();
        let robot_bodies = robots
            .iter()
            .flat_map(|r| r.bodies.iter().map(|b| b.placement.source.trim()));
        let placed_bodies: std::collections::HashSet<&str> = scenes
            .iter()
            .flat_map(|s| s.bodies.iter().map(|b| b.source.trim()))
            .chain(robot_bodies)
            .collect();
        let bodies = model
            .bodies
            .iter()
            .filter(|b| placed_bodies.contains(b.name.trim()))
            .cloned()
            .collect();
        let used = Model {
            bodies,
            robots,
            scenes,
        };
        check(&used, |kind| self.file_label(kind))
    }

    /// The text each file would have if saved now: each record unchanged since it was
    /// loaded or saved as it is in the file (its numbers as they were written), the
    /// others written anew.
    pub fn render(&self, kind: FileKind) -> String {
        let sources = &self.sources[kind.index()];
        // The record's text if the record is unchanged: the clean record of that name,
        // equal to it, with its text kept.
        fn kept<'a, T: PartialEq>(
            clean: &'a [T],
            sources: &'a [Option<Arc<str>>],
            name: impl Fn(&T) -> &str + 'a,
        ) -> impl Fn(&T) -> Option<Arc<str>> + 'a {
            move |record| {
                let k = clean.iter().position(|c| name(c) == name(record))?;
                (clean[k] == *record).then(|| sources.get(k).cloned().flatten())?
            }
        }
        let clean = &self.clean;
        match kind {
            FileKind::Bodies => write::file(
                "bodies",
                &self.model.bodies,
                kept(&clean.bodies, sources, |b| &b.name),
                write::body,
            ),
            FileKind::Robots => write::file(
                "robots",
                &self.model.robots,
                kept(&clean.robots, sources, |r| &r.name),
                write::robot,
            ),
            FileKind::Scenes => write::file(
                "scenes",
                &self.model.scenes,
                kept(&clean.scenes, sources, |s| &s.name),
                write::scene,
            ),
        }
    }

    /// Whether `kind`'s collection differs from what was loaded or last saved.
    fn collection_changed(&self, kind: FileKind) -> bool {
        match kind {
            FileKind::Bodies => self.model.bodies != self.clean.bodies,
            FileKind::Robots => self.model.robots != self.clean.robots,
            FileKind::Scenes => self.model.scenes != self.clean.scenes,
        }
    }

    /// Saves into `self.dir`, each changed file atomically. Refuses (unless `overwrite`
    /// is confirmed) to replace a file that changed on disk since it was loaded, or one
    /// whose unreadable records would be dropped.
    pub fn save(&mut self, overwrite: Overwrite) -> Result<(), SaveError> {
        let dir = self.dir.clone().ok_or(SaveError::NoFolder)?;
        self.save_with(&dir, overwrite, |_| Ok(()))
    }

    /// Saves into `dir` (save-as: the database moves there).
    pub fn save_to(&mut self, dir: &Path, overwrite: Overwrite) -> Result<(), SaveError> {
        if self.dir.as_deref() != Some(dir) {
            // A new folder: what is there now is what we would overwrite.
            for kind in FileKind::ALL {
                let path = dir.join(kind.file_name());
                self.loaded[kind.index()] = Loaded {
                    bytes: read_file(&path).ok(),
                    ..Loaded::default()
                };
            }
        }
        self.save_with(dir, overwrite, |_| Ok(()))?;
        self.dir = Some(dir.to_path_buf());
        Ok(())
    }

    /// [`Database::save`] with a hook run before each step of the save (`SaveStep`); an
    /// error from it fails that step, as a full disk or a power cut would (the tests
    /// fail every step in turn).
    pub fn save_with(
        &mut self,
        dir: &Path,
        overwrite: Overwrite,
        mut before: impl FnMut(SaveStep) -> std::io::Result<()>,
    ) -> Result<(), SaveError> {
        // A file is written only if its records changed, or it is not where it was loaded
        // from (a save to another folder): the others stay as they are, byte for byte.
        // A file that was missing is written (the database is whole again); one that could
        // not be read is not, unless its collection changed.
        let moved = self.dir.as_deref() != Some(dir);
        let texts: Vec<(FileKind, String)> = FileKind::ALL
            .iter()
            .filter(|&&k| {
                let loaded = &self.loaded[k.index()];
                let missing = loaded.bytes.is_none() && !loaded.unreadable;
                moved || self.collection_changed(k) || missing
            })
            .map(|&k| (k, self.render(k)))
            .collect();
        // Check every file before writing any, so a refusal changes nothing.
        for (kind, text) in &texts {
            let path = dir.join(kind.file_name());
            let loaded = &self.loaded[kind.index()];
            let on_disk = read_file(&path).ok();
            if on_disk.as_deref() == Some(text.as_bytes()) {
                continue;
            }
            if overwrite == Overwrite::Never {
                if on_disk != loaded.bytes {
                    return Err(SaveError::ChangedOnDisk(path));
                }
                if loaded.lossy {
                    return Err(SaveError::WouldDropRecords(path));
                }
            }
        }
        std::fs::create_dir_all(dir).map_err(|source| SaveError::Io {
            path: dir.to_path_buf(),
            source,
        })?;
        let mut changed = Vec::new();
        for (kind, text) in texts.clone() {
            let path = dir.join(kind.file_name());
            let unchanged = read_file(&path).ok().as_deref() == Some(text.as_bytes());
            // A file that never existed and would be empty stays absent.
            let empty_new = !path.exists() && self.collection_is_empty(kind);
            if !unchanged && !empty_new {
                changed.push((kind, path, text.into_bytes()));
            }
        }
        let files: Vec<(&Path, &[u8])> = changed
            .iter()
            .map(|(_, p, t)| (p.as_path(), t.as_slice()))
            .collect();
        let kinds: Vec<FileKind> = changed.iter().map(|(k, ..)| *k).collect();
        let not_durable = match write_all_or_nothing(&files, &kinds, &mut before) {
            Ok(()) => None,
            Err((path, SaveFailure::Io(source))) => return Err(SaveError::Io { path, source }),
            Err((path, SaveFailure::NotDurable(source))) => Some((path, source)),
        };
        // Every file is renamed into place: what is on disk is what was saved, even if the
        // folder could not be synced (then say so, but do not refuse the next save).
        for (kind, text) in &texts {
            self.loaded[kind.index()] = Loaded {
                bytes: read_file(&dir.join(kind.file_name())).ok(),
                ..Loaded::default()
            };
            self.sources[kind.index()] = record_texts(text, *kind);
        }
        self.clean = self.model.clone();
        match not_durable {
            Some((path, source)) => Err(SaveError::NotDurable { path, source }),
            None => Ok(()),
        }
    }

    fn collection_is_empty(&self, kind: FileKind) -> bool {
        match kind {
            FileKind::Bodies => self.model.bodies.is_empty(),
            FileKind::Robots => self.model.robots.is_empty(),
            FileKind::Scenes => self.model.scenes.is_empty(),
        }
    }

    /// Which files changed on disk since they were loaded or saved.
    pub fn changed_on_disk(&self) -> Vec<FileKind> {
        let Some(dir) = &self.dir else {
            return Vec::new();
        };
        FileKind::ALL
            .into_iter()
            .filter(|k| read_file(&dir.join(k.file_name())).ok() != self.loaded[k.index()].bytes)
            .collect()
    }

    /// Whether the model has edits since it was loaded or saved. (Compared as records,
    /// not as text: a hand-written file that we would format differently is not an edit.)
    pub fn is_dirty(&self) -> bool {
        self.model != self.clean
    }
}

/// The largest database file read: far beyond any database (the default's three files
/// are 10 KB), far below what a read of `/dev/zero` would fill memory with.
pub const MAX_FILE_BYTES: u64 = 64 << 20;

/// A database file's bytes: a regular file (a FIFO would wait for a writer for ever, a
/// device read for ever) of at most `MAX_FILE_BYTES`.
pub fn read_file(path: &Path) -> std::io::Result<Vec<u8>> {
    use std::io::Read;
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        // Opening a FIFO waits for a writer, unless asked not to.
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK);
    }
    let file = match options.open(path) {
        Ok(file) => file,
        // A link to nothing is not a missing file (an empty collection): it is a mistake.
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => match std::fs::read_link(path) {
            Ok(target) => {
                return Err(std::io::Error::other(format!(
                    "a symbolic link to {}, which does not exist",
                    target.display()
                )));
            }
            Err(_) => return Err(e),
        },
        Err(e) => return Err(e),
    };
    let meta = file.metadata()?;
    if !meta.is_file() {
        return Err(std::io::Error::other(
            "not a regular file (a folder, a FIFO or a device)",
        ));
    }
    if meta.len() > MAX_FILE_BYTES {
        return Err(std::io::Error::other(format!(
            "{} bytes, more than a database file may hold ({} MiB)",
            meta.len(),
            MAX_FILE_BYTES >> 20
        )));
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(MAX_FILE_BYTES + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(std::io::Error::other(format!(
            "more than a database file may hold ({} MiB)",
            MAX_FILE_BYTES >> 20
        )));
    }
    Ok(bytes)
}

/// The records' texts of a file this program wrote, in order (its own writing reads back
/// whole, one record per model record).
fn record_texts(text: &str, kind: FileKind) -> Vec<Option<Arc<str>>> {
    let Ok(parsed) = xml::parse(text, kind.file_name()) else {
        return Vec::new();
    };
    parsed
        .root
        .children
        .iter()
        .map(|c| {
            c.span
                .as_deref()
                .and_then(|r| text.get(r.clone()))
                .map(Arc::from)
        })
        .collect()
}

/// One step of saving, for failure injection (`Database::save_with`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SaveStep {
    /// Writing and syncing a file's new text to a temporary file beside it.
    WriteTemporary(FileKind),
    /// Keeping the old file as a backup (a hard link) before replacing it.
    KeepBackup(FileKind),
    /// Renaming the temporary file over the file.
    Rename(FileKind),
    /// Syncing the folder, so that the renames last.
    SyncFolder,
}

/// Why writing the files failed: an error that left the old files in place, or one after
/// every file was renamed into place (only the folder's sync failed).
#[derive(Debug)]
enum SaveFailure {
    Io(std::io::Error),
    NotDurable(std::io::Error),
}

/// Writes several files as one: either every one has its new text or every one keeps its
/// old (a crash part way leaves old files and, at most, a backup or temporary file beside
/// them). Every new text is written to a temporary file in its folder and synced first;
/// then each old file is kept as a backup (a hard link, or a copy where the file system
/// has none) and the temporary renamed over it; if a rename fails, the files already
/// replaced get their backups back. A file keeps its permissions, and a symbolic link
/// keeps pointing where it did: its target is what gets written.
fn write_all_or_nothing(
    files: &[(&Path, &[u8])],
    kinds: &[FileKind],
    before: &mut impl FnMut(SaveStep) -> std::io::Result<()>,
) -> Result<(), (PathBuf, SaveFailure)> {
    fn io(path: &Path) -> impl FnOnce(std::io::Error) -> (PathBuf, SaveFailure) + '_ {
        move |e| (path.to_path_buf(), SaveFailure::Io(e))
    }
    // Where each file really is (through symbolic links), and its temporary beside it.
    let mut staged = Vec::new();
    for (&(path, bytes), &kind) in files.iter().zip(kinds) {
        let target = resolve_links(path).map_err(io(path))?;
        before(SaveStep::WriteTemporary(kind)).map_err(io(path))?;
        let temp = write_temporary(&target, bytes).map_err(io(path))?;
        staged.push((kind, path, target, temp));
    }
    // Old files are kept until every new one is in place.
    let mut replaced: Vec<(PathBuf, Option<PathBuf>)> = Vec::new();
    let mut failure = None;
    for (kind, path, target, temp) in staged {
        let step = (|| {
            before(SaveStep::KeepBackup(kind))?;
            let backup = keep_backup(&target)?;
            replaced.push((target.clone(), backup));
            before(SaveStep::Rename(kind))?;
            temp.persist(&target).map_err(|e| e.error)?;
            Ok::<(), std::io::Error>(())
        })();
        if let Err(e) = step {
            failure = Some((path.to_path_buf(), e));
            break;
        }
    }
    if let Some((path, e)) = failure {
        // The way back: every file already replaced gets its old text (or is removed if it
        // is new); `replaced`'s last entry may not have been renamed yet, which restoring
        // its backup leaves as it was.
        for (target, backup) in replaced.iter().rev() {
            match backup {
                Some(backup) => {
                    // Renaming a link over another link to the same file does nothing:
                    // then the backup is removed.
                    let _ = std::fs::rename(backup, target);
                    let _ = std::fs::remove_file(backup);
                }
                None => {
                    let _ = std::fs::remove_file(target);
                }
            }
        }
        return Err((path, SaveFailure::Io(e)));
    }
    for (_, backup) in &replaced {
        if let Some(backup) = backup {
            let _ = std::fs::remove_file(backup);
        }
    }
    let mut folders: Vec<&Path> = replaced
        .iter()
        .map(|(target, _)| target.parent().unwrap_or(Path::new(".")))
        .collect();
    folders.sort();
    folders.dedup();
    for folder in folders {
        let synced = before(SaveStep::SyncFolder).and_then(|()| sync_folder(folder));
        if let Err(e) = synced {
            return Err((folder.to_path_buf(), SaveFailure::NotDurable(e)));
        }
    }
    Ok(())
}

/// `bytes` in a synced temporary file beside `target`, with `target`'s permissions.
fn write_temporary(target: &Path, bytes: &[u8]) -> std::io::Result<tempfile::NamedTempFile> {
    let dir = target
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let mut temp = tempfile::Builder::new()
        .prefix(".robosim-")
        .suffix(".tmp")
        .tempfile_in(dir)?;
    temp.write_all(bytes)?;
    temp.flush()?;
    let permissions = match std::fs::metadata(target) {
        Ok(meta) => meta.permissions(),
        // A new file: as the user's files are (0644 under the usual umask), not tempfile's
        // private 0600.
        Err(_) => default_permissions(),
    };
    temp.as_file().set_permissions(permissions)?;
    temp.as_file().sync_all()?;
    Ok(temp)
}

#[cfg(unix)]
fn default_permissions() -> std::fs::Permissions {
    use std::os::unix::fs::PermissionsExt;
    // SAFETY: umask is read by setting it and setting it back.
    let umask = unsafe {
        let mask = libc::umask(0o022);
        libc::umask(mask);
        mask
    };
    std::fs::Permissions::from_mode(0o666 & !(umask as u32))
}

#[cfg(not(unix))]
fn default_permissions() -> std::fs::Permissions {
    std::fs::metadata(".")
        .map(|m| m.permissions())
        .unwrap_or_else(|_| {
            std::fs::File::open(".")
                .and_then(|f| f.metadata())
                .expect("the current folder")
                .permissions()
        })
}

/// A backup of `target` beside it (None: there is no file yet), kept until the save ends.
fn keep_backup(target: &Path) -> std::io::Result<Option<PathBuf>> {
    if !target.exists() {
        return Ok(None);
    }
    let name = target.file_name().unwrap_or_default().to_string_lossy();
    let backup = target.with_file_name(format!(".robosim-backup-{name}"));
    let _ = std::fs::remove_file(&backup);
    if std::fs::hard_link(target, &backup).is_err() {
        std::fs::copy(target, &backup)?;
    }
    Ok(Some(backup))
}

#[cfg(unix)]
fn sync_folder(folder: &Path) -> std::io::Result<()> {
    std::fs::File::open(folder)?.sync_all()
}

#[cfg(not(unix))]
fn sync_folder(_folder: &Path) -> std::io::Result<()> {
    Ok(())
}

/// Who uses a body or robot, for the reference check before a delete.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum User {
    Robot(String),
    Scene(String),
}

impl std::fmt::Display for User {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            User::Robot(name) => write!(f, "robot \"{name}\""),
            User::Scene(name) => write!(f, "scene \"{name}\""),
        }
    }
}

#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum EditError {
    #[error("\"{0}\" does not exist")]
    Missing(String),
    #[error("the name \"{0}\" is already taken")]
    Taken(String),
    #[error("the name is empty")]
    EmptyName,
    #[error("\"{name}\" is used by {}", users.iter().map(|u| u.to_string()).collect::<Vec<_>>().join(", "))]
    InUse { name: String, users: Vec<User> },
}

/// Whether a delete also removes what refers to the deleted item.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Delete {
    /// Refuse if anything refers to it.
    IfUnused,
    /// Also remove the placements that refer to it (and robots/scenes left without
    /// those placements keep the rest).
    Cascade,
}

impl Model {
    /// Robots and scenes that place the body `name`.
    pub fn body_users(&self, name: &str) -> Vec<User> {
        let mut users: Vec<User> = self
            .robots
            .iter()
            .filter(|r| {
                r.bodies
                    .iter()
                    .any(|b| same_name(&b.placement.source, name))
            })
            .map(|r| User::Robot(r.name.clone()))
            .collect();
        users.extend(
            self.scenes
                .iter()
                .filter(|s| s.bodies.iter().any(|b| same_name(&b.source, name)))
                .map(|s| User::Scene(s.name.clone())),
        );
        users
    }

    /// Scenes that place the robot `name`.
    pub fn robot_users(&self, name: &str) -> Vec<User> {
        self.scenes
            .iter()
            .filter(|s| s.robots.iter().any(|r| same_name(&r.source, name)))
            .map(|s| User::Scene(s.name.clone()))
            .collect()
    }

    fn check_new_name(taken: bool, new: &str) -> Result<(), EditError> {
        if new.trim().is_empty() {
            Err(EditError::EmptyName)
        } else if taken {
            Err(EditError::Taken(new.to_string()))
        } else {
            Ok(())
        }
    }

    /// Renames a body definition and every reference to it.
    pub fn rename_body(&mut self, old: &str, new: &str) -> Result<(), EditError> {
        let index = self
            .bodies
            .iter()
            .position(|b| same_name(&b.name, old))
            .ok_or_else(|| EditError::Missing(old.into()))?;
        Self::check_new_name(
            self.body(new).is_some_and(|b| !same_name(&b.name, old)),
            new,
        )?;
        self.bodies[index].name = new.to_string();
        for p in self
            .robots
            .iter_mut()
            .flat_map(|r| r.bodies.iter_mut())
            .map(|b| &mut b.placement)
        {
            if same_name(&p.source, old) {
                p.source = new.to_string();
            }
        }
        for p in self.scenes.iter_mut().flat_map(|s| s.bodies.iter_mut()) {
            if same_name(&p.source, old) {
                p.source = new.to_string();
            }
        }
        Ok(())
    }

    /// Renames a robot and every scene's reference to it.
    pub fn rename_robot(&mut self, old: &str, new: &str) -> Result<(), EditError> {
        let index = self
            .robots
            .iter()
            .position(|r| same_name(&r.name, old))
            .ok_or_else(|| EditError::Missing(old.into()))?;
        Self::check_new_name(
            self.robot(new).is_some_and(|r| !same_name(&r.name, old)),
            new,
        )?;
        self.robots[index].name = new.to_string();
        for r in self.scenes.iter_mut().flat_map(|s| s.robots.iter_mut()) {
            if same_name(&r.source, old) {
                r.source = new.to_string();
            }
        }
        Ok(())
    }

    pub fn rename_scene(&mut self, old: &str, new: &str) -> Result<(), EditError> {
        let index = self
            .scenes
            .iter()
            .position(|s| same_name(&s.name, old))
            .ok_or_else(|| EditError::Missing(old.into()))?;
        Self::check_new_name(
            self.scene(new).is_some_and(|s| !same_name(&s.name, old)),
            new,
        )?;
        self.scenes[index].name = new.to_string();
        Ok(())
    }

    /// Deletes a body definition; refused while used unless `Cascade`, which also removes
    /// its placements (and the joints of removed robot bodies).
    pub fn delete_body(&mut self, name: &str, mode: Delete) -> Result<(), EditError> {
        let index = self
            .bodies
            .iter()
            .position(|b| same_name(&b.name, name))
            .ok_or_else(|| EditError::Missing(name.into()))?;
        let users = self.body_users(name);
        if !users.is_empty() && mode == Delete::IfUnused {
            return Err(EditError::InUse {
                name: name.into(),
                users,
            });
        }
        self.bodies.remove(index);
        for robot in &mut self.robots {
            let removed: Vec<String> = robot
                .bodies
                .iter()
                .filter(|b| same_name(&b.placement.source, name))
                .map(|b| b.placement.alias.clone())
                .collect();
            robot
                .bodies
                .retain(|b| !same_name(&b.placement.source, name));
            let was_removed = |alias: &str| removed.iter().any(|r| same_name(r, alias));
            robot
                .joints
                .retain(|j| !was_removed(&j.body_a) && !was_removed(&j.body_b));
        }
        for scene in &mut self.scenes {
            scene.bodies.retain(|b| !same_name(&b.source, name));
        }
        Ok(())
    }

    /// Deletes a robot; refused while a scene uses it unless `Cascade`.
    pub fn delete_robot(&mut self, name: &str, mode: Delete) -> Result<(), EditError> {
        let index = self
            .robots
            .iter()
            .position(|r| same_name(&r.name, name))
            .ok_or_else(|| EditError::Missing(name.into()))?;
        let users = self.robot_users(name);
        if !users.is_empty() && mode == Delete::IfUnused {
            return Err(EditError::InUse {
                name: name.into(),
                users,
            });
        }
        self.robots.remove(index);
        for scene in &mut self.scenes {
            scene.robots.retain(|r| !same_name(&r.source, name));
        }
        Ok(())
    }

    pub fn delete_scene(&mut self, name: &str) -> Result<(), EditError> {
        let index = self
            .scenes
            .iter()
            .position(|s| same_name(&s.name, name))
            .ok_or_else(|| EditError::Missing(name.into()))?;
        self.scenes.remove(index);
        Ok(())
    }
}

/// The records of a robots.xml or scenes.xml text that read without an error, as the
/// clipboard carries them between windows; `None` if the text is neither.
pub fn records_from_text(
    text: &str,
) -> Option<(Vec<crate::model::Robot>, Vec<crate::model::Scene>)> {
    let parsed = xml::parse(text, "clipboard").ok()?;
    match &*parsed.root.name {
        "robots" => Some((read::robots(&parsed.root, "clipboard").records, Vec::new())),
        "scenes" => Some((Vec::new(), read::scenes(&parsed.root, "clipboard").records)),
        _ => None,
    }
}
