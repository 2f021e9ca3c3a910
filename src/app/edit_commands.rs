//! Commands that edit the model: whole items (new, duplicate, rename, delete), the
//! placements the canvas moves and turns, joints, outlines, and copy and paste of
//! placements. Each becomes one undoable edit of the document.

use super::dialogs::Dialog;
use super::inspector::NewPlacement;
use super::runner::{PREVIEW, preview};
use super::{Command, Copied, RoboSimApp, Selection, placements, placing, tools};
use crate::db::{Delete, EditError};
use crate::model::{Model, Placement, SceneRobot};
use crate::sim::Simulation;
use pe::{Aabb, Vec2};

impl RoboSimApp {
    pub(super) fn apply_edit(&mut self, command: Command, now: f64) {
        match command {
            Command::Select(selection) => self.select(selection),
            Command::Commit { draft, key } => self.commit(draft, &key, now),
            Command::Rename(from, to) => self.rename(&from, &to, now),
            Command::New(kind) => {
                let created = self.doc.new_item(kind, now);
                self.select(created);
                self.runner.running = false;
            }
            Command::Duplicate => self.duplicate(now),
            Command::Delete(mode) => self.delete_item(mode, now),
            Command::DeleteSelected => self.delete_selected(now),
            Command::Undo => self.undo(),
            Command::Redo => self.redo(),
            Command::PlaceInScene(item) => self.place_in_scene(item, now),
            Command::MovePlacement { body, to } => self.move_placement(body, to, now),
            Command::TurnPlacement { body, angle } => self.turn_placement(body, angle, now),
            Command::Nudge(delta) => self.nudge(delta, now),
            Command::Pick { bodies, add } => self.pick(&bodies, add),
            Command::TogglePick(body) => self.toggle_pick(body),
            Command::UseTool(p) => self.use_tool(p, now),
            Command::DrawShape { from, to } => self.draw_shape(from, to, now),
            Command::SetVertices { vertices, key } => self.set_vertices(vertices, &key, now),
            Command::CopyPlacement => {
                if let Some(clip) = self.copy_picked() {
                    let n = clip.items.len();
                    self.clipboard_out = Some(clip.to_text());
                    self.copied = Some(clip);
                    self.inform(format!(
                        "copied {n} placement{}",
                        if n == 1 { "" } else { "s" }
                    ));
                }
            }
            Command::CutPlacement => {
                if let Some(clip) = self.copy_picked() {
                    self.clipboard_out = Some(clip.to_text());
                    self.copied = Some(clip);
                    self.remove_picked(now);
                }
            }
            Command::PastePlacement => {
                // Placements from the system clipboard (copied here or in another
                // window), else the ones copied here.
                let from_text =
                    (self.pasted.take()).and_then(|t| super::placements::Clipboard::from_text(&t));
                if let Some(clip) = from_text.or_else(|| self.copied.clone()) {
                    self.paste_clipboard(clip, "paste", now);
                }
            }
            _ => {}
        }
    }

    /// Duplicates the placements selected at step 0 (beside them, leaving the clipboard
    /// alone), or else the item selected in the browser.
    fn duplicate(&mut self, now: f64) {
        if let Some(clip) = self.copy_picked() {
            return self.paste_clipboard(clip, "duplicate", now);
        }
        if let Some(copy) = self
            .selection
            .clone()
            .and_then(|s| self.doc.duplicate(&s, now))
        {
            self.select(copy);
        }
    }

    /// Deletes the selected placements at step 0, or else the selected item.
    fn delete_selected(&mut self, now: f64) {
        if !self.remove_picked(now) {
            self.delete_item(Delete::IfUnused, now);
        }
    }

    fn undo(&mut self) {
        if self.doc.undo() {
            self.model_edited();
            // What the undone edit said ("removed 5 placements") is no longer so.
            self.inform("undone".into());
        }
    }

    fn redo(&mut self) {
        if self.doc.redo() {
            self.model_edited();
            self.inform("redone".into());
        }
    }

    fn rename(&mut self, from: &Selection, to: &str, now: f64) {
        match self.doc.rename(from, to, now) {
            Ok(renamed) => {
                self.select(renamed);
                self.runner.running = false;
            }
            Err(e) => {
                self.complain(format!("cannot rename: {e}"));
                self.inspector.forget_typed_name();
            }
        }
    }

    fn delete_item(&mut self, mode: Delete, now: f64) {
        let Some(selected) = self.selection.clone() else {
            return;
        };
        match self.doc.delete(&selected, mode, now) {
            Ok(()) => self.model_changed(),
            Err(e @ EditError::InUse { .. }) => self.dialog = Some(Dialog::Cascade(e.to_string())),
            Err(e) => self.complain(e.to_string()),
        }
    }

    fn set_vertices(&mut self, vertices: Vec<[f64; 2]>, key: &str, now: f64) {
        let Some(Selection::Body(name)) = self.selection.clone() else {
            return;
        };
        let mut draft = self.doc.model().clone();
        if let Some(b) = draft.body_mut(&name) {
            b.vertices = vertices;
        }
        self.inform(String::new());
        self.commit(draft, key, now);
    }

