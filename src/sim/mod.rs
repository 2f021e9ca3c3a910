//! A scene from the database as a running `pe::World` (issue 6): placement composition,
//! joints from anchors, both motor kinds, the step counter and per-step metrics.

pub mod trace;

use crate::db::{self, clip};
use crate::model::{BodyMotorDef, JointDef, Model, Placement, Robot, Scene, SceneRobot, same_name};
use pe::{BodyDef, BodyHandle, ContactSolver, JointHandle, JointMotor, Vec2, World};

/// Why a scene cannot be simulated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BuildError {
    #[error("there is no scene \"{0}\" in the database")]
    UnknownScene(String),
    #[error("scene \"{scene}\": {problem}")]
    Invalid { scene: String, problem: String },
}

/// One simulated body and how traces name it.
#[derive(Debug, Clone, PartialEq)]
pub struct SimBody {
    /// The alias of a scene body, `"{robot}#{i}/{alias}"` for a body of the i-th robot (the
    /// robot's name as it is in robots.xml); a suffix `~2`, `~3` makes a repeated id unique.
    pub id: String,
    pub handle: BodyHandle,
    pub placed_by: PlacedBy,
}

/// The placement in the files that puts a simulated body where it starts (indices in
/// document order), so that the editor can change it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlacedBy {
    /// The scene's `k`-th `<body>`.
    SceneBody(usize),
    /// Body `body` of the robot placed by the scene's `robot`-th `<robot>`.
    RobotBody { robot: usize, body: usize },
}

#[derive(Debug, Clone, PartialEq)]
pub struct SimJoint {
    /// `"{robot}#{i}/{bodyA}-{bodyB}"`, unique as `SimBody::id` is.
    pub id: String,
    pub handle: JointHandle,
    /// The joint's motor as the files give it (its window, speed and swing), if any.
    pub motor: Option<crate::model::JointMotorDef>,
    /// Which of the motor's keys is held (−1 the first, 1 the second, 0 neither): the
    /// app's to set; a motor bound to keys runs only while one is.
    pub drive: i8,
    /// The joint in the files: the scene's `robot`-th `<robot>`, its `joint`-th joint.
    pub defined_by: (usize, usize),
}

/// What one step looked like.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Metrics {
    pub step: u64,
    pub time: f64,
    pub kinetic: f64,
    pub potential: f64,
    pub momentum: Vec2,
    pub angular_momentum: f64,
    pub max_joint_gap: f64,
    pub contacts: usize,
    /// The deepest contact penetration (0 when nothing overlaps).
    pub max_penetration: f64,
}

/// A motor's applied torque in the last step, for plots.
#[derive(Debug, Clone, PartialEq)]
pub struct MotorTorque {
    pub id: String,
    pub torque: f64,
}

#[derive(Debug, Clone)]
pub struct Simulation {
    pub world: World,
    pub bodies: Vec<SimBody>,
    pub joints: Vec<SimJoint>,
    /// Which body each body motor drives, by index into `bodies`.
    body_motor_owners: Vec<usize>,
    pub dt: f64,
    /// Every joint motor runs at this times its speed in the files (the app's throttle).
    pub motor_throttle: f64,
    pub scene_name: String,
    model: Model,
    solver: ContactSolver,
}

/// Trace ids made unique in order: an id already taken gets `~2`, `~3`, ... (a scene
/// body aliased `r#0/a` beside robot `r`'s body `a`, two joints between the same two
/// bodies), so that no two columns of a trace share a name.
fn make_unique<'a>(ids: impl Iterator<Item = &'a mut String>) {
    let mut taken = std::collections::HashSet::new();
    // The next suffix to try for each repeated id: n copies of one id take time linear
    // in n, not quadratic.
    let mut next_suffix: std::collections::HashMap<String, u64> = Default::default();
    for id in ids {
        if !taken.insert(id.clone()) {
            let k = next_suffix.entry(id.clone()).or_insert(2);
            let unique = loop {
                let candidate = format!("{id}~{k}");
                *k += 1;
                if !taken.contains(&candidate) {
                    break candidate;
                }
            };
            taken.insert(unique.clone());
            *id = unique;
        }
    }
}

/// A joint motor's `angular` (radians per step; positive: body B turns the way a
/// positive `orientation` turns, relative to body A, as a body motor's positive speed
/// turns its body, and as Box2D's motor speed is) as pe's target speed (rad/s of
/// ω_A − ω_B).
pub fn pe_joint_speed(angular: f64, dt: f64) -> f64 {
    -angular / dt
}

