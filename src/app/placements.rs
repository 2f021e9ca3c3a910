//! The placements selected on the canvas and the edits that apply to all of them at once:
//! move, nudge, turn, delete, copy, cut, paste and duplicate, each one undoable step.
//! The canvas selects simulated bodies; an edit changes the placements behind them (a
//! scene's body, a whole robot in a scene, a robot's body), each once.

use super::{Copied, RoboSimApp, Selection, document::next_in_count, placing};
use crate::model::{JointDef, Model, Robot, Scene, same_name};
use crate::sim::PlacedBy;
use pe::{Aabb, Vec2};

/// Where a simulated body's placement is in the model. Ordered by kind, then index, so
/// that removing in reverse order never shifts an index still to be removed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub(super) enum Owner {
    SceneBody(usize),
    SceneRobot(usize),
    RobotBody(usize),
}

/// Placements copied with Ctrl+C, and the world box around their bodies when copied: a
/// paste moves the whole group by one offset, so it keeps its shape. Copied robot bodies
/// bring the joints between them.
#[derive(Debug, Clone, PartialEq)]
pub struct Clipboard {
    pub items: Vec<Copied>,
    pub bounds: Aabb,
    pub joints: Vec<JointDef>,
}

/// The name the clipboard's record goes by in its text.
const CLIPBOARD_RECORD: &str = "robosim clipboard";

impl Clipboard {
    /// The placements as the text of a robots.xml (robot bodies and their joints) or a
    /// scenes.xml (robots and bodies placed in a scene), one record named
    /// "robosim clipboard" carrying the box in attributes: what Ctrl+C puts on the
    /// system clipboard, so that Ctrl+V works there and in another window of the app.
    pub fn to_text(&self) -> String {
        let b = self.bounds;
        let extra: Vec<(String, String)> = [
            ("minX", b.min.x),
            ("minY", b.min.y),
            ("maxX", b.max.x),
            ("maxY", b.max.y),
        ]
        .iter()
        .map(|(k, v)| (k.to_string(), crate::db::write::number(*v)))
        .collect();
        let robot_bodies: Vec<_> = self
            .items
            .iter()
            .filter_map(|c| match c {
                Copied::RobotBody(b) => Some(b.clone()),
                _ => None,
            })
            .collect();
        if !robot_bodies.is_empty() {
            let robot = Robot {
                name: CLIPBOARD_RECORD.into(),
                bodies: robot_bodies,
                joints: self.joints.clone(),
                extra,
                ..Default::default()
            };
            return crate::db::write::robots(&[robot]);
        }
        let mut scene = Scene {
            name: CLIPBOARD_RECORD.into(),
            extra,
            ..Default::default()
        };
        for c in &self.items {
            match c {
                Copied::SceneRobot(r) => scene.robots.push(r.clone()),
                Copied::SceneBody(b) => scene.bodies.push(b.clone()),
                Copied::RobotBody(_) => {}
            }
        }
        crate::db::write::scenes(&[scene])
    }

    /// The placements of a text `to_text` wrote (in this window or another); `None` for
    /// any other text.
    pub fn from_text(text: &str) -> Option<Self> {
        let (robots, scenes) = crate::db::records_from_text(text)?;
        let bounds_in = |extra: &[(String, String)]| {
            let get = |key: &str| {
                let value = extra.iter().find(|(k, _)| k == key)?;
                value.1.trim().parse::<f64>().ok().filter(|v| v.is_finite())
            };
            Some(Aabb {
                min: Vec2::new(get("minX")?, get("minY")?),
                max: Vec2::new(get("maxX")?, get("maxY")?),
            })
        };
        if let Some(r) = robots.into_iter().find(|r| r.name == CLIPBOARD_RECORD) {
            return Some(Self {
                bounds: bounds_in(&r.extra)?,
                items: r.bodies.into_iter().map(Copied::RobotBody).collect(),
                joints: r.joints,
            });
        }
        let s = scenes.into_iter().find(|s| s.name == CLIPBOARD_RECORD)?;
        let robots = s.robots.into_iter().map(Copied::SceneRobot);
        let bodies = s.bodies.into_iter().map(Copied::SceneBody);
        Some(Self {
            bounds: bounds_in(&s.extra)?,
            items: robots.chain(bodies).collect(),
            joints: Vec::new(),
        })
    }
}

