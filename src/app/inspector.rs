//! The property inspector: every field of the selected body, robot or scene, editable.
//! Widgets edit a draft of the model; the app turns a changed draft into one undoable edit.

use super::Selection;
use crate::model::{
    BodyMotorDef, JointDef, JointMotorDef, Model, Placement, RobotBody, SceneRobot,
};
use egui::{DragValue, Ui};
use pe::ContactSolver;

/// What the inspector changed this frame.
#[derive(Debug, Default)]
pub struct Change {
    /// Which field (for merging a drag into one undo step).
    pub key: Option<String>,
    /// A rename to apply through the database (it follows references).
    pub rename: Option<(Selection, String)>,
}

/// Fields edit `draft`; `name_buffer` holds a name being typed until Enter.
pub fn show(
    ui: &mut Ui,
    selection: &Selection,
    draft: &mut Model,
    name_buffer: &mut String,
) -> Change {
    let mut change = Change::default();
    let mut touched = |key: String, changed: bool| {
        if changed {
            change.key = Some(key);
        }
    };
    let body_names: Vec<String> = draft.bodies.iter().map(|b| b.name.clone()).collect();
    let robot_names: Vec<String> = draft.robots.iter().map(|r| r.name.clone()).collect();
    match selection {
        Selection::Body(name) => {
            let Some(body) = draft.body_mut(name) else {
                return change;
            };
            if let Some(new) = name_field(ui, name, name_buffer) {
                change.rename = Some((selection.clone(), new));
            }
            egui::Grid::new("body fields")
                .num_columns(2)
                .show(ui, |ui| {
                    let label = ui
                        .label("density")
                        .on_hover_text("Mass per unit area; 0 makes the body static");
                    touched(
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
                    touched(
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
                            touched("friction on".into(), true);
                        }
                        if let Some(mu) = body.friction.as_mut() {
                            touched(
                                "friction".into(),
                                ui.add(DragValue::new(mu).speed(0.01).range(0.0..=10.0))
                                    .changed(),
                            );
                        }
                    });
                    ui.end_row();
                });
            ui.label("vertices (relative to the body's origin)");
            let mut remove = None;
            egui::Grid::new("vertices").num_columns(3).show(ui, |ui| {
                for (i, v) in body.vertices.iter_mut().enumerate() {
                    touched(
                        format!("v{i}x"),
                        ui.add(DragValue::new(&mut v[0]).speed(0.5).prefix("x "))
                            .changed(),
                    );
                    touched(
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
                touched("remove vertex".into(), true);
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
                    touched("add vertex".into(), true);
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
                    touched("hull".into(), true);
                }
            });
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
                    touched("shape".into(), true);
                }
                ui.add(
                    DragValue::new(&mut w)
                        .speed(0.5)
                        .range(0.5..=1e5)
                        .prefix("w "),
                )
                .on_hover_text("Rectangle width");
                ui.add(
                    DragValue::new(&mut h)
                        .speed(0.5)
                        .range(0.5..=1e5)
                        .prefix("h "),
                )
                .on_hover_text("Rectangle height");
            });
            ui.horizontal(|ui| {
                if ui
                    .button("Regular polygon")
                    .on_hover_text(
                        "Replace the shape by a regular polygon of n sides and circumradius r",
                    )
                    .clicked()
                {
                    body.vertices = (0..sides)
                        .map(|k| {
                            let a = std::f64::consts::TAU * k as f64 / sides as f64;
                            [radius * a.cos(), radius * a.sin()]
                        })
                        .collect();
                    touched("shape".into(), true);
                }
                ui.add(DragValue::new(&mut sides).range(3..=64).prefix("n "))
                    .on_hover_text("Number of sides");
                ui.add(
                    DragValue::new(&mut radius)
                        .speed(0.5)
                        .range(0.5..=1e5)
                        .prefix("r "),
                )
                .on_hover_text("Circumradius");
            });
            ui.data_mut(|d| d.insert_temp(size_id, (w, h, sides, radius)));
            if ui
                .button("Clear and draw")
                .on_hover_text("Remove every vertex, then click on the canvas to place new ones")
                .clicked()
            {
                body.vertices.clear();
                touched("shape".into(), true);
            }
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
        Selection::Robot(name) => {
            let last_width = draft
                .robot(name)
                .and_then(|r| r.bodies.last())
                .and_then(|b| draft.body(&b.placement.source))
                .map_or(0.0, width_along_x);
            let Some(robot) = draft.robot_mut(name) else {
                return change;
            };
            if let Some(new) = name_field(ui, name, name_buffer) {
                change.rename = Some((selection.clone(), new));
            }
            let aliases: Vec<String> = robot
                .bodies
                .iter()
                .map(|b| b.placement.alias.clone())
                .collect();
            ui.strong("bodies");
            let mut remove = None;
            for (i, b) in robot.bodies.iter_mut().enumerate() {
                egui::CollapsingHeader::new(format!(
                    "{} ({})",
                    b.placement.alias, b.placement.source
                ))
                .id_salt(("robot body", i))
                .show(ui, |ui| {
                    placement_fields(
                        ui,
                        &mut b.placement,
                        &body_names,
                        true,
                        &format!("b{i}"),
                        &mut touched,
                    );
                    for (k, m) in b.motors.iter_mut().enumerate() {
                        ui.label(format!("motor {}", k + 1))
                            .on_hover_text("The thesis's motor: a torque on this body alone");
                        body_motor_fields(ui, m, &format!("b{i}m{k}"), &mut touched);
                    }
                    ui.horizontal(|ui| {
                        if ui.button("+ motor").clicked() {
                            b.motors.push(BodyMotorDef {
                                time0: 0,
                                time1: 1000,
                                angular: 0.05,
                                start_torque: 1e6,
                                max_torque: 2e6,
                                increase: 0.01,
                                ..Default::default()
                            });
                            touched(format!("b{i} add motor"), true);
                        }
                        if !b.motors.is_empty() && ui.button("− motor").clicked() {
                            b.motors.pop();
                            touched(format!("b{i} remove motor"), true);
                        }
                        if ui.button("Remove body").clicked() {
                            remove = Some(i);
                        }
                    });
                });
            }
            if let Some(i) = remove {
                let alias = robot.bodies.remove(i).placement.alias;
                robot
                    .joints
                    .retain(|j| j.body_a != alias && j.body_b != alias);
                touched("remove body".into(), true);
            }
            if let Some(source) = pick(ui, "+ body", &body_names) {
                let alias = unique(&aliases, &source);
                // To the right of the last body, overlapping it by a quarter of its width:
                // where the joint tool can pin the two.
                let (x, y) = robot.bodies.last().map_or((0.0, 0.0), |last| {
                    (last.placement.x + 0.75 * last_width, last.placement.y)
                });
                robot.bodies.push(RobotBody {
                    placement: Placement {
                        alias,
                        source,
                        x,
                        y,
                        ..Placement::default()
                    },
                    motors: Vec::new(),
                });
                touched("add body".into(), true);
            }
            ui.separator();
            ui.strong("joints");
            let mut remove = None;
            for (i, j) in robot.joints.iter_mut().enumerate() {
                egui::CollapsingHeader::new(format!("{} – {}", j.body_a, j.body_b))
                    .id_salt(("joint", i))
                    .show(ui, |ui| {
                        joint_fields(ui, j, &aliases, &format!("j{i}"), &mut touched);
                        if ui.button("Remove joint").clicked() {
                            remove = Some(i);
                        }
                    });
            }
            if let Some(i) = remove {
                robot.joints.remove(i);
                touched("remove joint".into(), true);
            }
            if aliases.len() >= 2
                && ui
                    .button("+ joint")
                    .on_hover_text("Pin the first two bodies at the first's origin; then edit")
                    .clicked()
            {
                robot.joints.push(JointDef {
                    body_a: aliases[0].clone(),
                    body_b: aliases[1].clone(),
                    ..JointDef::default()
                });
                touched("add joint".into(), true);
            }
            ui.separator();
            motor_timeline(ui, robot);
        }
        Selection::Scene(name) => {
            let Some(scene) = draft.scene_mut(name) else {
                return change;
            };
            if let Some(new) = name_field(ui, name, name_buffer) {
                change.rename = Some((selection.clone(), new));
            }
            egui::Grid::new("scene fields")
                .num_columns(2)
                .show(ui, |ui| {
                    let label = ui
                        .label("gravitation")
                        .on_hover_text("Along +y (down), in length units per s²");
                    touched(
                        "g".into(),
                        ui.add(DragValue::new(&mut scene.gravitation).speed(1.0))
                            .labelled_by(label.id)
                            .changed(),
                    );
                    ui.end_row();
                    let label = ui
                        .label("friction μ")
                        .on_hover_text("Coulomb friction coefficient of every contact");
                    touched(
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
                    let label = ui.label("timestep h").on_hover_text(
                        "Seconds per step; the editor writes it for every scene it saves",
                    );
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
                        touched("h".into(), true);
                    }
                    ui.end_row();
                    ui.label("solver");
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
                                    touched("solver".into(), true);
                                }
                            }
                        });
                    ui.end_row();
                });
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
                            ..Placement::default()
                        };
                        placement_fields(
                            ui,
                            &mut p,
                            &robot_names,
                            false,
                            &format!("r{i}"),
                            &mut touched,
                        );
                        (r.source, r.x, r.y, r.orientation) = (p.source, p.x, p.y, p.orientation);
                        if ui.button("Remove robot").clicked() {
                            remove = Some(i);
                        }
                    });
            }
            if let Some(i) = remove {
                scene.robots.remove(i);
                touched("remove robot".into(), true);
            }
            if let Some(source) = pick(ui, "+ robot", &robot_names) {
                scene.robots.push(SceneRobot {
                    source,
                    x: 300.0,
                    y: 200.0,
                    ..SceneRobot::default()
                });
                touched("add robot".into(), true);
            }
            ui.strong("bodies");
            let aliases: Vec<String> = scene.bodies.iter().map(|b| b.alias.clone()).collect();
            let mut remove = None;
            for (i, b) in scene.bodies.iter_mut().enumerate() {
                egui::CollapsingHeader::new(format!("{} ({})", b.alias, b.source))
                    .id_salt(("scene body", i))
                    .show(ui, |ui| {
                        placement_fields(ui, b, &body_names, true, &format!("s{i}"), &mut touched);
                        if ui.button("Remove body").clicked() {
                            remove = Some(i);
                        }
                    });
            }
            if let Some(i) = remove {
                scene.bodies.remove(i);
                touched("remove scene body".into(), true);
            }
            if let Some(source) = pick(ui, "+ body", &body_names) {
                let alias = unique(&aliases, &source);
                scene.bodies.push(Placement {
                    alias,
                    source,
                    x: 300.0,
                    y: 200.0,
                    ..Placement::default()
                });
                touched("add scene body".into(), true);
            }
        }
    }
    change
}