/// A placement composed with a parent frame (`model::compose`), as a position and angle.
fn compose(frame: (f64, f64, f64), local: (f64, f64, f64)) -> (Vec2, f64) {
    let (x, y, angle) = crate::model::compose(frame, local);
    (Vec2::new(x, y), angle)
}

/// The world velocity of a robot body's origin at `origin` and its spin: the robot's
/// motion as one rigid body (its origin's velocity, its spin about that origin) plus the
/// body's own starting velocity, given in the robot's coordinates.
fn robot_body_velocity(robot: &SceneRobot, body: &Placement, origin: Vec2) -> (Vec2, f64) {
    let (rv, bv) = (&robot.velocity, &body.velocity);
    let arm = origin - Vec2::new(robot.x, robot.y);
    let carried = Vec2::new(rv.vx - rv.omega * arm.y, rv.vy + rv.omega * arm.x);
    let own = rotated(Vec2::new(bv.vx, bv.vy), robot.orientation);
    (carried + own, rv.omega + bv.omega)
}

/// `v` turned by `angle` (radians), as `model::compose` turns a placement.
fn rotated(v: Vec2, angle: f64) -> Vec2 {
    let (x, y, _) = crate::model::compose((0.0, 0.0, angle), (v.x, v.y, 0.0));
    Vec2::new(x, y)
}

fn placement_frame(p: &Placement) -> (f64, f64, f64) {
    (p.x, p.y, p.orientation)
}

impl Simulation {
    /// Builds scene `name` of `model`. `dt` overrides the scene's step, `solver` its solver.
    pub fn new(
        model: &Model,
        name: &str,
        dt: Option<f64>,
        solver: Option<ContactSolver>,
    ) -> Result<Self, BuildError> {
        let scene = model
            .scene(name)
            .ok_or_else(|| BuildError::UnknownScene(clip(name)))?;
        let invalid = |problem: String| BuildError::Invalid {
            scene: clip(&scene.name),
            problem,
        };
        let dt = dt.unwrap_or(scene.timestep());
        if let Some(problem) = db::timestep_problem(dt) {
            return Err(invalid(problem));
        }
        let solver = match (solver, &scene.solver) {
            (Some(s), _) => s,
            (None, Some(name)) => ContactSolver::from_name(name.trim())
                .ok_or_else(|| invalid(format!("unknown solver \"{name}\"")))?,
            (None, None) => ContactSolver::default(),
        };
        let mut sim = Self {
            world: World::new(Vec2::new(0.0, scene.gravitation)),
            bodies: Vec::new(),
            joints: Vec::new(),
            body_motor_owners: Vec::new(),
            dt,
            motor_throttle: 1.0,
            scene_name: scene.name.clone(),
            model: model.clone(),
            solver,
        };
        sim.populate(scene).map_err(invalid)?;
        Ok(sim)
    }

    /// Body `placement` with its origin at `at` (world point and angle), the origin moving
    /// at `moving` (world velocity and spin about it).
    fn add_body(
        &mut self,
        id: String,
        placed_by: PlacedBy,
        placement: &Placement,
        at: (Vec2, f64),
        moving: (Vec2, f64),
    ) -> Result<BodyHandle, String> {
        let def = self
            .model
            .body(&placement.source)
            .ok_or_else(|| format!("{id}: source \"{}\" is not a body", placement.source))?;
        let polygon = db::polygon(def).map_err(|e| format!("{id}: body \"{}\": {e}", def.name))?;
        // Density, friction and placement are checked by `pe` (its limits, its words).
        // pe takes the centroid's velocity: the origin's, plus the spin about the origin.
        let to_centroid = rotated(polygon.mass_properties().centroid, at.1);
        let (v_origin, spin) = moving;
        let v_centroid = v_origin + Vec2::new(-spin * to_centroid.y, spin * to_centroid.x);
        let mut body = BodyDef::new(polygon, def.density)
            .restitution(def.cor)
            .at(at.0, at.1);
        if def.density > 0.0 {
            body = body.velocity(v_centroid, spin);
        }
        if let Some(mu) = def.friction {
            body = body.friction(mu);
        }
        let handle = self
            .world
            .add_body(body)
            .map_err(|e| format!("{id}: {e}"))?;
        self.bodies.push(SimBody {
            id,
            handle,
            placed_by,
        });
        Ok(handle)
    }

