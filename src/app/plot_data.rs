//! What the plots show: per-step samples of a running simulation, bounded in memory.

use crate::sim::Simulation;

/// One step's numbers.
#[derive(Debug, Clone, Default)]
pub struct Sample {
    pub time: f64,
    pub kinetic: f64,
    pub potential: f64,
    pub max_joint_gap: f64,
    /// Bodies' reference points, angles and velocities (`BodyState`), by index into
    /// `sim.bodies`: every body's in a scene of up to [`EVERY_BODY_LIMIT`], so that
    /// choosing another body shows its whole run; in bigger scenes the followed one's.
    pub bodies: Vec<(u32, BodyState)>,
    /// Every motor's torque, in `Simulation::motor_torques` order.
    pub torques: Vec<f64>,
    /// Every joint's angle θ (0 as placed) and spin ω_B − ω_A, in `sim.joints` order.
    pub joints: Vec<(f64, f64)>,
}

/// A body's reference point, angle and velocities: x, y, angle, vx, vy, ω.
pub type BodyState = [f64; 6];

/// Scenes of up to this many bodies keep every body's series (a robot scene: 20,000
/// samples of 32 bodies are 36 MB at most).
pub const EVERY_BODY_LIMIT: usize = 32;

/// Samples kept for the plots; the oldest half is thinned out when full, so a long run
/// keeps its whole shape at half the resolution.
#[derive(Debug, Clone, Default)]
pub struct PlotData {
    pub samples: Vec<Sample>,
    pub motor_names: Vec<String>,
    /// The joints' trace ids, in `Sample::joints` order.
    pub joint_names: Vec<String>,
    /// The body the plots and the CSV show (index into `sim.bodies`).
    pub shown_body: Option<usize>,
}

const CAPACITY: usize = 20_000;

impl PlotData {
    pub fn clear(&mut self) {
        self.samples.clear();
        self.motor_names.clear();
        self.joint_names.clear();
    }

    /// Shows body `body` from now on; its series from step 0 where every body is kept.
    pub fn show_body(&mut self, body: Option<usize>) {
        self.shown_body = body;
    }

    /// The shown body's state in sample `s`, if it was recorded there.
    pub fn shown_state(&self, s: &Sample) -> Option<BodyState> {
        let shown = self.shown_body? as u32;
        s.bodies.iter().find(|(i, _)| *i == shown).map(|(_, b)| *b)
    }

    pub fn record(&mut self, sim: &Simulation, followed: Option<usize>) {
        self.shown_body = followed;
        let metrics = sim.metrics();
        let torques = sim.motor_torques();
        if self.motor_names.len() != torques.len() {
            self.motor_names = torques.iter().map(|t| t.id.clone()).collect();
        }
        if self.joint_names.len() != sim.joints.len() {
            self.joint_names = sim.joints.iter().map(|j| j.id.clone()).collect();
        }
        let spin = |h: Option<pe::BodyHandle>| {
            h.and_then(|h| sim.world.body(h))
                .map_or(0.0, |b| b.angular_velocity)
        };
        let joints = sim
            .joints
            .iter()
            .map(|j| {
                let joint = sim.world.joint(j.handle);
                let angle = sim.world.joint_angle(j.handle).unwrap_or(f64::NAN);
                let relative = joint.map_or(f64::NAN, |joint| {
                    spin(joint.body_b) - spin(Some(joint.body_a))
                });
                (angle, relative)
            })
            .collect();
        let state = |i: usize| {
            let b = sim.world.body(sim.bodies.get(i)?.handle)?;
            let origin = b.origin();
            let v = b.velocity_at(origin);
            Some((
                i as u32,
                [origin.x, origin.y, b.angle, v.x, v.y, b.angular_velocity],
            ))
        };
        let bodies = if sim.bodies.len() <= EVERY_BODY_LIMIT {
            (0..sim.bodies.len()).filter_map(state).collect()
        } else {
            followed.and_then(state).into_iter().collect()
        };
        self.samples.push(Sample {
            time: metrics.time,
            kinetic: metrics.kinetic,
            potential: metrics.potential,
            max_joint_gap: metrics.max_joint_gap,
            bodies,
            torques: torques.iter().map(|t| t.torque).collect(),
            joints,
        });
        if self.samples.len() > CAPACITY {
            let mut keep = 0;
            let half = self.samples.len() / 2;
            for i in 0..self.samples.len() {
                if i >= half || i % 2 == 0 {
                    self.samples.swap(keep, i);
                    keep += 1;
                }
            }
            self.samples.truncate(keep);
        }
    }

    /// (time, value) pairs of one quantity, for a plot line.
    pub fn series(&self, value: impl Fn(&Sample) -> Option<f64>) -> Vec<[f64; 2]> {
        self.samples
            .iter()
            .filter_map(|s| value(s).map(|v| [s.time, v]))
            .collect()
    }
}
