//! The edge of the world: a body that leaves the scene's neighbourhood (a car driven off
//! the end of its terrain) is stopped there, with the bodies pinned to it, instead of
//! falling for ever while the energy runs away and the view follows it into nothing.

use super::placing::bounds_of;
use crate::sim::Simulation;
use pe::{Aabb, BodyHandle, Vec2};

#[derive(Debug, Clone, PartialEq)]
pub struct WorldBound {
    /// Every body's box at step 0: the scene.
    pub scene: Aabb,
    /// `scene` grown on every side: a body whose centroid leaves it is stopped.
    pub limit: Aabb,
    /// Stopped bodies and where they are held.
    stopped: Vec<(BodyHandle, Vec2, f64)>,
}

impl WorldBound {
    /// The bound around `sim` as it is now (step 0): the scene grown by half its larger
    /// side, and by at least ten typical body sizes, so that nothing still in play meets it.
    pub fn around(sim: &Simulation) -> Option<Self> {
        let scene = bounds_of(
            sim.world
                .bodies()
                .flat_map(|(_, b)| b.world_vertices().collect::<Vec<_>>()),
        )?;
        let size = scene.max - scene.min;
        let margin = (0.5 * size.x.max(size.y)).max(10.0 * sim.world.settings.length_scale);
        Some(Self {
            scene,
            limit: scene.grown(margin),
            stopped: Vec::new(),
        })
    }

    pub fn is_stopped(&self, body: BodyHandle) -> bool {
        self.stopped.iter().any(|(h, _, _)| *h == body)
    }

    /// Call after each step: holds the stopped bodies where they were stopped, and stops
    /// the bodies that left the limit with everything pinned to them. Returns the trace
    /// ids of the bodies stopped now.
    pub fn enforce(&mut self, sim: &mut Simulation) -> Vec<String> {
        for &(handle, position, angle) in &self.stopped {
            if let Some(body) = sim.world.body_mut(handle) {
                body.position = position;
                body.angle = angle;
                body.velocity = Vec2::zeros();
                body.angular_velocity = 0.0;
            }
        }
        let escaped: Vec<BodyHandle> = sim
            .world
            .bodies()
            .filter(|(h, b)| !b.is_static() && !self.is_stopped(*h))
            .filter(|(_, b)| {
                let c = b.centroid();
                !(c.x.is_finite()
                    && c.y.is_finite()
                    && (self.limit.min.x..=self.limit.max.x).contains(&c.x)
                    && (self.limit.min.y..=self.limit.max.y).contains(&c.y))
            })
            .map(|(h, _)| h)
            .collect();
        let mut newly = Vec::new();
        for handle in pinned_together(sim, &escaped) {
            if self.is_stopped(handle) {
                continue;
            }
            let Some(body) = sim.world.body_mut(handle) else {
                continue;
            };
            body.velocity = Vec2::zeros();
            body.angular_velocity = 0.0;
            self.stopped.push((handle, body.position, body.angle));
            if let Some(b) = sim.bodies.iter().find(|b| b.handle == handle) {
                newly.push(b.id.clone());
            }
        }
        newly
    }

    /// Whether every moving body has been stopped.
    /// The scene's neighbourhood and the bodies stopped at the edge of the world: what
    /// the view shows when nothing moves any more (the stopped robot in view, not only
    /// the scene it left).
    pub fn scene_and_stopped(&self, sim: &Simulation) -> Aabb {
        let mut area = self.scene;
        for (h, _, _) in &self.stopped {
            for v in sim
                .world
                .body(*h)
                .into_iter()
                .flat_map(|b| b.world_vertices())
            {
                area.min = area.min.inf(&v);
                area.max = area.max.sup(&v);
            }
        }
        area
    }

    pub fn all_stopped(&self, sim: &Simulation) -> bool {
        sim.world
            .bodies()
            .all(|(h, b)| b.is_static() || self.is_stopped(h))
    }
}

/// `start` and every body joined to one of them through a chain of joints.
fn pinned_together(sim: &Simulation, start: &[BodyHandle]) -> Vec<BodyHandle> {
    let mut group = start.to_vec();
    let mut k = 0;
    while k < group.len() {
        let body = group[k];
        for (_, joint) in sim.world.joints() {
            let other = match joint.body_b {
                Some(b) if joint.body_a == body => b,
                Some(b) if b == body => joint.body_a,
                _ => continue,
            };
            if !group.contains(&other) {
                group.push(other);
            }
        }
        k += 1;
    }
    group
}

/// The note for the status bar when `ids` were stopped at time `t`.
pub fn note(ids: &[String], t: f64) -> String {
    let who = match ids {
        [] => return String::new(),
        [one] => one.clone(),
        [first, rest @ ..] => format!("{first} and {} more", rest.len()),
    };
    format!(
        "{who} left the scene at t = {t:.2} s and stopped at the edge of the world · R starts again"
    )
}