    fn populate(&mut self, scene: &Scene) -> Result<(), String> {
        // The editor simulates a model whatever its problems, so what `db::check` reports
        // must not reach the engine either: the records' numbers are refused here, when
        // the scene is built, by the same checks and in the same words.
        if let Some(problem) = db::scene_number_problems(scene).into_iter().next() {
            return Err(problem);
        }
        self.world.friction = scene.friction;
        self.world.settings.contact_solver = self.solver;
        let model = self.model.clone();
        for (i, placed) in scene.robots.iter().enumerate() {
            let robot = model.robot(&placed.source).ok_or_else(|| {
                format!("robot #{i}: source \"{}\" is not a robot", placed.source)
            })?;
            self.add_robot(i, robot, placed)?;
        }
        for (k, p) in scene.bodies.iter().enumerate() {
            let at = (Vec2::new(p.x, p.y), p.orientation);
            let v = &p.velocity;
            let moving = (Vec2::new(v.vx, v.vy), v.omega);
            self.add_body(p.alias.clone(), PlacedBy::SceneBody(k), p, at, moving)?;
        }
        // Scenes are in pixels, tens of units per body, not metres: tolerances scale with
        // the typical body.
        self.world.settings.length_scale = self.world.median_body_radius().unwrap_or(1.0);
        make_unique(self.bodies.iter_mut().map(|b| &mut b.id));
        make_unique(self.joints.iter_mut().map(|j| &mut j.id));
        Ok(())
    }

    /// The `i`-th robot of the scene, placed by `placed`: its bodies with their motors, its
    /// mount's collision rule and its joints.
    fn add_robot(&mut self, i: usize, robot: &Robot, placed: &SceneRobot) -> Result<(), String> {
        let prefix = format!("{}#{i}", robot.name);
        let frame = (placed.x, placed.y, placed.orientation);
        let mut handles = Vec::new();
        for (k, b) in robot.bodies.iter().enumerate() {
            let p = &b.placement;
            let id = format!("{prefix}/{}", p.alias);
            let placed_by = PlacedBy::RobotBody { robot: i, body: k };
            let at = compose(frame, placement_frame(p));
            let moving = robot_body_velocity(placed, p, at.0);
            let handle = self.add_body(id.clone(), placed_by, p, at, moving)?;
            for m in &b.motors {
                self.add_body_motor(&id, handle, m)?;
            }
            handles.push(handle);
        }
        // A robot's static bodies are its mount (a pivot, a frame): in a real machine the
        // moving parts pass in front of it, so it collides with the scene, not with them.
        for (k, &mount) in handles.iter().enumerate() {
            if self.world.body(mount).is_some_and(|b| b.is_static()) {
                for (m, &other) in handles.iter().enumerate() {
                    if m != k {
                        self.world.ignore_collisions(mount, other);
                    }
                }
            }
        }
        let aliases = robot.alias_index();
        for (k, j) in robot.joints.iter().enumerate() {
            let id = format!("{prefix}/{}-{}", j.body_a.trim(), j.body_b.trim());
            let find = |alias: &str| aliases.get(alias.trim()).copied();
            let (Some(a), Some(b)) = (find(&j.body_a), find(&j.body_b)) else {
                return Err(format!("{id}: bodyA or bodyB is not a body of the robot"));
            };
            let (ha, hb) = (handles[a], handles[b]);
            let point = j.point(&robot.bodies[a].placement);
            let (anchor, _) = compose(frame, (point[0], point[1], 0.0));
            self.add_joint(id, (i, k), ha, hb, anchor, j)?;
        }
        Ok(())
    }

    fn add_body_motor(
        &mut self,
        id: &str,
        body: BodyHandle,
        m: &BodyMotorDef,
    ) -> Result<(), String> {
        if let Some(problem) = db::body_motor_problems(m).into_iter().next() {
            return Err(format!("{id}: motor: {problem}"));
        }
        let motor = pe::BodyMotor::new(
            m.time0,
            m.time1,
            m.angular,
            m.start_torque,
            m.max_torque,
            m.increase,
        );
        self.world
            .add_body_motor(body, motor)
            .map_err(|e| format!("{id}: {e}"))?;
        self.body_motor_owners.push(self.bodies.len() - 1);
        Ok(())
    }

