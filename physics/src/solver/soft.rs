//! The iterative "soft step" solver for big islands, after the design of Box2D v3:
//! substeps with soft contact constraints (a stiffness in Hz with damping), a relax pass
//! without bias, restitution once at the end above a speed threshold, warm starting from
//! the last step's impulses, speculative contacts, and contact anchors fixed for the step.
//!
//! Each substep: integrate velocities, warm start / solve with bias, integrate positions,
//! relax without bias. Contacts are found once per step; separations follow the bodies
//! through the substeps by their anchors.

use super::SolverBody;
use super::contact::Contact;
use super::joint::JointConstraint;
use crate::math::{Rot, Vec2, cross, cross_scalar, perp};

/// Tuning of the soft step; defaults after Box2D v3, scaled by the world's length scale.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SoftSettings {
    pub substeps: usize,
    /// Contact stiffness (Hz), capped at a quarter of the substep rate for stability.
    pub contact_hertz: f64,
    pub contact_damping_ratio: f64,
    pub joint_hertz: f64,
    pub joint_damping_ratio: f64,
    /// The fastest a soft contact pushes overlapping bodies apart (length units / s).
    pub max_push_speed: f64,
}

impl SoftSettings {
    pub fn for_length_scale(length_scale: f64) -> Self {
        Self {
            substeps: 4,
            contact_hertz: 30.0,
            contact_damping_ratio: 10.0,
            joint_hertz: 60.0,
            joint_damping_ratio: 2.0,
            max_push_speed: 3.0 * length_scale,
        }
    }
}

/// Mass and impulse scaling of a soft constraint (Box2D's b2Softness): a spring–damper of
/// the given frequency and damping ratio, made implicit over the substep.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct Softness {
    bias_rate: f64,
    mass_scale: f64,
    impulse_scale: f64,
}

impl Softness {
    fn new(hertz: f64, zeta: f64, h: f64) -> Self {
        if hertz == 0.0 {
            return Self {
                bias_rate: 0.0,
                mass_scale: 1.0,
                impulse_scale: 0.0,
            };
        }
        let omega = std::f64::consts::TAU * hertz;
        let a1 = 2.0 * zeta + h * omega;
        let a2 = h * omega * a1;
        let a3 = 1.0 / (1.0 + a2);
        Self {
            bias_rate: omega / a1,
            mass_scale: a2 * a3,
            impulse_scale: a3,
        }
    }
}

