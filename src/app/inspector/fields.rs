//! Fields shared by the body, robot and scene inspectors: names, placements, motors,
//! joints, the motor timeline and item pickers.

use crate::model::{BodyMotorDef, JointDef, JointMotorDef, Placement};
use egui::{DragValue, Ui};

/// What one frame of the inspector changed: the draft's changed field (for merging a
/// drag into one undo step), a rename, or something to place in the scene.
#[derive(Debug, Default)]
pub struct Edit {
    pub key: Option<String>,
    pub rename: Option<String>,
    pub place: Option<super::NewPlacement>,
}

impl Edit {
    /// Notes that the field `key` changed, if `changed`.
    pub fn touched(&mut self, key: String, changed: bool) {
        if changed {
            self.key = Some(key);
        }
    }
}

/// How motor speeds are shown: the files keep radians per step; with the step h of the
/// scenes that use the robot known, the inspector shows rad/s (= angular / h).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotorUnits {
    pub step: Option<f64>,
}

impl MotorUnits {
    /// A speed field: rad/s when the step is known, rad/step otherwise.
    pub fn speed(&self, ui: &mut Ui, angular: &mut f64) -> egui::Response {
        match self.step {
            Some(h) => {
                let mut per_second = *angular / h;
                let response = ui
                    .add(DragValue::new(&mut per_second).speed(0.05).suffix(" rad/s"))
                    .on_hover_text(format!(
                        "Stored as {} rad/step (the files' unit) at the step h = {} s of the scenes that use this robot; the sign gives the direction",
                        angular, h
                    ));
                if response.changed() {
                    *angular = per_second * h;
                }
                response
            }
            None => ui
                .add(DragValue::new(angular).speed(0.001).suffix(" rad/step"))
                .on_hover_text(
                    "Radians per step (no scene uses this robot, or its scenes differ in h); the sign gives the direction",
                ),
        }
    }
}

/// The name, applied on Enter or when the field loses focus.
pub fn name_field(ui: &mut Ui, current: &str, buffer: &mut String) -> Option<String> {
    ui.horizontal(|ui| {
        let label = ui
            .label("name")
            .on_hover_text("What the files and the other records call it; unique among its kind");
        let response = ui
            .text_edit_singleline(buffer)
            .labelled_by(label.id)
            .on_hover_text("Renaming updates every reference to it");
        (response.lost_focus() && buffer.trim() != current && !buffer.trim().is_empty())
            .then(|| buffer.trim().to_string())
    })
    .inner
}

pub fn placement_fields(
    ui: &mut Ui,
    p: &mut Placement,
    sources: &[String],
    aliased: bool,
    key: &str,
    edit: &mut Edit,
) {
    egui::Grid::new(("placement", key))
        .num_columns(2)
        .show(ui, |ui| {
            if aliased {
                ui.label("alias").on_hover_text("This placement's own name, unique where it is placed; traces and joints use it");
                edit.touched(
                    format!("{key} alias"),
                    ui.text_edit_singleline(&mut p.alias).changed(),
                );
                ui.end_row();
            }
            ui.label("source").on_hover_text("The body definition or robot this places");
            egui::ComboBox::from_id_salt(("source", key))
                .selected_text(p.source.trim())
                .show_ui(ui, |ui| {
                    for s in sources {
                        if ui.selectable_label(p.source.trim() == s, s).clicked() {
                            p.source = s.clone();
                            edit.touched(format!("{key} source"), true);
                        }
                    }
                });
            ui.end_row();
            ui.label("x, y").on_hover_text("Where the placed origin is, in the parent's units (y down)");
            ui.horizontal(|ui| {
                edit.touched(
                    format!("{key} x"),
                    ui.add(DragValue::new(&mut p.x).speed(0.5)).changed(),
                );
                edit.touched(
                    format!("{key} y"),
                    ui.add(DragValue::new(&mut p.y).speed(0.5)).changed(),
                );
            });
            ui.end_row();
            ui.label("orientation").on_hover_text("Its turn about the origin, in radians (positive: clockwise on screen)");
            edit.touched(
                format!("{key} o"),
                ui.add(
                    DragValue::new(&mut p.orientation)
                        .speed(0.01)
                        .suffix(" rad"),
                )
                .changed(),
            );
            ui.end_row();
            ui.label("start velocity").on_hover_text(
                "How fast the placed origin moves at step 0 (units/s, in the parent's axes, y down) and its spin about the origin (rad/s, positive clockwise on screen); a robot's moves it as one rigid body",
            );
            ui.horizontal(|ui| {
                let v = &mut p.velocity;
                for (name, value, suffix) in [("vx", &mut v.vx, ""), ("vy", &mut v.vy, ""), ("omega", &mut v.omega, " rad/s")] {
                    edit.touched(
                        format!("{key} {name}"),
                        ui.add(DragValue::new(value).speed(1.0).suffix(suffix))
                            .on_hover_text(name)
                            .changed(),
                    );
                }
            });
            ui.end_row();
        });
}

