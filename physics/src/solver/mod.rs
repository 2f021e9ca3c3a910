//! Constraint solvers: contacts, the boxed LCP, joints and motors.

pub mod contact;
pub mod lcp;

use crate::body::Body;
use crate::math::{Vec2, cross, cross_scalar};

/// What a solver needs of a body: its velocity, inverse mass and where its centroid is.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SolverBody {
    pub velocity: Vec2,
    pub angular_velocity: f64,
    pub inv_mass: f64,
    pub inv_inertia: f64,
    pub position: Vec2,
}

impl SolverBody {
    pub fn from_body(body: &Body) -> Self {
        Self {
            velocity: body.velocity,
            angular_velocity: body.angular_velocity,
            inv_mass: body.inv_mass,
            inv_inertia: body.inv_inertia,
            position: body.position,
        }
    }

    pub fn velocity_at(&self, point: Vec2) -> Vec2 {
        self.velocity + cross_scalar(self.angular_velocity, point - self.position)
    }

    pub fn apply_impulse(&mut self, impulse: Vec2, point: Vec2) {
        self.velocity += impulse * self.inv_mass;
        self.angular_velocity += self.inv_inertia * cross(point - self.position, impulse);
    }
}

/// How contact impulses are found each step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ContactSolver {
    /// One contact at a time, once (SPEC §2.4.5): the naive baseline.
    Sequential,
    /// The thesis: normal LCP, then a boxed friction LCP bounded by those normals (§3.2.4).
    #[default]
    Thesis,
}

impl ContactSolver {
    pub const ALL: [ContactSolver; 2] = [ContactSolver::Sequential, ContactSolver::Thesis];

    pub fn name(self) -> &'static str {
        match self {
            ContactSolver::Sequential => "sequential",
            ContactSolver::Thesis => "thesis",
        }
    }

    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|s| s.name() == name)
    }
}