/// The name, applied on Enter or when the field loses focus.
fn name_field(ui: &mut Ui, current: &str, buffer: &mut String) -> Option<String> {
    ui.horizontal(|ui| {
        let label = ui.label("name");
        let response = ui
            .text_edit_singleline(buffer)
            .labelled_by(label.id)
            .on_hover_text("Renaming updates every reference to it");
        (response.lost_focus() && buffer.trim() != current && !buffer.trim().is_empty())
            .then(|| buffer.trim().to_string())
    })
    .inner
}

fn placement_fields(
    ui: &mut Ui,
    p: &mut Placement,
    sources: &[String],
    aliased: bool,
    key: &str,
    touched: &mut impl FnMut(String, bool),
) {
    egui::Grid::new(("placement", key))
        .num_columns(2)
        .show(ui, |ui| {
            if aliased {
                ui.label("alias");
                touched(
                    format!("{key} alias"),
                    ui.text_edit_singleline(&mut p.alias).changed(),
                );
                ui.end_row();
            }
            ui.label("source");
            egui::ComboBox::from_id_salt(("source", key))
                .selected_text(p.source.trim())
                .show_ui(ui, |ui| {
                    for s in sources {
                        if ui.selectable_label(p.source.trim() == s, s).clicked() {
                            p.source = s.clone();
                            touched(format!("{key} source"), true);
                        }
                    }
                });
            ui.end_row();
            ui.label("x, y");
            ui.horizontal(|ui| {
                touched(
                    format!("{key} x"),
                    ui.add(DragValue::new(&mut p.x).speed(0.5)).changed(),
                );
                touched(
                    format!("{key} y"),
                    ui.add(DragValue::new(&mut p.y).speed(0.5)).changed(),
                );
            });
            ui.end_row();
            ui.label("orientation");
            touched(
                format!("{key} o"),
                ui.add(
                    DragValue::new(&mut p.orientation)
                        .speed(0.01)
                        .suffix(" rad"),
                )
                .changed(),
            );
            ui.end_row();
        });
}

