//! The document: the database being edited, what is wrong with it, its undo history and
//! the copy of unsaved work kept against a crash. Every model edit goes through
//! [`Document::commit`]; files are read and written here and nowhere else in the app.

use super::Selection;
use super::autosave::Autosave;
use super::undo::UndoHistory;
use crate::db::{Database, Delete, EditError, Overwrite, Problem, SaveError};
use crate::model::{BodyDef, Model, Robot, Scene};
use std::path::{Path, PathBuf};

/// The kinds of item the browser lists and creates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ItemKind {
    Body,
    Robot,
    Scene,
}

impl ItemKind {
    pub const ALL: [Self; 3] = [Self::Body, Self::Robot, Self::Scene];

    pub fn name(self) -> &'static str {
        match self {
            Self::Body => "body",
            Self::Robot => "robot",
            Self::Scene => "scene",
        }
    }
}

#[derive(Debug)]
pub struct Document {
    db: Database,
    /// What reading the files found (records skipped, files unreadable): kept until the
    /// files are read again or saved, however the model is edited.
    read_problems: Vec<Problem>,
    /// `read_problems`, then what checking the model finds (after every edit).
    problems: Vec<Problem>,
    edits: UndoHistory,
    autosave: Autosave,
    /// The model changed since unsaved work was last kept: keep it soon.
    edited_since_autosave: bool,
}

impl Document {
    /// The database in `folder` (a folder that does not exist is an empty database that
    /// saves there), or the built-in examples.
    pub fn open(folder: Option<&Path>) -> Self {
        let (db, problems) = match folder {
            Some(dir) => Database::load(dir),
            None => Database::embedded(),
        };
        let read_problems = problems_of_reading(&db, problems.clone());
        Self {
            db,
            read_problems,
            problems,
            edits: UndoHistory::default(),
            autosave: Autosave::default(),
            edited_since_autosave: false,
        }
    }

    /// This document on another database (the autosave slots stay).
    pub fn reopen(&mut self, folder: Option<&Path>) {
        let autosave = std::mem::take(&mut self.autosave);
        *self = Self {
            autosave,
            ..Self::open(folder)
        };
    }

    /// This document on a new, empty database with no folder yet.
    pub fn start_empty(&mut self) {
        let autosave = std::mem::take(&mut self.autosave);
        *self = Self {
            db: Database::new(Model::default()),
            read_problems: Vec::new(),
            problems: Vec::new(),
            edits: UndoHistory::default(),
            autosave,
            edited_since_autosave: false,
        };
    }

    pub fn model(&self) -> &Model {
        &self.db.model
    }

    pub fn db(&self) -> &Database {
        &self.db
    }

    pub fn folder(&self) -> Option<&Path> {
        self.db.dir.as_deref()
    }

    pub fn problems(&self) -> &[Problem] {
        &self.problems
    }

    pub fn is_dirty(&self) -> bool {
        self.db.is_dirty()
    }

    pub fn can_undo(&self) -> bool {
        self.edits.can_undo()
    }

    pub fn can_redo(&self) -> bool {
        self.edits.can_redo()
    }

    /// Makes `draft` the model as one undoable edit (merged with the last if `key` names
    /// the same field soon after). Returns whether anything changed.
    pub fn commit(&mut self, draft: Model, key: &str, now: f64) -> bool {
        if draft == self.db.model {
            return false;
        }
        self.edits.record(&self.db.model, key, now);
        self.db.model = draft;
        self.changed();
        true
    }

    pub fn undo(&mut self) -> bool {
        let undone = self.edits.undo(&mut self.db.model);
        if undone {
            self.changed();
        }
        undone
    }

    pub fn redo(&mut self) -> bool {
        let redone = self.edits.redo(&mut self.db.model);
        if redone {
            self.changed();
        }
        redone
    }

    fn changed(&mut self) {
        self.edited_since_autosave = true;
        self.problems = self.read_problems.clone();
        self.problems.extend(self.db.check());
    }