pub fn body_motor_fields(
    ui: &mut Ui,
    m: &mut BodyMotorDef,
    units: MotorUnits,
    key: &str,
    edit: &mut Edit,
) {
    egui::Grid::new(("motor", key))
        .num_columns(2)
        .show(ui, |ui| {
            ui.label("steps").on_hover_text(
                "The motor runs from the first step up to, not including, the second",
            );
            ui.horizontal(|ui| {
                edit.touched(
                    format!("{key} t0"),
                    ui.add(DragValue::new(&mut m.time0).prefix("from "))
                        .changed(),
                );
                edit.touched(
                    format!("{key} t1"),
                    ui.add(DragValue::new(&mut m.time1).prefix("to ")).changed(),
                );
            });
            ui.end_row();
            ui.label("speed")
                .on_hover_text("Target speed; positive turns the way a positive orientation does");
            ui.horizontal(|ui| {
                edit.touched(
                    format!("{key} w"),
                    units.speed(ui, &mut m.angular).changed(),
                );
                turn_arrow(ui, m.angular, "", "");
            });
            ui.end_row();
            ui.label("torque")
                .on_hover_text("The torque it starts with and the most it ramps up to");
            ui.horizontal(|ui| {
                edit.touched(
                    format!("{key} ts"),
                    ui.add(
                        DragValue::new(&mut m.start_torque)
                            .speed(1e4)
                            .prefix("start ")
                            .range(0.0..=f64::MAX),
                    )
                    .changed(),
                );
                edit.touched(
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
            edit.touched(
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

pub fn joint_fields(
    ui: &mut Ui,
    j: &mut JointDef,
    aliases: &[String],
    units: MotorUnits,
    key: &str,
    edit: &mut Edit,
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
                                edit.touched(format!("{key} {label}"), true);
                            }
                        }
                    });
                ui.end_row();
            }
            ui.label("anchor")
                .on_hover_text("Offset of the pin from bodyA's placement, in robot coordinates");
            ui.horizontal(|ui| {
                edit.touched(
                    format!("{key} ax"),
                    ui.add(DragValue::new(&mut j.anchor_ax).speed(0.5))
                        .changed(),
                );
                edit.touched(
                    format!("{key} ay"),
                    ui.add(DragValue::new(&mut j.anchor_ay).speed(0.5))
                        .changed(),
                );
            });
            ui.end_row();
            ui.label("collide").on_hover_text("Whether the two pinned bodies also collide with each other");
            edit.touched(
                format!("{key} collide"),
                ui.checkbox(&mut j.collide, "the two bodies collide")
                    .changed(),
            );
            ui.end_row();
            limit_rows(ui, j, key, edit);
            spring_rows(ui, j, key, edit);
            ui.label("motor").on_hover_text("A joint motor: turns body B against body A");
            let mut has = j.motor.is_some();
            if ui
                .checkbox(&mut has, "joint motor")
                .on_hover_text(
                    "Turns body B relative to body A with a bounded torque, reacting on both",
                )
                .changed()
            {
                j.motor = has.then(|| JointMotorDef {
                    time0: 0,
                    time1: 1000,
                    angular: 0.05,
                    max_torque: 1e7,
                    ..Default::default()
                });
                edit.touched(format!("{key} motor"), true);
            }
            ui.end_row();
            if let Some(m) = j.motor.as_mut() {
                ui.label("steps").on_hover_text("The motor runs from the first step up to, not including, the second");
                ui.horizontal(|ui| {
                    edit.touched(
                        format!("{key} mt0"),
                        ui.add(DragValue::new(&mut m.time0).prefix("from "))
                            .changed(),
                    );
                    edit.touched(
                        format!("{key} mt1"),
                        ui.add(DragValue::new(&mut m.time1).prefix("to ")).changed(),
                    );
                });
                ui.end_row();
                ui.label("speed").on_hover_text(
                    "Body B's speed relative to body A; positive turns the way a positive orientation does, as a body motor's positive speed",
                );
                ui.horizontal(|ui| {
                    edit.touched(
                        format!("{key} mw"),
                        units.speed(ui, &mut m.angular).changed(),
                    );
                    turn_arrow(ui, m.angular, &j.body_b, &j.body_a);
                });
                ui.end_row();
                ui.label("max torque").on_hover_text("The most torque the motor applies, on both bodies");
                edit.touched(
                    format!("{key} mm"),
                    ui.add(
                        DragValue::new(&mut m.max_torque)
                            .speed(1e4)
                            .range(0.0..=f64::MAX),
                    )
                    .changed(),
                );
                ui.end_row();
                ui.label("swing period").on_hover_text(
                    "Steps: forward for the first half of each period, back for the second, so the joint swings to and fro (a gait); 0 turns one way only",
                );
                edit.touched(
                    format!("{key} mp"),
                    ui.add(DragValue::new(&mut m.period).range(0..=1_000_000).suffix(" steps"))
                        .changed(),
                );
                ui.end_row();
                servo_row(ui, m, key, edit);
                keys_row(ui, m, key, edit);
            }
        });
}