/// A body during the soft step: velocity, inverse mass, and how far it moved this step.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct SoftBody {
    v: Vec2,
    w: f64,
    inv_mass: f64,
    inv_inertia: f64,
    /// Displacement and rotation since the start of the step.
    dp: Vec2,
    dq: Rot,
    dangle: f64,
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct PointConstraint {
    contact: u32,
    a: u32,
    b: u32,
    /// Anchors relative to the centroids at the start of the step (world axes).
    r_a: Vec2,
    r_b: Vec2,
    normal: Vec2,
    /// Separation at the start, minus the anchors' part, so that the current separation is
    /// `n·(Δ(p_a + r_a) − Δ(p_b + r_b)) + base_separation`.
    base_separation: f64,
    normal_mass: f64,
    tangent_mass: f64,
    friction: f64,
    restitution: f64,
    relative_velocity: f64,
    normal_impulse: f64,
    tangent_impulse: f64,
    max_normal_impulse: f64,
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct SoftJoint {
    a: u32,
    b: u32,
    r_a: Vec2,
    r_b: Vec2,
    /// Anchor separation at the start of the step (A − B).
    base_gap: Vec2,
    impulse: Vec2,
    motor_impulse: f64,
    /// The motor's angular impulse summed over this step's substeps.
    motor_step_total: f64,
    motor: Option<(f64, f64)>,
    slot: u32,
}

/// Warm-start memory and buffers, kept between steps.
#[derive(Debug, Clone, Default)]
pub struct SoftStepSolver {
    bodies: Vec<SoftBody>,
    points: Vec<PointConstraint>,
    joints: Vec<SoftJoint>,
    /// Last step's impulses by (body A, body B, feature), sorted for binary search.
    memory: Vec<((u32, u32, u32), f64, f64)>,
    next_memory: Vec<((u32, u32, u32), f64, f64)>,
    joint_memory: Vec<(u32, Vec2, f64)>,
}

/// The most a body may turn in one substep (radians).
const MAX_TURN_PER_SUBSTEP: f64 = 0.25 * std::f64::consts::PI;

fn rotate_delta(q: Rot, r: Vec2) -> Vec2 {
    q.apply(r)
}

impl SoftStepSolver {
    /// Advances `bodies` by `dt`: velocities from `accelerations` (linear, angular per
    /// body), constraints from `contacts` and `joints`, positions and angles integrated.
    #[allow(clippy::too_many_arguments)]
    pub fn step(
        &mut self,
        settings: &SoftSettings,
        bodies: &mut [SolverBody],
        accelerations: &[(Vec2, f64)],
        contacts: &mut [Contact],
        joints: &mut [JointConstraint],
        dt: f64,
        bounce_below: f64,
    ) {
        let h = dt / settings.substeps as f64;
        let contact_soft = Softness::new(
            settings.contact_hertz.min(0.25 / h),
            settings.contact_damping_ratio,
            h,
        );
        let joint_soft = Softness::new(
            settings.joint_hertz.min(0.25 / h),
            settings.joint_damping_ratio,
            h,
        );
        self.prepare(bodies, contacts, joints);
        for _ in 0..settings.substeps {
            self.integrate_velocities(accelerations, h);
            self.warm_start();
            self.solve(h, &contact_soft, &joint_soft, settings.max_push_speed, true);
            self.integrate_positions(h);
            self.solve(
                h,
                &contact_soft,
                &joint_soft,
                settings.max_push_speed,
                false,
            );
            // Warm starting re-applies the accumulated impulse in every substep, so the
            // step's total is the sum of the substeps' accumulated values.
            for j in &mut self.joints {
                j.motor_step_total += j.motor_impulse;
            }
        }
        self.restitution(bounce_below);
        self.store(bodies, contacts, joints);
    }

    fn prepare(&mut self, bodies: &[SolverBody], contacts: &[Contact], joints: &[JointConstraint]) {
        self.bodies.clear();
        self.bodies.extend(bodies.iter().map(|b| SoftBody {
            v: b.velocity,
            w: b.angular_velocity,
            inv_mass: b.inv_mass,
            inv_inertia: b.inv_inertia,
            dp: Vec2::zeros(),
            dq: Rot { cos: 1.0, sin: 0.0 },
            dangle: 0.0,
        }));
        self.points.clear();
        for (i, c) in contacts.iter().enumerate() {
            let (a, b) = (&bodies[c.body_a as usize], &bodies[c.body_b as usize]);
            let r_a = c.point - a.position;
            let r_b = c.point - b.position;
            let t = perp(c.normal);
            let k = |d: Vec2| {
                let (ca, cb) = (cross(r_a, d), cross(r_b, d));
                a.inv_mass + b.inv_mass + a.inv_inertia * ca * ca + b.inv_inertia * cb * cb
            };
            let inverse = |x: f64| if x > 0.0 { 1.0 / x } else { 0.0 };
            let key = (c.body_a, c.body_b, c.id.0);
            let (normal_impulse, tangent_impulse) =
                match self.memory.binary_search_by(|m| m.0.cmp(&key)) {
                    Ok(k) => (self.memory[k].1, self.memory[k].2),
                    Err(_) => (0.0, 0.0),
                };
            self.points.push(PointConstraint {
                contact: i as u32,
                a: c.body_a,
                b: c.body_b,
                r_a,
                r_b,
                normal: c.normal,
                base_separation: -c.depth,
                normal_mass: inverse(k(c.normal)),
                tangent_mass: inverse(k(t)),
                friction: c.friction,
                restitution: c.restitution,
                relative_velocity: c.approach_velocity,
                normal_impulse,
                tangent_impulse,
                max_normal_impulse: 0.0,
            });
        }
        self.joints.clear();
        for j in joints {
            let (a, b) = (&bodies[j.body_a as usize], &bodies[j.body_b as usize]);
            let (r_a, r_b) = j.arms((a.angle, b.angle));
            let (impulse, motor_impulse) =
                match self.joint_memory.binary_search_by(|m| m.0.cmp(&j.joint)) {
                    Ok(k) => (self.joint_memory[k].1, self.joint_memory[k].2),
                    Err(_) => (Vec2::zeros(), 0.0),
                };
            self.joints.push(SoftJoint {
                a: j.body_a,
                b: j.body_b,
                r_a,
                r_b,
                base_gap: (a.position + r_a) - (b.position + r_b) - j.gap_target,
                impulse,
                motor_impulse,
                motor_step_total: 0.0,
                motor: j
                    .motor
                    .filter(|m| m.enabled)
                    .map(|m| (m.target_speed, m.max_torque)),
                slot: j.joint,
            });
        }
    }

    fn integrate_velocities(&mut self, accelerations: &[(Vec2, f64)], h: f64) {
        for (b, (lin, ang)) in self.bodies.iter_mut().zip(accelerations) {
            if b.inv_mass == 0.0 && b.inv_inertia == 0.0 {
                continue;
            }
            b.v += lin * h;
            b.w += ang * h;
            // A body turning more than a quarter turn per substep is beyond what the
            // linearised rotation below (and any contact found at the step's start) can
            // follow; like Box2D, cap the spin there rather than let it overflow to NaN.
            let max_w = MAX_TURN_PER_SUBSTEP / h;
            b.w = b.w.clamp(-max_w, max_w);
        }
    }

    fn integrate_positions(&mut self, h: f64) {
        for b in self.bodies.iter_mut() {
            b.dp += b.v * h;
            b.dangle += b.w * h;
            // Rotate the delta rotation by ω·h and renormalise: no trigonometry per substep.
            let (c, s) = (b.dq.cos - h * b.w * b.dq.sin, b.dq.sin + h * b.w * b.dq.cos);
            let len = (c * c + s * s).sqrt();
            b.dq = Rot {
                cos: c / len,
                sin: s / len,
            };
        }
    }

    fn apply(bodies: &mut [SoftBody], a: u32, b: u32, r_a: Vec2, r_b: Vec2, impulse: Vec2) {
        let ba = &mut bodies[a as usize];
        ba.v += impulse * ba.inv_mass;
        ba.w += ba.inv_inertia * cross(r_a, impulse);
        let bb = &mut bodies[b as usize];
        bb.v -= impulse * bb.inv_mass;
        bb.w -= bb.inv_inertia * cross(r_b, impulse);
    }

    fn warm_start(&mut self) {
        for p in &self.points {
            let impulse = p.normal * p.normal_impulse + perp(p.normal) * p.tangent_impulse;
            Self::apply(&mut self.bodies, p.a, p.b, p.r_a, p.r_b, impulse);
        }
        for j in &self.joints {
            Self::apply(&mut self.bodies, j.a, j.b, j.r_a, j.r_b, j.impulse);
            let (a, b) = (j.a as usize, j.b as usize);
            let ia = self.bodies[a].inv_inertia;
            self.bodies[a].w += ia * j.motor_impulse;
            let ib = self.bodies[b].inv_inertia;
            self.bodies[b].w -= ib * j.motor_impulse;
        }
    }

    fn solve(
        &mut self,
        h: f64,
        contact_soft: &Softness,
        joint_soft: &Softness,
        max_push: f64,
        use_bias: bool,
    ) {
        for j in self.joints.iter_mut() {
            solve_joint(&mut self.bodies, j, h, joint_soft, use_bias);
        }
        for p in self.points.iter_mut() {
            solve_point(&mut self.bodies, p, h, contact_soft, max_push, use_bias);
        }
    }

    /// Restitution once, after the substeps, for contacts that were approaching faster
    /// than the threshold and did push.
    fn restitution(&mut self, bounce_below: f64) {
        for p in self.points.iter_mut() {
            if p.restitution == 0.0
                || p.relative_velocity > -bounce_below
                || p.max_normal_impulse == 0.0
            {
                continue;
            }
            let (a, b) = (&self.bodies[p.a as usize], &self.bodies[p.b as usize]);
            let ra = rotate_delta(a.dq, p.r_a);
            let rb = rotate_delta(b.dq, p.r_b);
            let dv = (a.v + cross_scalar(a.w, ra)) - (b.v + cross_scalar(b.w, rb));
            let vn = dv.dot(&p.normal);
            let impulse = -p.normal_mass * (vn + p.restitution * p.relative_velocity);
            let total = (p.normal_impulse + impulse).max(0.0);
            let delta = total - p.normal_impulse;
            p.normal_impulse = total;
            Self::apply(&mut self.bodies, p.a, p.b, ra, rb, p.normal * delta);
        }
    }

    fn store(
        &mut self,
        bodies: &mut [SolverBody],
        contacts: &mut [Contact],
        joints: &mut [JointConstraint],
    ) {
        for (b, s) in bodies.iter_mut().zip(&self.bodies) {
            if s.inv_mass == 0.0 && s.inv_inertia == 0.0 {
                continue;
            }
            b.velocity = s.v;
            b.angular_velocity = s.w;
            b.position += s.dp;
            b.angle += s.dangle;
        }
        self.next_memory.clear();
        for p in &self.points {
            let c = &mut contacts[p.contact as usize];
            c.normal_impulse = p.normal_impulse;
            c.tangent_impulse = p.tangent_impulse;
            self.next_memory
                .push(((p.a, p.b, c.id.0), p.normal_impulse, p.tangent_impulse));
        }
        self.next_memory.sort_unstable_by_key(|x| x.0);
        std::mem::swap(&mut self.memory, &mut self.next_memory);
        self.joint_memory.clear();
        for (j, c) in self.joints.iter().zip(joints.iter_mut()) {
            self.joint_memory.push((j.slot, j.impulse, j.motor_impulse));
            if let Some(m) = c.motor.as_mut() {
                m.last_impulse = j.motor_impulse;
                m.step_impulse = j.motor_step_total;
            }
        }
        self.joint_memory.sort_unstable_by_key(|x| x.0);
    }
}

fn solve_point(
    bodies: &mut [SoftBody],
    p: &mut PointConstraint,
    h: f64,
    soft: &Softness,
    max_push: f64,
    use_bias: bool,
) {
    let (a, b) = (bodies[p.a as usize], bodies[p.b as usize]);
    let ra = rotate_delta(a.dq, p.r_a);
    let rb = rotate_delta(b.dq, p.r_b);
    // Current separation: how the anchors moved along the normal since the start.
    let moved = (a.dp + ra - p.r_a) - (b.dp + rb - p.r_b);
    let separation = moved.dot(&p.normal) + p.base_separation;
    let (bias, mass_scale, impulse_scale) = if separation > 0.0 {
        (separation / h, 1.0, 0.0) // speculative: may close the gap, no more
    } else if use_bias {
        (
            (soft.bias_rate * separation).max(-max_push),
            soft.mass_scale,
            soft.impulse_scale,
        )
    } else {
        (0.0, 1.0, 0.0)
    };
    let dv = (a.v + cross_scalar(a.w, ra)) - (b.v + cross_scalar(b.w, rb));
    let vn = dv.dot(&p.normal);
    let impulse = -p.normal_mass * mass_scale * (vn + bias) - impulse_scale * p.normal_impulse;
    let total = (p.normal_impulse + impulse).max(0.0);
    let delta = total - p.normal_impulse;
    p.normal_impulse = total;
    p.max_normal_impulse = p.max_normal_impulse.max(delta);
    SoftStepSolver::apply(bodies, p.a, p.b, ra, rb, p.normal * delta);

    let (a, b) = (bodies[p.a as usize], bodies[p.b as usize]);
    let t = perp(p.normal);
    let dv = (a.v + cross_scalar(a.w, ra)) - (b.v + cross_scalar(b.w, rb));
    let vt = dv.dot(&t);
    let limit = p.friction * p.normal_impulse;
    let total = (p.tangent_impulse - p.tangent_mass * vt).clamp(-limit, limit);
    let delta = total - p.tangent_impulse;
    p.tangent_impulse = total;
    SoftStepSolver::apply(bodies, p.a, p.b, ra, rb, t * delta);
}

fn solve_joint(
    bodies: &mut [SoftBody],
    j: &mut SoftJoint,
    h: f64,
    soft: &Softness,
    use_bias: bool,
) {
    if let Some((target, max_torque)) = j.motor {
        let (a, b) = (bodies[j.a as usize], bodies[j.b as usize]);
        let k = a.inv_inertia + b.inv_inertia;
        if k > 0.0 {
            let limit = max_torque * h;
            let total = (j.motor_impulse - (a.w - b.w - target) / k).clamp(-limit, limit);
            let delta = total - j.motor_impulse;
            j.motor_impulse = total;
            bodies[j.a as usize].w += a.inv_inertia * delta;
            bodies[j.b as usize].w -= b.inv_inertia * delta;
        }
    }
    let (a, b) = (bodies[j.a as usize], bodies[j.b as usize]);
    let ra = rotate_delta(a.dq, j.r_a);
    let rb = rotate_delta(b.dq, j.r_b);
    let dv = (a.v + cross_scalar(a.w, ra)) - (b.v + cross_scalar(b.w, rb));
    let (bias, mass_scale, impulse_scale) = if use_bias {
        let gap = (a.dp + ra - j.r_a) - (b.dp + rb - j.r_b) + j.base_gap;
        (gap * soft.bias_rate, soft.mass_scale, soft.impulse_scale)
    } else {
        (Vec2::zeros(), 1.0, 0.0)
    };
    let m = a.inv_mass + b.inv_mass;
    let (ia, ib) = (a.inv_inertia, b.inv_inertia);
    let k11 = m + ia * ra.y * ra.y + ib * rb.y * rb.y;
    let k12 = -ia * ra.x * ra.y - ib * rb.x * rb.y;
    let k22 = m + ia * ra.x * ra.x + ib * rb.x * rb.x;
    let det = k11 * k22 - k12 * k12;
    if det <= 0.0 {
        return;
    }
    let rhs = dv + bias;
    let solved = Vec2::new(k22 * rhs.x - k12 * rhs.y, k11 * rhs.y - k12 * rhs.x) / det;
    let impulse = -solved * mass_scale - j.impulse * impulse_scale;
    j.impulse += impulse;
    SoftStepSolver::apply(bodies, j.a, j.b, ra, rb, impulse);
}
