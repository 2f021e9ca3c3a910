//! Commands that edit the model: whole items (new, duplicate, rename, delete), the
//! placements the canvas moves and turns, joints, outlines, and copy and paste of
//! placements. Each becomes one undoable edit of the document.

use super::dialogs::Dialog;
use super::inspector::NewPlacement;
use super::runner::{PREVIEW, preview};
use super::{Command, Copied, RoboSimApp, Selection, document::unique, placing, tools};
use crate::db::{Delete, EditError};
use crate::model::{Model, Placement, SceneRobot};
use crate::sim::{PlacedBy, Simulation};
use pe::{Aabb, Vec2};

/// Where a simulated body's placement is in the model.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Owner {
    SceneBody(usize),
    SceneRobot(usize),
    RobotBody(usize),
}

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
            Command::Duplicate => {
                if let Some(copy) = self
                    .selection
                    .clone()
                    .and_then(|s| self.doc.duplicate(&s, now))
                {
                    self.select(copy);
                }
            }
            Command::Delete(mode) => self.delete_item(mode, now),
            Command::DeleteSelected => self.delete_selected(now),
            Command::Undo => self.undo(),
            Command::Redo => self.redo(),
            Command::PlaceInScene(item) => self.place_in_scene(item, now),
            Command::MovePlacement { body, to } => self.move_placement(body, to, now),
            Command::TurnPlacement { body, angle } => {
                self.edit_placement(body, now, |_, _, o| *o += angle);
            }
            Command::UseTool(p) => self.use_tool(p, now),
            Command::SetVertices { vertices, key } => self.set_vertices(vertices, &key, now),
            Command::CopyPlacement => {
                self.copied = self.selected_placement().map(|(copied, _)| copied);
            }
            Command::CutPlacement => {
                self.copied = self.selected_placement().map(|(copied, _)| copied);
                self.remove_placement(now);
            }
            Command::PastePlacement => self.paste(now),
            _ => {}
        }
    }

    /// Deletes the selected placement at step 0, or else the selected item.
    fn delete_selected(&mut self, now: f64) {
        if !self.remove_placement(now) {
            self.delete_item(Delete::IfUnused, now);
        }
    }

    fn undo(&mut self) {
        if self.doc.undo() {
            self.model_changed();
        }
    }

    fn redo(&mut self) {
        if self.doc.redo() {
            self.model_changed();
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

    /// Where simulated body `index`'s placement is in the model, and its trace id.
    fn owner(&self, index: usize) -> Option<(Owner, String)> {
        let body = self.runner.sim()?.bodies.get(index)?;
        let owner = match (&self.selection, body.placed_by) {
            (Some(Selection::Scene(_)), PlacedBy::SceneBody(k)) => Owner::SceneBody(k),
            (Some(Selection::Scene(_)), PlacedBy::RobotBody { robot, .. }) => {
                Owner::SceneRobot(robot)
            }
            // The robot preview places the robot alone at the origin.
            (Some(Selection::Robot(_)), PlacedBy::RobotBody { body, .. }) => Owner::RobotBody(body),
            _ => return None,
        };
        Some((owner, body.id.clone()))
    }

    /// Edits (x, y, orientation) of the placement that puts simulated body `index` where it
    /// is: in a scene, the scene body or the whole robot; in a robot, the body's place in it.
    fn edit_placement(
        &mut self,
        index: usize,
        now: f64,
        edit: impl FnOnce(&mut f64, &mut f64, &mut f64),
    ) {
        let Some((owner, id)) = self.owner(index) else {
            return;
        };
        let mut draft = self.doc.model().clone();
        let placement = match (&self.selection, owner) {
            (Some(Selection::Scene(name)), Owner::SceneBody(k)) => draft
                .scene_mut(name)
                .and_then(|s| s.bodies.get_mut(k))
                .map(|b| (&mut b.x, &mut b.y, &mut b.orientation)),
            (Some(Selection::Scene(name)), Owner::SceneRobot(k)) => draft
                .scene_mut(name)
                .and_then(|s| s.robots.get_mut(k))
                .map(|r| (&mut r.x, &mut r.y, &mut r.orientation)),
            (Some(Selection::Robot(name)), Owner::RobotBody(k)) => draft
                .robot_mut(name)
                .and_then(|r| r.bodies.get_mut(k))
                .map(|b| {
                    (
                        &mut b.placement.x,
                        &mut b.placement.y,
                        &mut b.placement.orientation,
                    )
                }),
            _ => None,
        };
        let Some((x, y, o)) = placement else {
            return;
        };
        edit(x, y, o);
        self.commit(draft, &format!("place {id}"), now);
    }

    /// Moves the placement behind simulated body `index` so that its reference point goes
    /// to `wanted` (snapped to the grid).
    fn move_placement(&mut self, index: usize, wanted: Vec2, now: f64) {
        let Some(origin) = self.runner.sim().and_then(|s| {
            let b = s.bodies.get(index)?;
            Some(s.world.body(b.handle)?.origin())
        }) else {
            return;
        };
        let snapped = self.snapped(wanted);
        let delta = snapped - origin;
        if delta.norm() < 1e-12 {
            return;
        }
        self.edit_placement(index, now, |x, y, _| {
            *x += delta.x;
            *y += delta.y;
        });
    }

    fn snapped(&self, p: Vec2) -> Vec2 {
        let step = self.view.snap_step;
        Vec2::new(tools::snap(p.x, step), tools::snap(p.y, step))
    }

    /// Applies the current tool at world point `p` (the robot preview puts the robot's
    /// frame at the world origin, so world and robot coordinates agree).
    fn use_tool(&mut self, p: Vec2, now: f64) {
        let (tools::Tool::Joint, Some(Selection::Robot(robot))) =
            (self.view.tool, self.selection.clone())
        else {
            return;
        };
        let p = self.snapped(p);
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

    /// A new placement's reference point: its box in free space nearest the view's centre.
    fn free_spot_in(&self, scene: &str, item: Aabb) -> Vec2 {
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
        let copied = match item {
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
        self.put_in_scene(&scene, copied, spot, "add to scene", now);
    }

    /// Adds a scene robot or scene body to `scene` with its origin at `spot`.
    fn put_in_scene(&mut self, scene: &str, item: Copied, spot: Vec2, key: &str, now: f64) {
        let mut draft = self.doc.model().clone();
        let Some(placed_in) = draft.scene_mut(scene) else {
            return;
        };
        match item {
            Copied::SceneRobot(mut r) => {
                (r.x, r.y) = (spot.x, spot.y);
                placed_in.robots.push(r);
            }
            Copied::SceneBody(mut b) => {
                let aliases: Vec<String> =
                    placed_in.bodies.iter().map(|b| b.alias.clone()).collect();
                b.alias = unique(&aliases, &b.alias);
                (b.x, b.y) = (spot.x, spot.y);
                placed_in.bodies.push(b);
            }
            Copied::RobotBody(_) => return,
        }
        self.commit(draft, key, now);
    }

    /// The placement behind the followed body at step 0, as it would be copied.
    fn selected_placement(&self) -> Option<(Copied, Owner)> {
        let index = self.followed.filter(|_| self.runner.editing())?;
        let (owner, _) = self.owner(index)?;
        let model = self.doc.model();
        let copied = match (&self.selection, owner) {
            (Some(Selection::Scene(n)), Owner::SceneBody(k)) => {
                Copied::SceneBody(model.scene(n)?.bodies.get(k)?.clone())
            }
            (Some(Selection::Scene(n)), Owner::SceneRobot(k)) => {
                Copied::SceneRobot(model.scene(n)?.robots.get(k)?.clone())
            }
            (Some(Selection::Robot(n)), Owner::RobotBody(k)) => {
                Copied::RobotBody(model.robot(n)?.bodies.get(k)?.clone())
            }
            _ => return None,
        };
        Some((copied, owner))
    }

    /// Removes the placement behind the followed body at step 0 (a robot body with its
    /// joints); false when no placement is selected.
    fn remove_placement(&mut self, now: f64) -> bool {
        let Some((_, owner)) = self.selected_placement() else {
            return false;
        };
        let mut draft = self.doc.model().clone();
        match (&self.selection, owner) {
            (Some(Selection::Scene(n)), Owner::SceneBody(k)) => {
                if let Some(s) = draft.scene_mut(n) {
                    s.bodies.remove(k);
                }
            }
            (Some(Selection::Scene(n)), Owner::SceneRobot(k)) => {
                if let Some(s) = draft.scene_mut(n) {
                    s.robots.remove(k);
                }
            }
            (Some(Selection::Robot(n)), Owner::RobotBody(k)) => {
                if let Some(r) = draft.robot_mut(n) {
                    let alias = r.bodies.remove(k).placement.alias;
                    r.joints.retain(|j| j.body_a != alias && j.body_b != alias);
                }
            }
            _ => return false,
        }
        self.followed = None;
        self.commit(draft, "remove placement", now);
        true
    }

    /// Pastes the copied placement: into a scene in free space at the view's centre, into
    /// a robot beside where it was copied from.
    fn paste(&mut self, now: f64) {
        let Some(copied) = self.copied.clone() else {
            return;
        };
        match (self.selection.clone(), copied) {
            (
                Some(Selection::Scene(scene)),
                item @ (Copied::SceneBody(_) | Copied::SceneRobot(_)),
            ) => {
                let one = match &item {
                    Copied::SceneRobot(r) => preview(self.doc.model(), Some(&r.source), None),
                    Copied::SceneBody(b) => preview(self.doc.model(), None, Some(&b.source)),
                    Copied::RobotBody(_) => return,
                };
                let spot = self.free_spot_in(&scene, preview_box(&one));
                self.put_in_scene(&scene, item, spot, "paste", now);
            }
            (Some(Selection::Robot(robot)), Copied::RobotBody(mut body)) => {
                let mut draft = self.doc.model().clone();
                let Some(r) = draft.robot_mut(&robot) else {
                    return;
                };
                let aliases: Vec<String> =
                    r.bodies.iter().map(|b| b.placement.alias.clone()).collect();
                body.placement.alias = unique(&aliases, &body.placement.alias);
                body.placement.x += 20.0;
                body.placement.y += 20.0;
                r.bodies.push(body);
                self.commit(draft, "paste", now);
            }
            _ => self.complain(
                "paste a scene's robot or body into a scene, a robot's body into a robot".into(),
            ),
        }
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
