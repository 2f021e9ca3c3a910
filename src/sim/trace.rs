//! The trace format of `robosim run` (issue 6): one record per written step, as JSON
//! Lines or CSV. Field names and order are part of the format.

use super::Simulation;
use serde::Serialize;

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BodyState {
    pub id: String,
    /// The body's reference point (where its placement in the files puts it).
    pub x: f64,
    pub y: f64,
    pub angle: f64,
    /// The reference point's velocity.
    pub vx: f64,
    pub vy: f64,
    pub omega: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct JointState {
    pub id: String,
    /// Distance between the joint's two anchors.
    pub gap: f64,
}

#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Energy {
    pub kinetic: f64,
    pub potential: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Record {
    pub step: u64,
    pub time: f64,
    pub bodies: Vec<BodyState>,
    pub joints: Vec<JointState>,
    pub energy: Energy,
}

impl Record {
    pub fn of(sim: &Simulation) -> Self {
        let bodies = sim
            .bodies
            .iter()
            .filter_map(|b| {
                let body = sim.world.body(b.handle)?;
                let origin = body.origin();
                let v = body.velocity_at(origin);
                Some(BodyState {
                    id: b.id.clone(),
                    x: origin.x,
                    y: origin.y,
                    angle: body.angle,
                    vx: v.x,
                    vy: v.y,
                    omega: body.angular_velocity,
                })
            })
            .collect();
        let joints = sim
            .joints
            .iter()
            .filter_map(|j| {
                Some(JointState {
                    id: j.id.clone(),
                    gap: sim.world.joint_gap(j.handle)?,
                })
            })
            .collect();
        Record {
            step: sim.step_count(),
            time: sim.time(),
            bodies,
            joints,
            energy: Energy {
                kinetic: sim.world.kinetic_energy(),
                potential: sim.world.potential_energy(),
            },
        }
    }

    pub fn to_json_line(&self) -> String {
        serde_json::to_string(self).expect("a record of numbers and strings serialises")
    }

    /// The CSV header for records shaped like this one: `step,time,kinetic,potential`,
    /// then `{id}.x`, `.y`, `.angle`, `.vx`, `.vy`, `.omega` per body and `{id}.gap` per joint.
    pub fn csv_header(&self) -> Vec<String> {
        let mut header: Vec<String> = ["step", "time", "kinetic", "potential"]
            .map(String::from)
            .to_vec();
        for b in &self.bodies {
            let id = without_control_characters(&b.id);
            for field in ["x", "y", "angle", "vx", "vy", "omega"] {
                header.push(format!("{id}.{field}"));
            }
        }
        header.extend(
            self.joints
                .iter()
                .map(|j| format!("{}.gap", without_control_characters(&j.id))),
        );
        header
    }

    pub fn csv_row(&self) -> Vec<String> {
        let mut row = vec![
            self.step.to_string(),
            self.time.to_string(),
            self.energy.kinetic.to_string(),
            self.energy.potential.to_string(),
        ];
        for b in &self.bodies {
            row.extend([b.x, b.y, b.angle, b.vx, b.vy, b.omega].map(|v| v.to_string()));
        }
        row.extend(self.joints.iter().map(|j| j.gap.to_string()));
        row
    }
}

/// `name` with its control characters written as JSON writes them (`\u001b`): a CSV
/// printed to a terminal must not carry an escape sequence or a carriage return from a
/// name in the files (the csv crate quotes fields, it does not escape them).
fn without_control_characters(name: &str) -> String {
    let mut out = String::with_capacity(name.len());
    for c in name.chars() {
        if c.is_control() {
            out += &format!("\\u{:04x}", c as u32);
        } else {
            out.push(c);
        }
    }
    out
}
