//! Constraint solvers: contacts, the boxed LCP, joints and motors.

pub(crate) mod bounce;
pub(crate) mod contact;
pub(crate) mod envelope;
pub(crate) mod exact;
pub(crate) mod impacts;
pub(crate) mod island;
pub(crate) mod joint;
pub(crate) mod lcp;
pub(crate) mod motor;
pub(crate) mod report;
pub(crate) mod soft;

use crate::body::Body;
use crate::math::{Vec2, cross, cross_scalar};

/// The bodies handed to a solver, by slot, and the slots of those that move, increasing
/// (every other body is fixed for the solver).
pub(crate) type BodiesAndMoving<'a> = (&'a mut [SolverBody], &'a [u32]);

/// What a solver needs of a body: its velocity, inverse mass and where its centroid is.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct SolverBody {
    pub velocity: Vec2,
    pub angular_velocity: f64,
    pub inv_mass: f64,
    pub inv_inertia: f64,
    pub position: Vec2,
    pub angle: f64,
}

impl SolverBody {
    /// The body as the solvers take it: a sleeping one fixed where it is, with the
    /// velocity it has (none unless given by hand: then it carries what touches it, as a
    /// conveyor does).
    pub(crate) fn from_body(body: &Body) -> Self {
        let (inv_mass, inv_inertia) = if body.is_fixed() {
            (0.0, 0.0)
        } else {
            (body.inv_mass, body.inv_inertia)
        };
        Self {
            velocity: body.velocity,
            angular_velocity: body.angular_velocity,
            inv_mass,
            inv_inertia,
            position: body.position,
            angle: body.angle,
        }
    }

    /// A body held still for a pass of `auto`: as the solvers see a sleeping one, fixed
    /// where it is.
    pub(crate) fn held_still(body: &Body) -> Self {
        Self {
            velocity: Vec2::zeros(),
            angular_velocity: 0.0,
            inv_mass: 0.0,
            inv_inertia: 0.0,
            ..Self::from_body(body)
        }
    }

    /// Whether impulses move the body (not static, not held by `auto`).
    pub(crate) fn moves(&self) -> bool {
        self.inv_mass > 0.0 || self.inv_inertia > 0.0
    }

    /// ½ m v² + ½ I ω² (0 for a body impulses do not move).
    pub(crate) fn kinetic_energy(&self) -> f64 {
        let linear = if self.inv_mass > 0.0 {
            self.velocity.norm_squared() / self.inv_mass
        } else {
            0.0
        };
        let angular = if self.inv_inertia > 0.0 {
            self.angular_velocity * self.angular_velocity / self.inv_inertia
        } else {
            0.0
        };
        0.5 * (linear + angular)
    }

    pub(crate) fn velocity_at(&self, point: Vec2) -> Vec2 {
        self.velocity + cross_scalar(self.angular_velocity, point - self.position)
    }

    pub(crate) fn apply_impulse(&mut self, impulse: Vec2, point: Vec2) {
        self.velocity += impulse * self.inv_mass;
        self.angular_velocity += self.inv_inertia * cross(point - self.position, impulse);
    }
}

/// How contact impulses are found each step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ContactSolver {
    /// One contact at a time, once (thesis §2.4.5): the naive baseline.
    Sequential,
    /// The thesis: push-apart, a normal LCP, then a boxed friction LCP bounded by those
    /// normals (§3.2.4); joints in their own passes.
    Thesis,
    /// Box2D-v3-style soft step: substeps, soft contacts, relax, warm starting. For big
    /// piles, where a dense solve costs too much.
    Soft,
    /// One boxed LCP per island with normals, friction bounded by the normal it solves
    /// for, pins and joint motors; penetration removed by a split-impulse position pass.
    Exact,
    /// Per island: `Exact` where exact pivoting is needed and fast (robots, and small
    /// islands of unlike masses), `Soft` for the rest (piles of like bodies), so that no
    /// scene pays for pivoting it does not need. The default.
    #[default]
    Auto,
}

impl ContactSolver {
    pub const ALL: [ContactSolver; 5] = [
        ContactSolver::Sequential,
        ContactSolver::Thesis,
        ContactSolver::Soft,
        ContactSolver::Exact,
        ContactSolver::Auto,
    ];

    pub fn name(self) -> &'static str {
        match self {
            ContactSolver::Sequential => "sequential",
            ContactSolver::Thesis => "thesis",
            ContactSolver::Soft => "soft",
            ContactSolver::Exact => "exact",
            ContactSolver::Auto => "auto",
        }
    }

    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|s| s.name() == name)
    }

    /// The stage lists a step runs under this solver: the one place the choice is read.
    pub(crate) fn stage_list(self) -> StageList {
        match self {
            ContactSolver::Sequential => StageList::Impulses(ImpulseMethod::Sequential),
            ContactSolver::Thesis => StageList::Impulses(ImpulseMethod::Thesis),
            ContactSolver::Exact => StageList::Impulses(ImpulseMethod::Exact),
            ContactSolver::Soft => StageList::Soft,
            ContactSolver::Auto => StageList::Auto,
        }
    }
}

/// What a step runs: the impulse stage list with one method for every island, the soft
/// step, or `auto`'s split of the islands between the impulse list's `Exact` and the soft
/// step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum StageList {
    Impulses(ImpulseMethod),
    Soft,
    Auto,
}

/// How the impulse stage list solves contacts and pins.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum ImpulseMethod {
    /// One contact at a time, then the pins in their own passes.
    Sequential,
    /// The thesis's normal LCP, then its friction LCP, then the pins.
    Thesis,
    /// One boxed LCP per island with contacts, friction, pins and motors.
    Exact,
}

impl ImpulseMethod {
    /// Overlap is pushed out by moving the pair (thesis §3.1) before the solve: the
    /// thesis's and the sequential method's way. The exact method removes it by split
    /// impulses after its solve instead, which keeps the pins' and contacts' impulses
    /// consistent.
    pub(crate) fn pushes_apart(self) -> bool {
        self != ImpulseMethod::Exact
    }

    /// The pins' position pass keeps the motors' impulses the solve already applied this
    /// step: only the exact method solves motors with the contacts.
    pub(crate) fn solves_motors_with_contacts(self) -> bool {
        self == ImpulseMethod::Exact
    }
}
