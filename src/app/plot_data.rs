//! What the plots show: per-step samples of a running simulation, bounded in memory.

use crate::sim::Simulation;

/// One step's numbers.
#[derive(Debug, Clone, Default)]
pub struct Sample {
    pub time: f64,
    pub kinetic: f64,
    pub potential: f64,
    pub max_joint_gap: f64,
    /// The selected body's reference point, velocity and angle, if a body is selected.
    pub body: Option<[f64; 6]>,
    /// Every motor's torque, in `Simulation::motor_torques` order.
    pub torques: Vec<f64>,
}

/// Samples kept for the plots; the oldest half is thinned out when full, so a long run
/// keeps its whole shape at half the resolution.
#[derive(Debug, Clone, Default)]
pub struct PlotData {
    pub samples: Vec<Sample>,
    pub motor_names: Vec<String>,
}

const CAPACITY: usize = 20_000;

impl PlotData {
    pub fn clear(&mut self) {
        self.samples.clear();
        self.motor_names.clear();
    }

    pub fn record(&mut self, sim: &Simulation, selected: Option<usize>) {
        let metrics = sim.metrics();
        let torques = sim.motor_torques();
        if self.motor_names.len() != torques.len() {
            self.motor_names = torques.iter().map(|t| t.id.clone()).collect();
        }
        let body = selected
            .and_then(|i| sim.bodies.get(i))
            .and_then(|b| sim.world.body(b.handle))
            .map(|b| {
                let origin = b.origin();
                let v = b.velocity_at(origin);
                [origin.x, origin.y, b.angle, v.x, v.y, b.angular_velocity]
            });
        self.samples.push(Sample {
            time: metrics.time,
            kinetic: metrics.kinetic,
            potential: metrics.potential,
            max_joint_gap: metrics.max_joint_gap,
            body,
            torques: torques.iter().map(|t| t.torque).collect(),
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