    /// The pin of `joint` between bodies `a` and `b` at `anchor` (world), with its motor.
    fn add_joint(
        &mut self,
        id: String,
        defined_by: (usize, usize),
        a: BodyHandle,
        b: BodyHandle,
        anchor: Vec2,
        joint: &JointDef,
    ) -> Result<(), String> {
        let mut def = pe::JointDef::new(a, Some(b), anchor);
        def.collide_connected = joint.collide;
        if let Some(problem) = db::joint_limit_problems(joint).into_iter().next() {
            return Err(format!("{id}: {problem}"));
        }
        if joint.lower_angle.is_some() || joint.upper_angle.is_some() {
            let far = pe::limits::ANGLE;
            def.limits = Some(pe::JointLimits::new(
                joint.lower_angle.unwrap_or(-far),
                joint.upper_angle.unwrap_or(far),
            ));
        }
        if let Some(spring) = &joint.spring {
            if let Some(problem) = db::joint_spring_problems(spring).into_iter().next() {
                return Err(format!("{id}: spring: {problem}"));
            }
            def.spring = Some(pe::JointSpring::new(
                spring.stiffness,
                spring.damping,
                spring.rest_angle,
            ));
        }
        if let Some(m) = &joint.motor {
            if let Some(problem) = db::joint_motor_problems(m).into_iter().next() {
                return Err(format!("{id}: motor: {problem}"));
            }
            let at_start = m.angular_driven_at(0, 0);
            def.motor = Some(JointMotor {
                target_angle: m.target_angle,
                enabled: at_start.is_some(),
                ..JointMotor::new(
                    pe_joint_speed(at_start.unwrap_or(m.angular), self.dt),
                    m.max_torque,
                )
            });
        }
        let handle = self
            .world
            .add_joint(def)
            .map_err(|e| format!("{id}: {e}"))?;
        self.joints.push(SimJoint {
            id,
            handle,
            motor: joint.motor.clone(),
            drive: 0,
            defined_by,
        });
        Ok(())
    }

    /// Takes up, without starting again, the changes of `model` that a running scene can
    /// follow (as Algodoo does): the scene's gravitation, friction and step, and its
    /// robots' joint motors' speeds, torques and servo angles. False, and nothing changed, if anything
    /// else differs or a new number is one the scene may not have: then it is to be
    /// built again.
    pub fn follow_live_edit(&mut self, model: &Model) -> bool {
        let Some(motors) = self.live_edit(model) else {
            return false;
        };
        let scene = model.scene(&self.scene_name).expect("checked by live_edit");
        let dt = scene.timestep();
        self.world.gravity = Vec2::new(0.0, scene.gravitation);
        self.world.friction = scene.friction;
        self.dt = dt;
        for (handle, m) in motors {
            if let Some(motor) = self.world.joint_motor_mut(handle) {
                motor.max_torque = m.max_torque;
                motor.target_angle = m.target_angle;
            }
            if let Some(j) = self.joints.iter_mut().find(|j| j.handle == handle) {
                j.motor = Some(m);
            }
        }
        self.model = model.clone();
        true
    }

    /// Whether `follow_live_edit` would take `model` up as the scene runs.
    pub fn can_follow_live_edit(&self, model: &Model) -> bool {
        self.live_edit(model).is_some()
    }

    /// The joint motors of `model`, by joint, if every other difference from the model
    /// the scene was built from is one it can follow as it runs (see `follow_live_edit`).
    fn live_edit(&self, model: &Model) -> Option<Vec<(JointHandle, crate::model::JointMotorDef)>> {
        // Both models with what may change live set aside must be equal.
        let set_aside = |m: &Model| {
            let mut m = m.clone();
            if let Some(s) = m
                .scenes
                .iter_mut()
                .find(|s| same_name(&s.name, &self.scene_name))
            {
                (s.gravitation, s.friction, s.timestep) = (0.0, 0.0, None);
            }
            for j in m.robots.iter_mut().flat_map(|r| &mut r.joints) {
                if let Some(motor) = &mut j.motor {
                    (motor.angular, motor.max_torque) = (0.0, 0.0);
                    motor.target_angle = None;
                }
            }
            m
        };
        let scene = model.scene(&self.scene_name)?;
        if set_aside(model) != set_aside(&self.model)
            || !db::scene_number_problems(scene).is_empty()
            || db::timestep_problem(scene.timestep()).is_some()
        {
            return None;
        }
        let mut motors = Vec::new();
        for j in &self.joints {
            let (r, k) = j.defined_by;
            let robot = scene.robots.get(r).and_then(|p| model.robot(&p.source));
            let def = robot.and_then(|robot| robot.joints.get(k)?.motor.as_ref());
            if let Some(m) = def {
                if !db::joint_motor_problems(m).is_empty() {
                    return None;
                }
                motors.push((j.handle, m.clone()));
            }
        }
        Some(motors)
    }