impl Copied {
    fn position(&self) -> Vec2 {
        match self {
            Copied::SceneRobot(r) => Vec2::new(r.x, r.y),
            Copied::SceneBody(b) => Vec2::new(b.x, b.y),
            Copied::RobotBody(b) => Vec2::new(b.placement.x, b.placement.y),
        }
    }
}

impl RoboSimApp {
    /// Where simulated body `index`'s placement is in the model.
    pub(super) fn owner(&self, index: usize) -> Option<Owner> {
        let body = self.runner.sim()?.bodies.get(index)?;
        Some(match (&self.selection, body.placed_by) {
            (Some(Selection::Scene(_)), PlacedBy::SceneBody(k)) => Owner::SceneBody(k),
            (Some(Selection::Scene(_)), PlacedBy::RobotBody { robot, .. }) => {
                Owner::SceneRobot(robot)
            }
            // The robot preview places the robot alone at the origin.
            (Some(Selection::Robot(_)), PlacedBy::RobotBody { body, .. }) => Owner::RobotBody(body),
            _ => return None,
        })
    }

    /// The simulated bodies that `owners` place.
    fn bodies_of(&self, owners: &[Owner]) -> Vec<usize> {
        let count = self.runner.sim().map_or(0, |s| s.bodies.len());
        (0..count)
            .filter(|&i| self.owner(i).is_some_and(|o| owners.contains(&o)))
            .collect()
    }

    /// Follows `body` (the inspector and the plots) and selects the placement behind it
    /// alone: all of a robot's bodies in a scene, since a drag moves the whole robot.
    pub(super) fn follow(&mut self, body: Option<usize>) {
        self.followed = body;
        self.picked = match body.and_then(|i| self.owner(i)) {
            Some(owner) => self.bodies_of(&[owner]),
            None => body.into_iter().collect(),
        };
        self.runner.show_in_plots(body);
    }

    /// Selects the placements behind `bodies` (a rubber band); with `add`, besides those
    /// already selected.
    pub(super) fn pick(&mut self, bodies: &[usize], add: bool) {
        let mut owners = if add {
            self.picked_owners()
        } else {
            Vec::new()
        };
        for o in bodies.iter().filter_map(|&i| self.owner(i)) {
            if !owners.contains(&o) {
                owners.push(o);
            }
        }
        self.pick_owners(&owners);
    }

    /// Shift+click: adds the placement behind `body` to the selection, or takes it out.
    pub(super) fn toggle_pick(&mut self, body: usize) {
        let Some(owner) = self.owner(body) else {
            return;
        };
        let mut owners = self.picked_owners();
        match owners.iter().position(|&o| o == owner) {
            Some(k) => {
                owners.remove(k);
            }
            None => owners.push(owner),
        }
        self.pick_owners(&owners);
    }

    /// Selects `owners`; the followed body stays if it is among them, else the first.
    pub(super) fn pick_owners(&mut self, owners: &[Owner]) {
        self.picked = self.bodies_of(owners);
        if !self.followed.is_some_and(|f| self.picked.contains(&f)) {
            self.followed = self.picked.first().copied();
            self.runner.show_in_plots(self.followed);
        }
    }

    /// The selected placements, each once, in model order.
    pub(super) fn picked_owners(&self) -> Vec<Owner> {
        let mut owners: Vec<Owner> = self.picked.iter().filter_map(|&i| self.owner(i)).collect();
        owners.sort();
        owners.dedup();
        owners
    }

    /// The selected placements an edit may change: only at step 0.
    fn editable_owners(&self) -> Vec<Owner> {
        if self.runner.editing() {
            self.picked_owners()
        } else {
            Vec::new()
        }
    }

