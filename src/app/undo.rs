//! Undo and redo for every edit: the model is small (a few hundred records at most), so a
//! snapshot of it before each edit is the simplest history that cannot miss a change.

use crate::model::Model;

/// Snapshots of the model before each edit, and after each undo.
#[derive(Debug, Clone, Default)]
pub struct UndoHistory {
    undo: Vec<Model>,
    redo: Vec<Model>,
    /// The last edit's key and time: a drag or typing in one field is one edit, not one
    /// per frame.
    last: Option<(String, f64)>,
}

/// Edits to the same field within this many seconds merge into one undo step.
const MERGE_SECONDS: f64 = 1.0;
const LIMIT: usize = 500;

impl UndoHistory {
    /// Records `before` as the state to return to, unless this edit continues the last
    /// one (same `key`, soon after).
    pub fn record(&mut self, before: &Model, key: &str, now: f64) {
        let continues = self
            .last
            .as_ref()
            .is_some_and(|(k, t)| k == key && now - t < MERGE_SECONDS);
        if !continues {
            self.undo.push(before.clone());
            if self.undo.len() > LIMIT {
                self.undo.remove(0);
            }
        }
        self.redo.clear();
        self.last = Some((key.to_string(), now));
    }

    pub fn undo(&mut self, current: &mut Model) -> bool {
        let Some(previous) = self.undo.pop() else {
            return false;
        };
        self.redo.push(std::mem::replace(current, previous));
        self.last = None;
        true
    }

    pub fn redo(&mut self, current: &mut Model) -> bool {
        let Some(next) = self.redo.pop() else {
            return false;
        };
        self.undo.push(std::mem::replace(current, next));
        self.last = None;
        true
    }

    pub fn can_undo(&self) -> bool {
        !self.undo.is_empty()
    }

    pub fn can_redo(&self) -> bool {
        !self.redo.is_empty()
    }

    pub fn clear(&mut self) {
        *self = Self::default();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::BodyDef;

    fn model(n: usize) -> Model {
        Model {
            bodies: (0..n)
                .map(|i| BodyDef {
                    name: i.to_string(),
                    ..BodyDef::default()
                })
                .collect(),
            ..Model::default()
        }
    }

    #[test]
    fn undo_and_redo_walk_the_snapshots_and_merge_one_drag() {
        let mut h = UndoHistory::default();
        let mut m = model(0);
        for (i, t) in [(1, 0.0), (2, 0.1), (3, 0.2)] {
            h.record(&m, "drag x", t); // one drag over three frames
            m = model(i);
        }
        h.record(&m, "density", 5.0);
        m = model(4);
        assert!(h.undo(&mut m));
        assert_eq!(m, model(3));
        assert!(h.undo(&mut m));
        assert_eq!(m, model(0), "the whole drag undoes at once");
        assert!(!h.undo(&mut m));
        assert!(h.redo(&mut m) && h.redo(&mut m));
        assert_eq!(m, model(4));
        assert!(!h.can_redo());
        h.undo(&mut m);
        h.record(&m, "other", 9.0);
        assert!(!h.can_redo(), "a new edit drops the redo branch");
    }
}