/// A joint's stops in its grid: each on or off, and its angle.
fn limit_rows(ui: &mut Ui, j: &mut JointDef, key: &str, edit: &mut Edit) {
    let tips = [
        "The least angle the joint may reach (0 is as placed; equal stops weld it)",
        "The greatest angle the joint may reach (0 is as placed; equal stops weld it)",
    ];
    let stops = [
        ("lower stop", &mut j.lower_angle),
        ("upper stop", &mut j.upper_angle),
    ];
    for ((label, stop), tip) in stops.into_iter().zip(tips) {
        ui.label(label).on_hover_text(tip);
        ui.horizontal(|ui| {
            let mut on = stop.is_some();
            if ui.checkbox(&mut on, "").on_hover_text(label).changed() {
                *stop = on.then_some(0.0);
                edit.touched(format!("{key} {label}"), true);
            }
            if let Some(angle) = stop.as_mut() {
                edit.touched(
                    format!("{key} {label} angle"),
                    ui.add(DragValue::new(angle).speed(0.01).suffix(" rad"))
                        .changed(),
                );
            }
        });
        ui.end_row();
    }
}

/// A joint's spring rows in its grid: on or off, then stiffness, damping, rest angle.
fn spring_rows(ui: &mut Ui, j: &mut JointDef, key: &str, edit: &mut Edit) {
    ui.label("spring").on_hover_text(
        "A rotational spring-damper: torque on body B −stiffness·(angle − rest) − damping·(spin of B against A)",
    );
    let mut has = j.spring.is_some();
    if ui.checkbox(&mut has, "spring").changed() {
        j.spring = has.then_some(crate::model::JointSpringDef {
            stiffness: 1e6,
            damping: 0.0,
            rest_angle: 0.0,
        });
        edit.touched(format!("{key} spring"), true);
    }
    ui.end_row();
    let Some(spring) = j.spring.as_mut() else {
        return;
    };
    let rows = [
        (
            "stiffness",
            &mut spring.stiffness,
            "Torque per radian the joint turns from rest",
            "",
        ),
        (
            "damping",
            &mut spring.damping,
            "Torque per rad/s of body B's spin against body A",
            "",
        ),
        (
            "rest angle",
            &mut spring.rest_angle,
            "The joint's angle where the spring is slack; 0 is as placed",
            " rad",
        ),
    ];
    for (label, value, tip, suffix) in rows {
        ui.label(label).on_hover_text(tip);
        let speed = if suffix.is_empty() { 1e3 } else { 0.01 };
        let mut drag = DragValue::new(value).speed(speed).suffix(suffix);
        if suffix.is_empty() {
            drag = drag.range(0.0..=f64::MAX);
        }
        edit.touched(format!("{key} spring {label}"), ui.add(drag).changed());
        ui.end_row();
    }
}