    /// The placements an edit of body `index` changes: the whole selection if the body is
    /// in it, else its own placement.
    fn owners_moved_with(&self, index: usize) -> Vec<Owner> {
        if self.picked.contains(&index) {
            self.picked_owners()
        } else {
            self.owner(index).into_iter().collect()
        }
    }

    /// Applies `edit` to (x, y, orientation) of each of `owners` as one undoable edit.
    fn edit_placements(
        &mut self,
        owners: &[Owner],
        key: &str,
        now: f64,
        mut edit: impl FnMut(&mut f64, &mut f64, &mut f64),
    ) {
        let mut draft = self.doc.model().clone();
        for &owner in owners {
            if let Some((x, y, o)) = placement_mut(&mut draft, self.selection.as_ref(), owner) {
                edit(x, y, o);
            }
        }
        self.commit(draft, key, now);
    }

    /// Moves the placements that move with simulated body `index` so that its reference
    /// point goes to `wanted` (snapped to the grid); the others keep their offsets to it.
    pub(super) fn move_placement(&mut self, index: usize, wanted: Vec2, now: f64) {
        let Some((origin, id)) = self.runner.sim().and_then(|s| {
            let b = s.bodies.get(index)?;
            Some((s.world.body(b.handle)?.origin(), b.id.clone()))
        }) else {
            return;
        };
        let delta = self.snapped(wanted) - origin;
        if delta.norm() < 1e-12 {
            return;
        }
        let owners = self.owners_moved_with(index);
        self.edit_placements(&owners, &format!("place {id}"), now, |x, y, _| {
            *x += delta.x;
            *y += delta.y;
        });
    }

    /// Moves the selected placements by `delta` (arrow keys at step 0).
    pub(super) fn nudge(&mut self, delta: Vec2, now: f64) {
        let owners = self.editable_owners();
        self.edit_placements(&owners, "nudge", now, |x, y, _| {
            *x += delta.x;
            *y += delta.y;
        });
    }

    /// Turns the placements that move with body `index` by `angle` (rad) about the mean
    /// of their reference points: one placement turns about its own.
    pub(super) fn turn_placement(&mut self, index: usize, angle: f64, now: f64) {
        let owners = self.owners_moved_with(index);
        let model = self.doc.model();
        let positions: Vec<Vec2> = owners
            .iter()
            .filter_map(|&o| copied(model, self.selection.as_ref(), o))
            .map(|c| c.position())
            .collect();
        if positions.is_empty() {
            return;
        }
        let pivot = positions.iter().sum::<Vec2>() / positions.len() as f64;
        let id = self
            .runner
            .sim()
            .and_then(|s| s.bodies.get(index))
            .map_or(String::new(), |b| b.id.clone());
        let (s, c) = angle.sin_cos();
        // p' = pivot + R(angle)·(p − pivot), the same rotation `model::compose` applies.
        self.edit_placements(&owners, &format!("place {id}"), now, |x, y, o| {
            let d = Vec2::new(*x, *y) - pivot;
            *x = pivot.x + c * d.x - s * d.y;
            *y = pivot.y + s * d.x + c * d.y;
            *o += angle;
        });
    }

    /// The selected placements at step 0 as they would be copied, with their box.
    pub(super) fn copy_picked(&self) -> Option<Clipboard> {
        let owners = self.editable_owners();
        let model = self.doc.model();
        let items: Vec<Copied> = owners
            .iter()
            .filter_map(|&o| copied(model, self.selection.as_ref(), o))
            .collect();
        let sim = self.runner.sim()?;
        let bounds = placing::bounds_of(
            self.picked
                .iter()
                .filter_map(|&i| sim.world.body(sim.bodies.get(i)?.handle))
                .flat_map(|b| b.world_vertices().collect::<Vec<_>>()),
        )?;
        let joints = match (&self.selection, items.first()) {
            (Some(Selection::Robot(n)), Some(Copied::RobotBody(_))) => {
                let copied = |alias: &str| {
                    items.iter().any(
                        |c| matches!(c, Copied::RobotBody(b) if same_name(&b.placement.alias, alias)),
                    )
                };
                model.robot(n).map_or(Vec::new(), |r| {
                    r.joints
                        .iter()
                        .filter(|j| copied(&j.body_a) && copied(&j.body_b))
                        .cloned()
                        .collect()
                })
            }
            _ => Vec::new(),
        };
        (!items.is_empty()).then_some(Clipboard {
            items,
            bounds,
            joints,
        })
    }