    /// Reads the files again, dropping unsaved edits (undoable). False without a folder.
    pub fn revert(&mut self) -> bool {
        let Some(dir) = self.db.dir.clone() else {
            return false;
        };
        let (db, problems) = Database::load(&dir);
        self.edits.record(&self.db.model, "revert", f64::NAN);
        self.read_problems = problems_of_reading(&db, problems);
        self.db = db;
        self.changed();
        true
    }

    /// Saves to the database's folder, or to `folder` (which it then belongs to).
    pub fn save(&mut self, folder: Option<&Path>, overwrite: Overwrite) -> Result<(), SaveError> {
        let kept_for = self.db.dir.clone();
        match folder {
            Some(dir) => self.db.save_to(dir, overwrite)?,
            None => self.db.save(overwrite)?,
        }
        // The files now hold the model: what reading them found is gone.
        self.read_problems.clear();
        self.problems = self.db.check();
        self.autosave.clear(kept_for.as_deref());
        self.autosave.clear(self.db.dir.as_deref());
        Ok(())
    }

    // Unsaved work kept against a crash.

    pub fn keep_unsaved_work_under(&mut self, root: Option<PathBuf>) {
        self.autosave = Autosave::new(root);
    }

    /// Schedules the copy of unsaved work after an edit and writes it when due; returns
    /// how long until the next write (for a repaint timer).
    pub fn autosave_tick(&mut self, now: f64) -> Result<Option<f64>, SaveError> {
        if std::mem::take(&mut self.edited_since_autosave) {
            self.autosave.edited(now);
        }
        if self.autosave.is_due(now) {
            self.autosave.keep(&self.db)?;
        }
        Ok(self.autosave.seconds_left(now))
    }

    /// Writes the copy of unsaved work now (or clears it when all is saved).
    pub fn keep_unsaved_work(&mut self) -> Result<(), SaveError> {
        self.autosave.keep(&self.db)
    }

    /// Forgets the unsaved work kept for `folder`.
    pub fn discard_kept_work(&mut self, folder: Option<&Path>) {
        self.autosave.clear(folder);
    }

    /// Work an earlier session kept for this database and never saved.
    pub fn kept_work(&self) -> Option<Model> {
        self.autosave.find(self.db.dir.as_deref(), &self.db.model)
    }

    // Edits of whole items: each returns what to select afterwards.