/// A joint motor's keys row: two key names (`Left Right`, `A D`); held while the scene
/// runs, the first drives it backward, the second forward. Empty: no keys, it runs by
/// its window alone.
fn keys_row(ui: &mut Ui, m: &mut JointMotorDef, key: &str, edit: &mut Edit) {
    ui.label("keys").on_hover_text(
        "Two keys (Left, Right, Up, Down, A-Z, 0-9), e.g. \"Left Right\": while running, the motor drives only while one is held, backward for the first, forward for the second. Empty: it runs by its steps alone",
    );
    let mut text = m
        .keys
        .as_ref()
        .map_or(String::new(), |[a, b]| format!("{a} {b}"));
    let response = ui.add(egui::TextEdit::singleline(&mut text).desired_width(90.0));
    if response.changed() {
        let names: Vec<String> = text.split_whitespace().map(str::to_string).collect();
        m.keys = match names.as_slice() {
            [] => None,
            [one] => Some([one.clone(), String::new()]),
            [first, rest @ ..] => Some([first.clone(), rest.join(" ")]),
        };
        edit.touched(format!("{key} keys"), true);
    }
    ui.end_row();
}

/// A joint motor's servo row: on, it drives the joint to an angle and holds it there.
fn servo_row(ui: &mut Ui, m: &mut JointMotorDef, key: &str, edit: &mut Edit) {
    ui.label("servo to").on_hover_text(
        "A servo drives the joint's angle (0 as placed) to this, at no more than the speed, and holds it there",
    );
    ui.horizontal(|ui| {
        let mut servo = m.target_angle.is_some();
        if ui.checkbox(&mut servo, "").on_hover_text("servo").changed() {
            m.target_angle = servo.then_some(0.0);
            edit.touched(format!("{key} servo"), true);
        }
        if let Some(angle) = m.target_angle.as_mut() {
            edit.touched(
                format!("{key} servo angle"),
                ui.add(DragValue::new(angle).speed(0.01).suffix(" rad"))
                    .changed(),
            );
        }
    });
    ui.end_row();
}

/// An arrow for which way a motor of speed `angular` turns `body` (relative to `other`,
/// if any) as the canvas shows it (y down: a positive orientation turns clockwise on
/// screen), said in full when hovered. Short, so that the inspector keeps its width.
pub fn turn_arrow(ui: &mut Ui, angular: f64, body: &str, other: &str) {
    let (arrow, way) = if angular > 0.0 {
        ("⟳", "clockwise")
    } else if angular < 0.0 {
        ("⟲", "anticlockwise")
    } else {
        ("·", "")
    };
    let said = match (way, other.is_empty()) {
        ("", _) => "stands still".to_string(),
        (way, true) => format!("turns {way} on screen"),
        (way, false) => format!("{} turns {way} against {}", body.trim(), other.trim()),
    };
    ui.label(egui::RichText::new(arrow).size(16.0))
        .on_hover_text(said);
}

/// Every motor's window on one time axis (steps).
pub fn motor_timeline(ui: &mut Ui, robot: &crate::model::Robot) {
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
pub fn pick(ui: &mut Ui, label: &str, names: &[String]) -> Option<String> {
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
pub fn width_along_x(body: &crate::model::BodyDef) -> f64 {
    let xs = body.vertices.iter().map(|v| v[0]);
    let width = xs.clone().fold(f64::NEG_INFINITY, f64::max) - xs.fold(f64::INFINITY, f64::min);
    if width.is_finite() { width } else { 0.0 }
}