    /// Removes the selected placements at step 0 (a robot body with its joints) as one
    /// edit; false when none is selected.
    pub(super) fn remove_picked(&mut self, now: f64) -> bool {
        let owners = self.editable_owners();
        if owners.is_empty() {
            return false;
        }
        let mut draft = self.doc.model().clone();
        for &owner in owners.iter().rev() {
            remove(&mut draft, self.selection.as_ref(), owner);
        }
        self.followed = None;
        self.picked.clear();
        let what = match owners.len() {
            1 => "removed 1 placement".to_string(),
            n => format!("removed {n} placements"),
        };
        self.inform(what);
        self.commit(draft, "remove placement", now);
        true
    }

    /// Pastes `clip` and selects what it pasted: into a scene moved as a group to free
    /// space nearest the view's centre, into a robot beside where it was copied from.
    pub(super) fn paste_clipboard(&mut self, clip: Clipboard, key: &str, now: f64) {
        let robot_bodies = clip
            .items
            .iter()
            .filter(|c| matches!(c, Copied::RobotBody(_)))
            .count();
        let mut draft = self.doc.model().clone();
        let pasted = match self.selection.clone() {
            Some(Selection::Scene(scene)) if robot_bodies == 0 => {
                // The copied box where it was in the world: the free spot is an offset.
                let delta = self.free_spot_in(&scene, clip.bounds);
                draft
                    .scene_mut(&scene)
                    .map(|s| put_in_scene(s, clip.items, delta))
            }
            Some(Selection::Robot(robot)) if robot_bodies == clip.items.len() => draft
                .robot_mut(&robot)
                .map(|r| paste_into_robot(r, clip.items, clip.joints, clip.bounds)),
            _ => {
                return self.complain(
                    "paste a scene's robots and bodies into a scene, a robot's bodies into a robot"
                        .into(),
                );
            }
        };
        let Some(pasted) = pasted else {
            return;
        };
        self.commit(draft, key, now);
        self.pick_owners(&pasted);
    }
}

/// Adds `items` (robot bodies, copied from within `bounds`) to `robot` beside where they
/// were copied from, clear of them to the right, each under an alias not yet taken, with
/// `joints` between them renamed to match; returns where they went. A joint's anchor is
/// relative to its bodyA, which moves with it.
fn paste_into_robot(
    robot: &mut Robot,
    items: Vec<Copied>,
    joints: Vec<JointDef>,
    bounds: pe::Aabb,
) -> Vec<Owner> {
    // The copy's width and a tenth more: beside, not on top (a pasted copy overlapping
    // its original is thrown apart once run).
    let width = bounds.max.x - bounds.min.x;
    let shift = (1.1 * width).max(20.0).ceil();
    let first = robot.bodies.len();
    let mut renamed: Vec<(String, String)> = Vec::new();
    for item in items {
        let Copied::RobotBody(mut body) = item else {
            continue;
        };
        let aliases: Vec<String> = robot
            .bodies
            .iter()
            .map(|b| b.placement.alias.clone())
            .collect();
        let alias = next_in_count(&aliases, &body.placement.alias);
        renamed.push((body.placement.alias.clone(), alias.clone()));
        body.placement.alias = alias;
        body.placement.x += shift;
        robot.bodies.push(body);
    }
    let new_alias = |old: &str| {
        renamed
            .iter()
            .find(|(o, _)| same_name(o, old))
            .map(|(_, n)| n.clone())
    };
    for mut joint in joints {
        if let (Some(a), Some(b)) = (new_alias(&joint.body_a), new_alias(&joint.body_b)) {
            (joint.body_a, joint.body_b) = (a, b);
            robot.joints.push(joint);
        }
    }
    (first..robot.bodies.len()).map(Owner::RobotBody).collect()
}

