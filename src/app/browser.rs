//! The database browser: scenes, robots and bodies to select, and buttons that create,
//! duplicate and delete them.

use super::document::ItemKind;
use super::{Command, Selection};
use crate::db::Delete;
use crate::model::Model;

pub fn ui(ui: &mut egui::Ui, model: &Model, selection: Option<&Selection>) -> Vec<Command> {
    let mut commands = Vec::new();
    ui.horizontal_wrapped(|ui| {
        ui.menu_button("New", |ui| {
            for kind in ItemKind::ALL {
                if ui.button(kind.name()).clicked() {
                    commands.push(Command::New(kind));
                }
            }
        })
        .response
        .on_hover_text("Create a body, robot or scene");
        if ui
            .add_enabled(selection.is_some(), egui::Button::new("Duplicate"))
            .on_hover_text("Copy the selected item under a new name (Ctrl+D)")
            .clicked()
        {
            commands.push(Command::Duplicate);
        }
        if ui
            .add_enabled(selection.is_some(), egui::Button::new("Delete"))
            .on_hover_text("Delete the selected item (refused while it is used; Delete)")
            .clicked()
        {
            commands.push(Command::Delete(Delete::IfUnused));
        }
    });
    ui.separator();
    egui::ScrollArea::vertical().show(ui, |ui| {
        let mut entry = |ui: &mut egui::Ui, item: Selection, text: String| {
            if ui
                .selectable_label(selection == Some(&item), text)
                .clicked()
            {
                commands.push(Command::Select(item));
            }
        };
        egui::CollapsingHeader::new(format!("Scenes ({})", model.scenes.len()))
            .default_open(true)
            .show(ui, |ui| {
                for s in &model.scenes {
                    entry(ui, Selection::Scene(s.name.clone()), s.name.clone());
                }
            });
        egui::CollapsingHeader::new(format!("Robots ({})", model.robots.len()))
            .default_open(true)
            .show(ui, |ui| {
                for r in &model.robots {
                    let text = format!(
                        "{} · {} bodies, {} joints",
                        r.name,
                        r.bodies.len(),
                        r.joints.len()
                    );
                    entry(ui, Selection::Robot(r.name.clone()), text);
                }
            });
        egui::CollapsingHeader::new(format!("Bodies ({})", model.bodies.len()))
            .default_open(false)
            .show(ui, |ui| {
                for b in &model.bodies {
                    let kind = if b.density == 0.0 {
                        "static"
                    } else {
                        "dynamic"
                    };
                    entry(
                        ui,
                        Selection::Body(b.name.clone()),
                        format!("{} · {kind}", b.name),
                    );
                }
            });
    });
    commands
}