fn body_motor_fields(
    ui: &mut Ui,
    m: &mut BodyMotorDef,
    key: &str,
    touched: &mut impl FnMut(String, bool),
) {
    egui::Grid::new(("motor", key))
        .num_columns(2)
        .show(ui, |ui| {
            ui.label("steps");
            ui.horizontal(|ui| {
                touched(
                    format!("{key} t0"),
                    ui.add(DragValue::new(&mut m.time0).prefix("from "))
                        .changed(),
                );
                touched(
                    format!("{key} t1"),
                    ui.add(DragValue::new(&mut m.time1).prefix("to ")).changed(),
                );
            });
            ui.end_row();
            ui.label("angular")
                .on_hover_text("Target speed in rad per step; the sign gives the direction");
            touched(
                format!("{key} w"),
                ui.add(DragValue::new(&mut m.angular).speed(0.001))
                    .changed(),
            );
            ui.end_row();
            ui.label("torque");
            ui.horizontal(|ui| {
                touched(
                    format!("{key} ts"),
                    ui.add(
                        DragValue::new(&mut m.start_torque)
                            .speed(1e4)
                            .prefix("start ")
                            .range(0.0..=f64::MAX),
                    )
                    .changed(),
                );
                touched(
                    format!("{key} tm"),
                    ui.add(
                        DragValue::new(&mut m.max_torque)
                            .speed(1e4)
                            .prefix("max ")
                            .range(0.0..=f64::MAX),
                    )
                    .changed(),
                );
            });
            ui.end_row();
            ui.label("increase")
                .on_hover_text("Fraction of startTorque added per step while below target");
            touched(
                format!("{key} inc"),
                ui.add(
                    DragValue::new(&mut m.increase)
                        .speed(0.001)
                        .range(0.0..=f64::MAX),
                )
                .changed(),
            );
            ui.end_row();
        });
}

