//! The body inspector: material, the vertex list, shape tools and mass properties.

use super::fields::{Edit, name_field};
use crate::model::BodyDef;
use egui::{DragValue, Ui};

/// Edits body `name` of the draft model through `body`.
pub fn ui(ui: &mut Ui, name: &str, body: &mut BodyDef, name_buffer: &mut String, edit: &mut Edit) {
    if let Some(new) = name_field(ui, name, name_buffer) {
        edit.rename = Some(new);
    }
    material(ui, body, edit);
    vertex_list(ui, body, edit);
    shape_tools(ui, body, edit);
    mass_properties(ui, body);
}

fn material(ui: &mut Ui, body: &mut BodyDef, edit: &mut Edit) {
    egui::Grid::new("body fields")
        .num_columns(2)
        .show(ui, |ui| {
            let label = ui
                .label("density")
                .on_hover_text("Mass per unit area; 0 makes the body static");
            edit.touched(
                "density".into(),
                ui.add(
                    DragValue::new(&mut body.density)
                        .speed(0.01)
                        .range(0.0..=f64::MAX),
                )
                .labelled_by(label.id)
                .changed(),
            );
            ui.end_row();
            let label = ui
                .label("cor")
                .on_hover_text("Coefficient of restitution e in [0, 1]");
            edit.touched(
                "cor".into(),
                ui.add(DragValue::new(&mut body.cor).speed(0.01).range(0.0..=1.0))
                    .labelled_by(label.id)
                    .changed(),
            );
            ui.end_row();
            ui.label("friction")
                .on_hover_text("Override the scene's μ for this body");
            ui.horizontal(|ui| {
                let mut own = body.friction.is_some();
                if ui.checkbox(&mut own, "").changed() {
                    body.friction = own.then_some(0.5);
                    edit.touched("friction on".into(), true);
                }
                if let Some(mu) = body.friction.as_mut() {
                    edit.touched(
                        "friction".into(),
                        ui.add(DragValue::new(mu).speed(0.01).range(0.0..=10.0))
                            .changed(),
                    );
                }
            });
            ui.end_row();
        });
}

fn vertex_list(ui: &mut Ui, body: &mut BodyDef, edit: &mut Edit) {
    ui.label("vertices (relative to the body's origin)")
        .on_hover_text("The outline, in order; drag them on the canvas or type them here");
    let mut remove = None;
    egui::Grid::new("vertices").num_columns(3).show(ui, |ui| {
        for (i, v) in body.vertices.iter_mut().enumerate() {
            edit.touched(
                format!("v{i}x"),
                ui.add(DragValue::new(&mut v[0]).speed(0.5).prefix("x "))
                    .changed(),
            );
            edit.touched(
                format!("v{i}y"),
                ui.add(DragValue::new(&mut v[1]).speed(0.5).prefix("y "))
                    .changed(),
            );
            if ui
                .small_button("×")
                .on_hover_text("Remove this vertex")
                .clicked()
            {
                remove = Some(i);
            }
            ui.end_row();
        }
    });
    if let Some(i) = remove {
        body.vertices.remove(i);
        edit.touched("remove vertex".into(), true);
    }
    ui.horizontal(|ui| {
        if ui
            .button("+ vertex")
            .on_hover_text("Add a vertex halfway along the last edge")
            .clicked()
        {
            let n = body.vertices.len();
            let new = match n {
                0 => [0.0, 0.0],
                1 => [body.vertices[0][0] + 20.0, body.vertices[0][1]],
                _ => {
                    let (a, b) = (body.vertices[n - 1], body.vertices[0]);
                    [(a[0] + b[0]) / 2.0 + 1.0, (a[1] + b[1]) / 2.0 + 1.0]
                }
            };
            body.vertices.push(new);
            edit.touched("add vertex".into(), true);
        }
        if ui
            .button("Convex hull")
            .on_hover_text("Replace the vertices by their convex hull")
            .clicked()
        {
            let points: Vec<pe::Vec2> = body
                .vertices
                .iter()
                .map(|v| pe::Vec2::new(v[0], v[1]))
                .collect();
            body.vertices = pe::convex_hull(&points)
                .iter()
                .map(|p| [p.x, p.y])
                .collect();
            edit.touched("hull".into(), true);
        }
    });
}

fn shape_tools(ui: &mut Ui, body: &mut BodyDef, edit: &mut Edit) {
    // Shape tools: sizes are remembered per session in egui's memory.
    let size_id = ui.make_persistent_id("shape tool sizes");
    let (mut w, mut h, mut sides, mut radius) = ui
        .data(|d| d.get_temp::<(f64, f64, u32, f64)>(size_id))
        .unwrap_or((40.0, 20.0, 6, 20.0));
    ui.horizontal(|ui| {
        if ui
            .button("Rectangle")
            .on_hover_text("Replace the shape by a w × h rectangle centred on the origin")
            .clicked()
        {
            body.vertices = vec![
                [-w / 2.0, -h / 2.0],
                [w / 2.0, -h / 2.0],
                [w / 2.0, h / 2.0],
                [-w / 2.0, h / 2.0],
            ];
            edit.touched("shape".into(), true);
        }
        size_field(ui, "w", &mut w, "Rectangle width");
        size_field(ui, "h", &mut h, "Rectangle height");
    });
    ui.horizontal(|ui| {
        if ui
            .button("Regular polygon")
            .on_hover_text("Replace the shape by a regular polygon of n sides and circumradius r")
            .clicked()
        {
            body.vertices = crate::app::tools::regular_polygon(sides, radius);
            edit.touched("shape".into(), true);
        }
        let label = ui.label("n");
        ui.add(DragValue::new(&mut sides).range(3..=64))
            .labelled_by(label.id)
            .on_hover_text("Number of sides");
        size_field(ui, "r", &mut radius, "Circumradius");
    });
    ui.data_mut(|d| d.insert_temp(size_id, (w, h, sides, radius)));
    if ui
        .button("Clear and draw")
        .on_hover_text("Remove every vertex, then click on the canvas to place new ones")
        .clicked()
    {
        body.vertices.clear();
        edit.touched("shape".into(), true);
    }
}

/// A labelled length for the shape tools.
fn size_field(ui: &mut Ui, label: &str, value: &mut f64, tip: &str) {
    let label = ui.label(label);
    ui.add(DragValue::new(value).speed(0.5).range(0.5..=1e5))
        .labelled_by(label.id)
        .on_hover_text(tip);
}

fn mass_properties(ui: &mut Ui, body: &BodyDef) {
    ui.separator();
    match crate::db::polygon(body) {
        Ok(poly) => {
            let mp = poly.mass_properties();
            egui::Grid::new("mass").num_columns(2).show(ui, |ui| {
                for (k, v) in [
                    ("area", format!("{:.4}", mp.area)),
                    ("mass", format!("{:.4}", mp.area * body.density)),
                    (
                        "centroid",
                        format!("({:.3}, {:.3})", mp.centroid.x, mp.centroid.y),
                    ),
                    (
                        "inertia",
                        format!("{:.5e}", mp.second_moment * body.density),
                    ),
                ] {
                    ui.label(k);
                    ui.label(v);
                    ui.end_row();
                }
            });
        }
        Err(e) => {
            ui.colored_label(
                egui::Color32::LIGHT_RED,
                format!("not a usable polygon: {e}"),
            );
        }
    }
}