    /// Solves contacts with `solver` from the next step on, and after `reset`.
    pub fn set_solver(&mut self, solver: ContactSolver) {
        self.solver = solver;
        self.world.settings.contact_solver = solver;
    }

    /// Back to the scene's first state.
    pub fn reset(&mut self) {
        let (model, name, dt, solver) = (
            self.model.clone(),
            self.scene_name.clone(),
            self.dt,
            self.solver,
        );
        let (sleeping, throttle) = (self.world.settings.sleeping, self.motor_throttle);
        *self = Self::new(&model, &name, Some(dt), Some(solver))
            .expect("a scene that built once builds again");
        self.world.settings.sleeping = sleeping;
        self.motor_throttle = throttle;
    }

    pub fn step_count(&self) -> u64 {
        self.world.step_count()
    }

    pub fn time(&self) -> f64 {
        self.step_count() as f64 * self.dt
    }

    /// One step of `dt` (see `try_step`), whatever it reports.
    pub fn step(&mut self) {
        let _reported = self.try_step();
    }

    /// One step of `dt`; joint motors switch on and off by their windows, turn back by
    /// their periods, and run at `motor_throttle` × their speed. An error names what pe
    /// refused, or the body whose state left the limits (by its trace id).
    pub fn try_step(&mut self) -> Result<(), String> {
        let step = self.world.step_count();
        for j in &self.joints {
            if let Some(def) = &j.motor
                && let Some(m) = self.world.joint_motor_mut(j.handle)
            {
                let angular = def.angular_driven_at(step, j.drive);
                m.enabled = angular.is_some();
                match angular {
                    Some(w) => m.target_speed = self.motor_throttle * pe_joint_speed(w, self.dt),
                    None => m.last_impulse = 0.0,
                }
            }
        }
        self.world.try_step(self.dt).map_err(|e| match e {
            pe::StepError::StateBeyond { body, .. } | pe::StepError::BadBody { body, .. } => {
                let id = self.bodies.iter().find(|b| b.handle.0 == body);
                let name = id.map_or(format!("body {body}"), |b| format!("\"{}\"", clip(&b.id)));
                e.to_string().replacen(&format!("body {body}"), &name, 1)
            }
            pe::StepError::PinTorn { joint, .. }
            | pe::StepError::MotorTooFast { joint, .. }
            | pe::StepError::BadJointMotor { joint, .. } => {
                let id = self.joints.iter().find(|j| j.handle.0 == joint);
                let name = id.map_or(format!("joint {joint}"), |j| {
                    format!("joint \"{}\"", clip(&j.id))
                });
                e.to_string().replacen(&format!("joint {joint}"), &name, 1)
            }
            e => e.to_string(),
        })
    }

    pub fn metrics(&self) -> Metrics {
        Metrics {
            step: self.step_count(),
            time: self.time(),
            kinetic: self.world.kinetic_energy(),
            potential: self.world.potential_energy(),
            momentum: self.world.linear_momentum(),
            angular_momentum: self.world.angular_momentum(),
            max_joint_gap: self.world.max_joint_gap(),
            contacts: self.world.contacts().len(),
            max_penetration: self
                .world
                .contacts()
                .iter()
                .map(|c| c.depth)
                .fold(0.0, f64::max),
        }
    }

    /// Every motor's torque in the last step: body motors by their ramp, joint motors by
    /// their impulse over the step.
    pub fn motor_torques(&self) -> Vec<MotorTorque> {
        let mut out: Vec<MotorTorque> = self
            .world
            .body_motors()
            .iter()
            .zip(&self.body_motor_owners)
            .map(|((_, m), &owner)| MotorTorque {
                id: self.bodies[owner].id.clone(),
                torque: m.current * if m.angular < 0.0 { -1.0 } else { 1.0 },
            })
            .collect();
        for j in &self.joints {
            if let Some(m) = self.world.joint(j.handle).and_then(|j| j.motor) {
                out.push(MotorTorque {
                    id: j.id.clone(),
                    // pe's impulse drives ω_A − ω_B; the files' sign is B's relative to A.
                    torque: -m.step_impulse / self.dt,
                });
            }
        }
        out
    }

    /// Whether any body's state is not finite (the guard against a blow-up).
    pub fn has_non_finite_state(&self) -> bool {
        self.world.bodies().any(|(_, b)| {
            !(b.position.x.is_finite()
                && b.position.y.is_finite()
                && b.angle.is_finite()
                && b.velocity.x.is_finite()
                && b.velocity.y.is_finite()
                && b.angular_velocity.is_finite())
        })
    }
}