fn joint_fields(
    ui: &mut Ui,
    j: &mut JointDef,
    aliases: &[String],
    key: &str,
    touched: &mut impl FnMut(String, bool),
) {
    egui::Grid::new(("joint", key))
        .num_columns(2)
        .show(ui, |ui| {
            for (label, value) in [("bodyA", &mut j.body_a), ("bodyB", &mut j.body_b)] {
                ui.label(label);
                egui::ComboBox::from_id_salt((label, key))
                    .selected_text(value.as_str())
                    .show_ui(ui, |ui| {
                        for a in aliases {
                            if ui.selectable_label(value == a, a).clicked() {
                                *value = a.clone();
                                touched(format!("{key} {label}"), true);
                            }
                        }
                    });
                ui.end_row();
            }
            ui.label("anchor")
                .on_hover_text("Offset of the pin from bodyA's placement, in robot coordinates");
            ui.horizontal(|ui| {
                touched(
                    format!("{key} ax"),
                    ui.add(DragValue::new(&mut j.anchor_ax).speed(0.5))
                        .changed(),
                );
                touched(
                    format!("{key} ay"),
                    ui.add(DragValue::new(&mut j.anchor_ay).speed(0.5))
                        .changed(),
                );
            });
            ui.end_row();
            ui.label("collide");
            touched(
                format!("{key} collide"),
                ui.checkbox(&mut j.collide, "the two bodies collide")
                    .changed(),
            );
            ui.end_row();
            ui.label("motor");
            let mut has = j.motor.is_some();
            if ui
                .checkbox(&mut has, "joint motor")
                .on_hover_text("Drives ω_A − ω_B with a bounded torque, reacting on both")
                .changed()
            {
                j.motor = has.then(|| JointMotorDef {
                    time0: 0,
                    time1: 1000,
                    angular: 0.05,
                    max_torque: 1e7,
                    ..Default::default()
                });
                touched(format!("{key} motor"), true);
            }
            ui.end_row();
            if let Some(m) = j.motor.as_mut() {
                ui.label("steps");
                ui.horizontal(|ui| {
                    touched(
                        format!("{key} mt0"),
                        ui.add(DragValue::new(&mut m.time0).prefix("from "))
                            .changed(),
                    );
                    touched(
                        format!("{key} mt1"),
                        ui.add(DragValue::new(&mut m.time1).prefix("to ")).changed(),
                    );
                });
                ui.end_row();
                ui.label("angular");
                touched(
                    format!("{key} mw"),
                    ui.add(
                        DragValue::new(&mut m.angular)
                            .speed(0.001)
                            .suffix(" rad/step"),
                    )
                    .changed(),
                );
                ui.end_row();
                ui.label("max torque");
                touched(
                    format!("{key} mm"),
                    ui.add(
                        DragValue::new(&mut m.max_torque)
                            .speed(1e4)
                            .range(0.0..=f64::MAX),
                    )
                    .changed(),
                );
                ui.end_row();
            }
        });
}