/// Adds `items` (scene robots and scene bodies) to `scene` moved by `delta`, a body under
/// an alias not yet taken; returns where they went.
pub(super) fn put_in_scene(scene: &mut Scene, items: Vec<Copied>, delta: Vec2) -> Vec<Owner> {
    let mut placed = Vec::new();
    for item in items {
        match item {
            Copied::SceneRobot(mut r) => {
                (r.x, r.y) = (r.x + delta.x, r.y + delta.y);
                scene.robots.push(r);
                placed.push(Owner::SceneRobot(scene.robots.len() - 1));
            }
            Copied::SceneBody(mut b) => {
                let aliases: Vec<String> = scene.bodies.iter().map(|b| b.alias.clone()).collect();
                b.alias = next_in_count(&aliases, &b.alias);
                (b.x, b.y) = (b.x + delta.x, b.y + delta.y);
                scene.bodies.push(b);
                placed.push(Owner::SceneBody(scene.bodies.len() - 1));
            }
            Copied::RobotBody(_) => {}
        }
    }
    placed
}

/// The placement `owner` of what `shown` shows, as it would be copied.
fn copied(model: &Model, shown: Option<&Selection>, owner: Owner) -> Option<Copied> {
    Some(match (shown?, owner) {
        (Selection::Scene(n), Owner::SceneBody(k)) => {
            Copied::SceneBody(model.scene(n)?.bodies.get(k)?.clone())
        }
        (Selection::Scene(n), Owner::SceneRobot(k)) => {
            Copied::SceneRobot(model.scene(n)?.robots.get(k)?.clone())
        }
        (Selection::Robot(n), Owner::RobotBody(k)) => {
            Copied::RobotBody(model.robot(n)?.bodies.get(k)?.clone())
        }
        _ => return None,
    })
}

/// (x, y, orientation) of placement `owner` of what `shown` shows.
fn placement_mut<'m>(
    model: &'m mut Model,
    shown: Option<&Selection>,
    owner: Owner,
) -> Option<(&'m mut f64, &'m mut f64, &'m mut f64)> {
    match (shown?, owner) {
        (Selection::Scene(n), Owner::SceneBody(k)) => model
            .scene_mut(n)?
            .bodies
            .get_mut(k)
            .map(|b| (&mut b.x, &mut b.y, &mut b.orientation)),
        (Selection::Scene(n), Owner::SceneRobot(k)) => model
            .scene_mut(n)?
            .robots
            .get_mut(k)
            .map(|r| (&mut r.x, &mut r.y, &mut r.orientation)),
        (Selection::Robot(n), Owner::RobotBody(k)) => {
            model.robot_mut(n)?.bodies.get_mut(k).map(|b| {
                let p = &mut b.placement;
                (&mut p.x, &mut p.y, &mut p.orientation)
            })
        }
        _ => None,
    }
}

/// Removes placement `owner` of what `shown` shows: a robot's body with its joints.
fn remove(model: &mut Model, shown: Option<&Selection>, owner: Owner) {
    match (shown, owner) {
        (Some(Selection::Scene(n)), Owner::SceneBody(k)) => {
            if let Some(s) = model.scene_mut(n).filter(|s| k < s.bodies.len()) {
                s.bodies.remove(k);
            }
        }
        (Some(Selection::Scene(n)), Owner::SceneRobot(k)) => {
            if let Some(s) = model.scene_mut(n).filter(|s| k < s.robots.len()) {
                s.robots.remove(k);
            }
        }
        (Some(Selection::Robot(n)), Owner::RobotBody(k)) => {
            if let Some(r) = model.robot_mut(n).filter(|r| k < r.bodies.len()) {
                let alias = r.bodies.remove(k).placement.alias;
                r.joints.retain(|j| j.body_a != alias && j.body_b != alias);
            }
        }
        _ => {}
    }
}