    pub(super) fn snapped(&self, p: Vec2) -> Vec2 {
        let step = self.view.snap_step;
        Vec2::new(tools::snap(p.x, step), tools::snap(p.y, step))
    }

    /// How near (screen points) a click of the joint tool must be to a body's centre or
    /// vertex to land on it.
    const JOINT_SNAP_POINTS: f64 = 6.0;

    /// Applies the current tool at world point `p` (the robot preview puts the robot's
    /// frame at the world origin, so world and robot coordinates agree).
    fn use_tool(&mut self, p: Vec2, now: f64) {
        let (tools::Tool::Joint, Some(Selection::Robot(robot))) =
            (self.view.tool, self.selection.clone())
        else {
            return;
        };
        // A centre or a vertex within a few points, else the grid.
        let radius = Self::JOINT_SNAP_POINTS / self.view.camera.zoom;
        let p = self
            .doc
            .model()
            .robot(&robot)
            .and_then(|r| tools::joint_snap_point(self.doc.model(), r, p, radius))
            .unwrap_or_else(|| self.snapped(p));
        let mut draft = self.doc.model().clone();
        match tools::add_joint(&mut draft, &robot, p) {
            Ok(j) => {
                self.inform(format!(
                    "pinned {} to {} at ({}, {})",
                    j.body_b, j.body_a, p.x, p.y
                ));
                self.commit(draft, "add joint", now);
            }
            Err(why) => self.complain(why),
        }
    }

    /// Makes the body a drawing tool's drag from `from` to `to` sizes: a new body
    /// definition placed where it was drawn in the scene or robot shown, one undo step
    /// for both, and selected.
    fn draw_shape(&mut self, from: Vec2, to: Vec2, now: f64) {
        let Some(into) = self.selection.clone() else {
            return;
        };
        let shape = match tools::drawn_shape(self.view.tool, self.view.shape, from, to) {
            Ok(shape) => shape,
            Err(why) => return self.complain(why),
        };
        let at = shape.at;
        // Terrain only in scenes: a robot's static body would pin it in place.
        let terrain = self.view.shape.terrain && matches!(into, Selection::Scene(_));
        let mut draft = self.doc.model().clone();
        let name = match tools::add_drawn_body(&mut draft, &into, shape, terrain) {
            Ok(name) => name,
            Err(why) => return self.complain(why),
        };
        let owner = match &into {
            Selection::Scene(n) => draft
                .scene(n)
                .map(|s| placements::Owner::SceneBody(s.bodies.len() - 1)),
            Selection::Robot(n) => draft
                .robot(n)
                .map(|r| placements::Owner::RobotBody(r.bodies.len() - 1)),
            Selection::Body(_) => None,
        };
        self.inform(format!(
            "drew {name} at ({}, {}): a new body, also in the library",
            at.x, at.y
        ));
        self.commit(draft, &format!("draw {name}"), now);
        if let Some(owner) = owner {
            self.pick_owners(&[owner]);
        }
    }

    /// A new placement's reference point: its box in free space nearest the view's centre.
    pub(super) fn free_spot_in(&self, scene: &str, item: Aabb) -> Vec2 {
        let occupied = Simulation::new(self.doc.model(), scene, None, None)
            .map(|sim| placing::body_boxes(&sim))
            .unwrap_or_default();
        self.snapped(placing::free_spot(&occupied, item, self.view.camera.centre))
    }

    /// Adds `item` to the selected scene in free space nearest the view's centre.
    fn place_in_scene(&mut self, item: NewPlacement, now: f64) {
        let Some(Selection::Scene(scene)) = self.selection.clone() else {
            return;
        };
        let (robot, body) = match &item {
            NewPlacement::Robot(source) => (Some(source.as_str()), None),
            NewPlacement::Body(source) => (None, Some(source.as_str())),
        };
        let item_box = preview_box(&preview(self.doc.model(), robot, body));
        let spot = self.free_spot_in(&scene, item_box);
        let item = match item {
            NewPlacement::Robot(source) => Copied::SceneRobot(SceneRobot {
                source,
                ..SceneRobot::default()
            }),
            NewPlacement::Body(source) => Copied::SceneBody(Placement {
                alias: source.clone(),
                source,
                ..Placement::default()
            }),
        };
        let mut draft = self.doc.model().clone();
        let Some(placed) = draft
            .scene_mut(&scene)
            .map(|s| placements::put_in_scene(s, vec![item], spot))
        else {
            return;
        };
        self.commit(draft, "add to scene", now);
        self.pick_owners(&placed);
    }
}

/// The box around the single item `model`'s preview scene places at the origin.
fn preview_box(model: &Model) -> Aabb {
    Simulation::new(model, PREVIEW, None, None)
        .ok()
        .and_then(|sim| {
            placing::bounds_of(
                placing::body_boxes(&sim)
                    .into_iter()
                    .flat_map(|b| [b.min, b.max]),
            )
        })
        .unwrap_or(Aabb {
            min: Vec2::repeat(-10.0),
            max: Vec2::repeat(10.0),
        })
}
