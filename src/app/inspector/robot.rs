//! The robot inspector: its bodies with their motors, its joints and the motor timeline.

use super::fields::{
    Edit, MotorUnits, body_motor_fields, joint_fields, motor_timeline, name_field, pick,
    placement_fields,
};
use crate::app::document::unique;
use crate::model::{BodyMotorDef, JointDef, Placement, Robot, RobotBody};
use egui::Ui;

/// What the robot inspector needs to know besides the robot.
pub struct Context<'a> {
    pub name: &'a str,
    pub body_names: &'a [String],
    /// The width of the last body's outline, to place the next one beside it.
    pub last_width: f64,
    pub units: MotorUnits,
}

pub fn ui(
    ui: &mut Ui,
    robot: &mut Robot,
    cx: Context<'_>,
    name_buffer: &mut String,
    edit: &mut Edit,
) {
    if let Some(new) = name_field(ui, cx.name, name_buffer) {
        edit.rename = Some(new);
    }
    let aliases: Vec<String> = robot
        .bodies
        .iter()
        .map(|b| b.placement.alias.clone())
        .collect();
    bodies(ui, robot, &cx, &aliases, edit);
    joints(ui, robot, &aliases, cx.units, edit);
    ui.separator();
    motor_timeline(ui, robot);
}

fn bodies(ui: &mut Ui, robot: &mut Robot, cx: &Context<'_>, aliases: &[String], edit: &mut Edit) {
    let (body_names, last_width, units) = (cx.body_names, cx.last_width, cx.units);
    ui.strong("bodies");
    let mut remove = None;
    for (i, b) in robot.bodies.iter_mut().enumerate() {
        egui::CollapsingHeader::new(format!("{} ({})", b.placement.alias, b.placement.source))
            .id_salt(("robot body", i))
            .show(ui, |ui| {
                placement_fields(
                    ui,
                    &mut b.placement,
                    body_names,
                    true,
                    &format!("b{i}"),
                    edit,
                );
                for (k, m) in b.motors.iter_mut().enumerate() {
                    ui.label(format!("motor {}", k + 1))
                        .on_hover_text("The thesis's motor: a torque on this body alone");
                    body_motor_fields(ui, m, units, &format!("b{i}m{k}"), edit);
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
                        edit.touched(format!("b{i} add motor"), true);
                    }
                    if !b.motors.is_empty() && ui.button("− motor").clicked() {
                        b.motors.pop();
                        edit.touched(format!("b{i} remove motor"), true);
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
        edit.touched("remove body".into(), true);
    }
    if let Some(source) = pick(ui, "+ body", body_names) {
        let alias = unique(aliases, &source);
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
        edit.touched("add body".into(), true);
    }
}

fn joints(ui: &mut Ui, robot: &mut Robot, aliases: &[String], units: MotorUnits, edit: &mut Edit) {
    ui.separator();
    ui.strong("joints");
    let mut remove = None;
    for (i, j) in robot.joints.iter_mut().enumerate() {
        egui::CollapsingHeader::new(format!("{} – {}", j.body_a, j.body_b))
            .id_salt(("joint", i))
            .show(ui, |ui| {
                joint_fields(ui, j, aliases, units, &format!("j{i}"), edit);
                if ui.button("Remove joint").clicked() {
                    remove = Some(i);
                }
            });
    }
    if let Some(i) = remove {
        robot.joints.remove(i);
        edit.touched("remove joint".into(), true);
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
        edit.touched("add joint".into(), true);
    }
}