    pub fn new_item(&mut self, kind: ItemKind, now: f64) -> Selection {
        let mut draft = self.db.model.clone();
        let selection = match kind {
            ItemKind::Body => {
                let names: Vec<String> = draft.bodies.iter().map(|b| b.name.clone()).collect();
                let name = unique(&names, "new body");
                draft.bodies.push(BodyDef {
                    name: name.clone(),
                    density: 1.0,
                    cor: 0.2,
                    vertices: vec![[-20.0, -10.0], [20.0, -10.0], [20.0, 10.0], [-20.0, 10.0]],
                    ..Default::default()
                });
                Selection::Body(name)
            }
            ItemKind::Robot => {
                let names: Vec<String> = draft.robots.iter().map(|r| r.name.clone()).collect();
                let name = unique(&names, "new robot");
                draft.robots.push(Robot {
                    name: name.clone(),
                    ..Default::default()
                });
                Selection::Robot(name)
            }
            ItemKind::Scene => {
                let names: Vec<String> = draft.scenes.iter().map(|s| s.name.clone()).collect();
                let name = unique(&names, "new scene");
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
        self.commit(draft, &format!("new {}", kind.name()), now);
        selection
    }

    pub fn duplicate(&mut self, selected: &Selection, now: f64) -> Option<Selection> {
        let mut draft = self.db.model.clone();
        let copy = match selected {
            Selection::Body(n) => {
                push_copy(&mut draft.bodies, n, |b| &mut b.name).map(Selection::Body)
            }
            Selection::Robot(n) => {
                push_copy(&mut draft.robots, n, |r| &mut r.name).map(Selection::Robot)
            }
            Selection::Scene(n) => {
                push_copy(&mut draft.scenes, n, |s| &mut s.name).map(Selection::Scene)
            }
        }?;
        self.commit(draft, "duplicate", now);
        Some(copy)
    }

    pub fn delete(
        &mut self,
        selected: &Selection,
        mode: Delete,
        now: f64,
    ) -> Result<(), EditError> {
        let mut draft = self.db.model.clone();
        match selected {
            Selection::Body(n) => draft.delete_body(n, mode),
            Selection::Robot(n) => draft.delete_robot(n, mode),
            Selection::Scene(n) => draft.delete_scene(n),
        }?;
        self.commit(draft, "delete", now);
        Ok(())
    }

    pub fn rename(
        &mut self,
        selected: &Selection,
        new: &str,
        now: f64,
    ) -> Result<Selection, EditError> {
        let mut draft = self.db.model.clone();
        let renamed = match selected {
            Selection::Body(n) => draft
                .rename_body(n, new)
                .map(|_| Selection::Body(new.into())),
            Selection::Robot(n) => draft
                .rename_robot(n, new)
                .map(|_| Selection::Robot(new.into())),
            Selection::Scene(n) => draft
                .rename_scene(n, new)
                .map(|_| Selection::Scene(new.into())),
        }?;
        self.commit(draft, "rename", now);
        Ok(renamed)
    }

    /// Whether `selection` still names an item of the model.
    pub fn has(&self, selection: &Selection) -> bool {
        let m = &self.db.model;
        match selection {
            Selection::Scene(n) => m.scene(n).is_some(),
            Selection::Robot(n) => m.robot(n).is_some(),
            Selection::Body(n) => m.body(n).is_some(),
        }
    }
}

/// The problems in `all` (from loading `db`) that reading the files found, as opposed to
/// what checking the model finds (which is checked again after every edit).
fn problems_of_reading(db: &Database, all: Vec<Problem>) -> Vec<Problem> {
    let checked = db.check();
    all.into_iter().filter(|p| !checked.contains(p)).collect()
}

/// The question to ask before saving bodies whose outline is not a convex polygon, or None
/// when every body is usable.
pub fn unusable_bodies_question(model: &Model) -> Option<String> {
    let unusable: Vec<String> = model
        .bodies
        .iter()
        .filter_map(|b| {
            let why = crate::db::polygon(b).err()?;
            Some(format!("\"{}\" ({why})", b.name))
        })
        .collect();
    let (first, more) = unusable.split_first()?;
    let others = match more.len() {
        0 => String::new(),
        n => format!(" and {n} more bodies"),
    };
    Some(format!(
        "Body {first}{others} is not a convex polygon. The simulation will not run a scene \
         that places it, or a robot built from it, until its outline is convex (Convex hull \
         in the body editor repairs it). Save anyway?"
    ))
}

/// `name` if it is free, else the next free name in its count: a name ending in a
/// number counts on from it ("box 5" → "box 6", "box 5 2" → "box 5 3"), another gets
/// " 2", " 3", … (`unique`). Duplicates are named as a person would number them.
pub fn next_in_count(taken: &[String], name: &str) -> String {
    if !taken.iter().any(|t| t == name) {
        return name.to_string();
    }
    let digits = name.len() - name.trim_end_matches(|c: char| c.is_ascii_digit()).len();
    let (stem, number) = name.split_at(name.len() - digits);
    match number.parse::<u64>() {
        Ok(n) if !stem.is_empty() && n < u64::MAX / 2 => (n + 1..)
            .map(|k| format!("{stem}{k}"))
            .find(|c| !taken.contains(c))
            .expect("some number is free"),
        _ => unique(taken, name),
    }
}

/// `base`, or `base 2`, `base 3`, … whichever is not in `taken`.
pub fn unique(taken: &[String], base: &str) -> String {
    if !taken.iter().any(|t| t == base) {
        return base.to_string();
    }
    (2..)
        .map(|k| format!("{base} {k}"))
        .find(|c| !taken.contains(c))
        .expect("some suffix is free")
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
    let new_name = unique(&taken, &format!("{name} copy"));
    *name_of(&mut copy) = new_name.clone();
    items.push(copy);
    Some(new_name)
}

#[cfg(test)]
mod tests {
    use super::*;

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