/// Every motor's window on one time axis (steps).
fn motor_timeline(ui: &mut Ui, robot: &crate::model::Robot) {
    let mut windows: Vec<(String, u64, u64)> = Vec::new();
    for b in &robot.bodies {
        for m in &b.motors {
            windows.push((b.placement.alias.clone(), m.time0, m.time1));
        }
    }
    for j in &robot.joints {
        if let Some(m) = &j.motor {
            windows.push((format!("{}–{}", j.body_a, j.body_b), m.time0, m.time1));
        }
    }
    if windows.is_empty() {
        return;
    }
    ui.strong("motor timeline (steps)");
    let end = windows
        .iter()
        .map(|w| w.2.max(w.1))
        .max()
        .unwrap_or(1)
        .max(1) as f32;
    let row = 16.0;
    let (rect, _) = ui.allocate_exact_size(
        egui::vec2(ui.available_width(), row * windows.len() as f32 + 14.0),
        egui::Sense::hover(),
    );
    let painter = ui.painter_at(rect);
    let label_width = 70.0;
    let span = rect.width() - label_width - 4.0;
    for (k, (name, t0, t1)) in windows.iter().enumerate() {
        let y = rect.top() + row * k as f32;
        painter.text(
            egui::pos2(rect.left(), y + 2.0),
            egui::Align2::LEFT_TOP,
            name,
            egui::FontId::proportional(11.0),
            ui.visuals().text_color(),
        );
        let x0 = rect.left() + label_width + span * (*t0 as f32 / end);
        let x1 = rect.left() + label_width + span * (*t1 as f32 / end);
        painter.rect_filled(
            egui::Rect::from_min_max(
                egui::pos2(x0, y + 3.0),
                egui::pos2(x1.max(x0 + 1.0), y + row - 3.0),
            ),
            2.0,
            egui::Color32::from_rgb(90, 160, 230),
        );
    }
    painter.text(
        rect.left_bottom() + egui::vec2(label_width, -12.0),
        egui::Align2::LEFT_TOP,
        "0",
        egui::FontId::proportional(10.0),
        egui::Color32::GRAY,
    );
    painter.text(
        rect.right_bottom() + egui::vec2(-2.0, -12.0),
        egui::Align2::RIGHT_TOP,
        format!("{end}"),
        egui::FontId::proportional(10.0),
        egui::Color32::GRAY,
    );
}

/// A menu button that offers `names` and returns the one picked.
fn pick(ui: &mut Ui, label: &str, names: &[String]) -> Option<String> {
    let mut picked = None;
    ui.menu_button(label, |ui| {
        egui::ScrollArea::vertical()
            .max_height(320.0)
            .show(ui, |ui| {
                for n in names {
                    if ui.button(n).clicked() {
                        picked = Some(n.clone());
                    }
                }
            });
    });
    picked
}

/// The extent of a body's outline along its x axis (0 when it has no vertices).
fn width_along_x(body: &crate::model::BodyDef) -> f64 {
    let xs = body.vertices.iter().map(|v| v[0]);
    let width = xs.clone().fold(f64::NEG_INFINITY, f64::max) - xs.fold(f64::INFINITY, f64::min);
    if width.is_finite() { width } else { 0.0 }
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
