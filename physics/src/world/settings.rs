//! A world's tuning (`StepSettings`), and the lengths that follow from its length scale.

use crate::solver::ContactSolver;
use crate::solver::joint::JointIterations;

/// How velocities and positions advance over a step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Integrator {
    /// Position from the velocity at the start of the step (thesis §2.1).
    ExplicitEuler,
    /// Velocity first, then position with the new velocity: the thesis's order (thesis §2.2).
    #[default]
    SemiImplicitEuler,
}

/// Tuning of a world. Lengths scale with `length_scale`, the size of a typical body, so that
/// a scene in pixels behaves like the same scene in metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepSettings {
    pub integrator: Integrator,
    pub contact_solver: ContactSolver,
    /// A typical body size in the world's length unit (1 for metre-sized bodies).
    pub length_scale: f64,
    /// Islands with more LCP rows than this are solved iteratively rather than by pivoting.
    pub dense_row_limit: usize,
    /// Whether islands at rest go to sleep (see `World::step`).
    pub sleeping: bool,
    /// Whether a body that ends a step through or deep in a static body is put back to its
    /// time of impact (see `World::step`).
    pub continuous: bool,
    /// Substeps per step of the soft step (`ContactSolver::Soft`); Box2D v3's default, 4.
    pub soft_substeps: usize,
    /// Whether a pair that has barely moved relative to itself keeps its last manifold's
    /// features instead of a new separating-axis test (see `collide::reuse`).
    pub reuse_manifolds: bool,
    /// Whether the soft step sweeps a big island's colours backwards every other pair of
    /// substeps, against the sway that one fixed order builds in a pile (see
    /// `solver::soft::SweepOrder`).
    pub soft_alternating_sweeps: bool,
    /// Whether an impact between moving bodies passes on through the bodies at rest in
    /// contact with them, pair by pair (a Newton's cradle sends out one ball), under
    /// `exact`, `soft` and `auto`; otherwise each island's contacts bounce together in one
    /// LCP, as in the thesis (the cradle moves off as a block).
    pub propagate_impacts: bool,
}

impl Default for StepSettings {
    fn default() -> Self {
        Self {
            integrator: Integrator::default(),
            contact_solver: ContactSolver::default(),
            length_scale: 1.0,
            dense_row_limit: crate::solver::exact::DENSE_ROW_LIMIT,
            sleeping: false,
            continuous: true,
            soft_substeps: 4,
            reuse_manifolds: true,
            soft_alternating_sweeps: true,
            propagate_impacts: true,
        }
    }
}

/// The most substeps a step may be asked for through `StepSettings::soft_substeps`.
pub const MAX_SOFT_SUBSTEPS: usize = 1024;

impl StepSettings {
    /// The settings a step can be taken with: a length scale that is a positive length
    /// within `limits::COORDINATE`, and 1 to `MAX_SOFT_SUBSTEPS` soft substeps.
    pub(crate) fn check(&self) -> Result<(), super::StepError> {
        let scale = self.length_scale;
        if !(scale > 0.0 && scale <= crate::limits::COORDINATE) {
            return Err(super::StepError::BadSetting {
                what: "length_scale",
                value: scale,
                range: "a length > 0 and at most 1e9",
            });
        }
        if !(1..=MAX_SOFT_SUBSTEPS).contains(&self.soft_substeps) {
            return Err(super::StepError::BadSetting {
                what: "soft_substeps",
                value: self.soft_substeps as f64,
                range: "1 to 1024",
            });
        }
        Ok(())
    }

    /// Bodies closer than this count as touching, so resting contacts persist (thesis §3.1).
    pub(crate) fn contact_margin(&self) -> f64 {
        0.02 * self.length_scale
    }

    /// The broad phase pairs bodies by their bounds grown by this much, and keeps those
    /// pairs while every body's bounds stay inside its grown ones (Box2D's fat bounds,
    /// 0.1 m for its 1 m boxes): a pile at rest is not paired again every step.
    pub(crate) fn broad_phase_margin(&self) -> f64 {
        0.1 * self.length_scale
    }

    /// A body slower than this (at its farthest point) counts as still, for sleeping.
    pub(crate) fn sleep_speed(&self) -> f64 {
        0.05 * self.length_scale
    }

    /// Penetration up to this depth is left alone, so resting contacts stay in touch.
    pub fn slop(&self) -> f64 {
        0.005 * self.length_scale
    }

    /// A pair keeps its manifold while no point of either body has moved relative to the
    /// other by more than this since the manifold was found: a tenth of the slop.
    pub(crate) fn manifold_reuse_tolerance(&self) -> f64 {
        0.1 * self.slop()
    }

    /// A reference face is swapped for the other body's only when better by this much.
    pub(crate) fn tie_tolerance(&self) -> f64 {
        0.001 * self.length_scale
    }

    /// Joint passes stop at a gap of a millionth of a body; the cap bounds the work when a
    /// badly broken joint cannot close in one step.
    pub(crate) fn joint_iterations(&self, dt: f64) -> JointIterations {
        JointIterations {
            position_tolerance: 1e-6 * self.length_scale,
            velocity_tolerance: 1e-6 * self.length_scale / dt,
            max_sweeps: 50,
            max_closing: 0.2 * self.length_scale,
            broken_gap: 0.01 * self.length_scale,
        }
    }
}
