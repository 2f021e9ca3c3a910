//! The scene inspector: gravity, friction, the step and the solver, its robots and bodies.

use super::NewPlacement;
use super::fields::{Edit, name_field, pick, placement_fields};
use crate::model::{Placement, Scene};
use egui::{DragValue, Ui};
use pe::ContactSolver;

/// The names a placement may take its source from.
pub struct Sources<'a> {
    pub bodies: &'a [String],
    pub robots: &'a [String],
}

pub fn ui(
    ui: &mut Ui,
    name: &str,
    scene: &mut Scene,
    sources: Sources<'_>,
    name_buffer: &mut String,
    edit: &mut Edit,
) {
    if let Some(new) = name_field(ui, name, name_buffer) {
        edit.rename = Some(new);
    }
    settings(ui, scene, edit);
    robots(ui, scene, sources.robots, edit);
    bodies(ui, scene, sources.bodies, edit);
}

fn settings(ui: &mut Ui, scene: &mut Scene, edit: &mut Edit) {
    egui::Grid::new("scene fields")
        .num_columns(2)
        .show(ui, |ui| {
            let label = ui
                .label("gravitation")
                .on_hover_text("Along +y (down), in length units per s²");
            edit.touched(
                "g".into(),
                ui.add(DragValue::new(&mut scene.gravitation).speed(1.0))
                    .labelled_by(label.id)
                    .changed(),
            );
            ui.end_row();
            let label = ui
                .label("friction μ")
                .on_hover_text("Coulomb friction coefficient of every contact");
            edit.touched(
                "mu".into(),
                ui.add(
                    DragValue::new(&mut scene.friction)
                        .speed(0.01)
                        .range(0.0..=10.0),
                )
                .labelled_by(label.id)
                .changed(),
            );
            ui.end_row();
            let label = ui
                .label("timestep h")
                .on_hover_text("Seconds per step; a scene without one runs at 0.05 s");
            let mut h = scene.timestep();
            if ui
                .add(
                    DragValue::new(&mut h)
                        .speed(0.001)
                        .range(1e-4..=1.0)
                        .suffix(" s"),
                )
                .labelled_by(label.id)
                .changed()
            {
                scene.timestep = Some(h);
                edit.touched("h".into(), true);
            }
            ui.end_row();
            ui.label("solver").on_hover_text(
                "How this scene's contacts are solved (auto suits almost every scene)",
            );
            let current = scene
                .solver
                .clone()
                .unwrap_or_else(|| ContactSolver::default().name().to_string());
            egui::ComboBox::from_id_salt("scene solver")
                .selected_text(&current)
                .show_ui(ui, |ui| {
                    for s in ContactSolver::ALL {
                        if ui.selectable_label(current == s.name(), s.name()).clicked() {
                            scene.solver = Some(s.name().to_string());
                            edit.touched("solver".into(), true);
                        }
                    }
                })
                .response
                .on_hover_text("This scene's own contact solver, saved in its file");
            ui.end_row();
        });
}

fn robots(ui: &mut Ui, scene: &mut Scene, robot_names: &[String], edit: &mut Edit) {
    ui.strong("robots");
    let mut remove = None;
    for (i, r) in scene.robots.iter_mut().enumerate() {
        egui::CollapsingHeader::new(format!("{} #{i}", r.source.trim()))
            .id_salt(("scene robot", i))
            .show(ui, |ui| {
                let mut p = Placement {
                    source: r.source.clone(),
                    x: r.x,
                    y: r.y,
                    orientation: r.orientation,
                    velocity: r.velocity,
                    ..Placement::default()
                };
                placement_fields(ui, &mut p, robot_names, false, &format!("r{i}"), edit);
                (r.source, r.x, r.y, r.orientation, r.velocity) =
                    (p.source, p.x, p.y, p.orientation, p.velocity);
                if ui.button("Remove robot").clicked() {
                    remove = Some(i);
                }
            });
    }
    if let Some(i) = remove {
        scene.robots.remove(i);
        edit.touched("remove robot".into(), true);
    }
    if let Some(source) = pick(ui, "+ robot", robot_names) {
        edit.place = Some(NewPlacement::Robot(source));
    }
}

fn bodies(ui: &mut Ui, scene: &mut Scene, body_names: &[String], edit: &mut Edit) {
    ui.strong("bodies");
    let mut remove = None;
    for (i, b) in scene.bodies.iter_mut().enumerate() {
        egui::CollapsingHeader::new(format!("{} ({})", b.alias, b.source))
            .id_salt(("scene body", i))
            .show(ui, |ui| {
                placement_fields(ui, b, body_names, true, &format!("s{i}"), edit);
                if ui.button("Remove body").clicked() {
                    remove = Some(i);
                }
            });
    }
    if let Some(i) = remove {
        scene.bodies.remove(i);
        edit.touched("remove scene body".into(), true);
    }
    if let Some(source) = pick(ui, "+ body", body_names) {
        edit.place = Some(NewPlacement::Body(source));
    }
}
