//! The database: a directory of three XML files (SPEC §4.3) — bodies.xml, robots.xml,
//! scenes.xml — loaded whatever they contain, checked with messages that name file, line
//! and element, and saved atomically without ever overwriting what changed on disk.

mod check;
mod problem;
mod read;
pub mod write;
mod xml;

pub use check::{TIMESTEP_RANGE, beyond_all, check, limits, outline_polygon, polygon};
pub use problem::{Problem, Severity};
pub use xml::{MAX_DEPTH, clip};

use crate::model::{Model, same_name};
use std::io::Write as _;
use std::path::{Path, PathBuf};

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
}

#[derive(Debug, Clone, PartialEq, Default)]
pub struct Database {
    /// Where it was loaded from and saves to (None: embedded or new).
    pub dir: Option<PathBuf>,
    pub model: Model,
    loaded: [Loaded; 3],
    /// The model as last loaded or saved: what "unsaved changes" are measured against.
    clean: Model,
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
        for kind in FileKind::ALL {
            let path = dir.join(kind.file_name());
            let bytes = match std::fs::read(&path) {
                Ok(bytes) => Some(bytes),
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => None,
                Err(e) => {
                    problems.push(Problem::error(
                        &path.display().to_string(),
                        "file",
                        format!("cannot read: {e}"),
                    ));
                    None
                }
            };
            files.push((kind, path.display().to_string(), bytes));
        }
        let mut db = Self::from_files(files, &mut problems);
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
            let root = match xml::decode(bytes, &name).and_then(|text| xml::parse(text, &name)) {
                Ok(root) => root,
                Err(p) => {
                    problems.push(p);
                    loaded.lossy = true;
                    continue;
                }
            };
            let skipped = match kind {
                FileKind::Bodies => {
                    let r = read::bodies(&root, &name);
                    db.model.bodies = r.records;
                    problems.extend(r.problems);
                    r.skipped
                }
                FileKind::Robots => {
                    let r = read::robots(&root, &name);
                    db.model.robots = r.records;
                    problems.extend(r.problems);
                    r.skipped
                }
                FileKind::Scenes => {
                    let r = read::scenes(&root, &name);
                    db.model.scenes = r.records;
                    problems.extend(r.problems);
                    r.skipped
                }
            };
            db.loaded[kind.index()].lossy = skipped;
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

    /// The text each file would have if saved now.
    pub fn render(&self, kind: FileKind) -> String {
        match kind {
            FileKind::Bodies => write::bodies(&self.model.bodies),
            FileKind::Robots => write::robots(&self.model.robots),
            FileKind::Scenes => write::scenes(&self.model.scenes),
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
                    bytes: std::fs::read(path).ok(),
                    lossy: false,
                };
            }
        }
        self.save_with(dir, overwrite, |_| Ok(()))?;
        self.dir = Some(dir.to_path_buf());
        Ok(())
    }

    /// [`Database::save`] with a hook run just before each rename (tests use it to
    /// interrupt a save).
    pub fn save_with(
        &mut self,
        dir: &Path,
        overwrite: Overwrite,
        mut before_rename: impl FnMut(&Path) -> std::io::Result<()>,
    ) -> Result<(), SaveError> {
        let texts: Vec<(FileKind, String)> =
            FileKind::ALL.iter().map(|&k| (k, self.render(k))).collect();
        // Check every file before writing any, so a refusal changes nothing.
        for (kind, text) in &texts {
            let path = dir.join(kind.file_name());
            let loaded = &self.loaded[kind.index()];
            let on_disk = std::fs::read(&path).ok();
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
        for (kind, text) in texts {
            let path = dir.join(kind.file_name());
            let unchanged = std::fs::read(&path).ok().as_deref() == Some(text.as_bytes());
            // A file that never existed and would be empty stays absent.
            let empty_new = !path.exists() && self.collection_is_empty(kind);
            if !unchanged && !empty_new {
                write_atomic(&path, text.as_bytes(), &mut before_rename).map_err(|source| {
                    SaveError::Io {
                        path: path.clone(),
                        source,
                    }
                })?;
            }
            self.loaded[kind.index()] = Loaded {
                bytes: std::fs::read(&path).ok(),
                lossy: false,
            };
        }
        self.clean = self.model.clone();
        Ok(())
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
            .filter(|k| std::fs::read(dir.join(k.file_name())).ok() != self.loaded[k.index()].bytes)
            .collect()
    }

    /// Whether the model has edits since it was loaded or saved. (Compared as records,
    /// not as text: a hand-written file that we would format differently is not an edit.)
    pub fn is_dirty(&self) -> bool {
        self.model != self.clean
    }
}

/// Writes `bytes` to `path` so that a crash leaves either the old or the new file: a
/// temporary file in the same directory, written, flushed and fsynced, then renamed over
/// the old one (and the directory fsynced, so the rename itself is durable).
pub fn write_atomic(
    path: &Path,
    bytes: &[u8],
    before_rename: &mut impl FnMut(&Path) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let mut temp = tempfile::Builder::new()
        .prefix(".robosim-")
        .suffix(".tmp")
        .tempfile_in(dir)?;
    temp.write_all(bytes)?;
    temp.flush()?;
    temp.as_file().sync_all()?;
    // On error the temporary file is removed when `temp` drops.
    before_rename(temp.path())?;
    temp.persist(path).map_err(|e| e.error)?;
    #[cfg(unix)]
    std::fs::File::open(dir)?.sync_all()?;
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
