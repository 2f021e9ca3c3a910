//! The property inspector: every field of the selected body, robot or scene, editable,
//! and read-outs of the running simulation. Widgets edit a draft of the model; the panel
//! returns it as one command, which the app turns into one undoable edit.

mod body;
pub mod fields;
mod robot;
mod scene;

use super::{Command, Selection};
use crate::model::Model;
use crate::sim::Simulation;
use fields::{Edit, MotorUnits, width_along_x};

/// What the scene inspector asks to place; the app picks where.
#[derive(Debug, Clone, PartialEq)]
pub enum NewPlacement {
    Robot(String),
    Body(String),
}

#[derive(Debug, Default)]
pub struct Inspector {
    /// The selection's name as it is being typed (applied on Enter).
    name_buffer: String,
    /// The selection `name_buffer` was filled for.
    named: Option<Selection>,
}

/// What the inspector shows besides the selected item.
pub struct Running<'a> {
    pub sim: Option<&'a Simulation>,
    /// The body followed (index into `sim.bodies`).
    pub followed: Option<usize>,
    /// How many placements are selected on the canvas.
    pub items_picked: usize,
}

impl Inspector {
    /// Shows the selection's name again in the name field (after a refused rename).
    pub fn forget_typed_name(&mut self) {
        self.named = None;
    }

    pub fn ui(
        &mut self,
        ui: &mut egui::Ui,
        model: &Model,
        selection: Option<&Selection>,
        running: Running<'_>,
    ) -> Vec<Command> {
        let mut commands = Vec::new();
        egui::ScrollArea::vertical().show(ui, |ui| {
            ui.heading("Inspector");
            let Some(selection) = selection else {
                ui.label("Select a scene, robot or body.");
                return;
            };
            if self.named.as_ref() != Some(selection) {
                self.name_buffer = name_of(selection).to_string();
                self.named = Some(selection.clone());
            }
            let mut draft = model.clone();
            let edit = self.item(ui, selection, &mut draft);
            if let Some(new) = edit.rename {
                commands.push(Command::Rename(selection.clone(), new));
            } else if let Some(item) = edit.place {
                commands.push(Command::PlaceInScene(item));
            } else if let Some(key) = edit.key {
                commands.push(Command::Commit { draft, key });
            }
            if !matches!(selection, Selection::Body(_)) {
                ui.separator();
                if running.items_picked > 1 {
                    ui.strong(format!("{} items selected", running.items_picked))
                        .on_hover_text(
                            "Delete, Cut, Copy, Paste, Duplicate, the arrow keys, Q / E and a \
                             drag apply to all of them; the body below is the one followed",
                        );
                }
                followed_body(ui, running.sim, running.followed);
            }
        });
        commands
    }

    fn item(&mut self, ui: &mut egui::Ui, selection: &Selection, draft: &mut Model) -> Edit {
        let mut edit = Edit::default();
        let body_names: Vec<String> = draft.bodies.iter().map(|b| b.name.clone()).collect();
        let robot_names: Vec<String> = draft.robots.iter().map(|r| r.name.clone()).collect();
        let buffer = &mut self.name_buffer;
        match selection {
            Selection::Body(name) => {
                if let Some(b) = draft.body_mut(name) {
                    body::ui(ui, name, b, buffer, &mut edit);
                }
            }
            Selection::Robot(name) => {
                let last_width = draft
                    .robot(name)
                    .and_then(|r| r.bodies.last())
                    .and_then(|b| draft.body(&b.placement.source))
                    .map_or(0.0, width_along_x);
                let units = MotorUnits {
                    step: step_of_scenes_using(draft, name),
                };
                if let Some(r) = draft.robot_mut(name) {
                    let cx = robot::Context {
                        name,
                        body_names: &body_names,
                        last_width,
                        units,
                    };
                    robot::ui(ui, r, cx, buffer, &mut edit);
                }
            }
            Selection::Scene(name) => {
                if let Some(s) = draft.scene_mut(name) {
                    let sources = scene::Sources {
                        bodies: &body_names,
                        robots: &robot_names,
                    };
                    scene::ui(ui, name, s, sources, buffer, &mut edit);
                }
            }
        }
        edit
    }
}

fn name_of(selection: &Selection) -> &str {
    match selection {
        Selection::Scene(n) | Selection::Robot(n) | Selection::Body(n) => n,
    }
}

/// The step h of the scenes that place robot `name`, if they agree on one.
fn step_of_scenes_using(model: &Model, name: &str) -> Option<f64> {
    let mut steps = model
        .scenes
        .iter()
        .filter(|s| {
            s.robots
                .iter()
                .any(|r| crate::model::same_name(&r.source, name))
        })
        .map(|s| s.timestep());
    let first = steps.next()?;
    steps.all(|h| h == first).then_some(first)
}

/// The followed body's mass properties and state.
fn followed_body(ui: &mut egui::Ui, sim: Option<&Simulation>, followed: Option<usize>) {
    let (Some(sim), Some(i)) = (sim, followed) else {
        ui.label("Click a body on the canvas to follow it.");
        return;
    };
    let Some((id, body)) = sim
        .bodies
        .get(i)
        .and_then(|b| sim.world.body(b.handle).map(|body| (b, body)))
    else {
        return;
    };
    let o = body.origin();
    let v = body.velocity_at(o);
    egui::Grid::new("selected").num_columns(2).show(ui, |ui| {
        for (k, val) in [
            ("body", id.id.clone()),
            ("mass", format!("{:.4}", body.mass())),
            ("inertia", format!("{:.5e}", body.inertia())),
            ("x, y", format!("{:.3}, {:.3} px", o.x, o.y)),
            ("angle", format!("{:.4} rad", body.angle)),
            ("vx, vy", format!("{:.3}, {:.3} px/s", v.x, v.y)),
            ("ω", format!("{:.4} rad/s", body.angular_velocity)),
        ] {
            ui.label(k);
            ui.label(val);
            ui.end_row();
        }
    });
}

/// How the last step solved each island of touching or pinned bodies (issue 50): the
/// method, the size of its system and whether the exact solve ran out of pivots.
pub fn islands(ui: &mut egui::Ui, sim: Option<&Simulation>) {
    let reports = sim.map_or(&[][..], |s| s.world.island_reports());
    ui.strong(format!(
        "physics islands in the last step: {}",
        reports.len()
    ))
    .on_hover_text(
        "Bodies that touch or are pinned together are solved together. Pivoting: the exact \
             LCP; GaussSeidel: row by row above the size limit; Soft…: the soft step. Over \
             budget: the exact solve stopped at its pivot budget and kept its last round.",
    );
    if reports.is_empty() {
        return;
    }
    egui::Grid::new("islands")
        .num_columns(6)
        .striped(true)
        .show(ui, |ui| {
            for title in ["method", "contacts", "joints", "rows", "pivots", "budget"] {
                ui.strong(title);
            }
            ui.end_row();
            for r in reports.iter().take(50) {
                ui.label(format!("{:?}", r.method));
                ui.label(r.contacts.to_string());
                ui.label(r.joints.to_string());
                ui.label(r.rows.to_string());
                ui.label(r.pivots.to_string());
                if r.over_budget {
                    ui.colored_label(egui::Color32::LIGHT_RED, "over");
                } else {
                    ui.label("ok");
                }
                ui.end_row();
            }
        });
    if reports.len() > 50 {
        ui.label(format!("… and {} more", reports.len() - 50));
    }
}
