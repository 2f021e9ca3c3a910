//! What the database holds (thesis §4.3): body definitions, robots made of placed bodies,
//! joints and motors, and scenes of placed robots and bodies. Plain data: no physics, no
//! files. Lengths are in the files' units (the thesis's pixels, y down), angles in radians.

/// Where an item was read from (1-based line and column), for messages. Never part of an
/// item's identity: two items equal in content are equal wherever they were read.
#[derive(Debug, Clone, Copy, Default)]
pub struct Location {
    pub line: usize,
    pub column: usize,
}

impl PartialEq for Location {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

/// Attributes this version does not know, kept so that saving never drops them.
pub type ExtraAttributes = Vec<(String, String)>;

/// A reusable shape: `<body name density cor>` with `<vertex x y>` children (bodies.xml).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct BodyDef {
    pub name: String,
    /// Mass per unit area; 0 makes the body static (terrain, or a robot's fixed pivot).
    pub density: f64,
    /// Coefficient of restitution e in [0, 1]; a contact uses the smaller of its pair's.
    pub cor: f64,
    /// Optional override of the scene's friction μ (extension: attribute `friction`).
    pub friction: Option<f64>,
    /// Vertices relative to the body's origin, the point a placement puts at (x, y).
    pub vertices: Vec<[f64; 2]>,
    pub extra: ExtraAttributes,
    pub location: Location,
}

/// The thesis's motor (`<force>` on a robot body, thesis §4.4): a torque on that body alone.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct BodyMotorDef {
    /// Active for steps time0 ≤ t < time1.
    pub time0: u64,
    pub time1: u64,
    /// Target angular speed in radians per step; its sign gives the direction.
    pub angular: f64,
    pub start_torque: f64,
    pub max_torque: f64,
    /// Fraction of startTorque added per step while below target.
    pub increase: f64,
    pub extra: ExtraAttributes,
    pub location: Location,
}

/// A joint motor (extension: `<motor>` inside `<joint>`): drives body B's angular velocity
/// relative to body A, ω_B − ω_A, to `angular` (radians per step; positive turns the way
/// a positive orientation does) with at most `maxTorque`, reacting on both bodies.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct JointMotorDef {
    pub time0: u64,
    pub time1: u64,
    pub angular: f64,
    pub max_torque: f64,
    /// Extension (attribute `period`, steps; 0: none): the motor turns at +angular for the
    /// first half of every `period` steps from time0 and at −angular for the second half,
    /// so that its joint swings to and fro through angular·period/2: a gait.
    pub period: u64,
    /// Extension (attribute `targetAngle`, radians): a servo, driving the joint's angle θ
    /// (θ = 0 as placed) to this at no more than |angular| a step, with at most
    /// maxTorque, and holding it there.
    pub target_angle: Option<f64>,
    /// Extension (attribute `keys`, two names: `keys="Left Right"`): the motor runs only
    /// while one of its keys is held in the app, at −angular for the first, +angular for
    /// the second (within its window). Names: `Left`, `Right`, `Up`, `Down`, a letter
    /// `A`–`Z` or a digit `0`–`9` (see `motor_key_names`).
    pub keys: Option<[String; 2]>,
    pub extra: ExtraAttributes,
    pub location: Location,
}

/// The key names a motor may be bound to (`JointMotorDef::keys`).
pub fn is_motor_key_name(name: &str) -> bool {
    matches!(name, "Left" | "Right" | "Up" | "Down")
        || (name.len() == 1
            && name
                .chars()
                .all(|c| c.is_ascii_uppercase() || c.is_ascii_digit()))
}

impl JointMotorDef {
    /// The speed (radians per step) the motor drives at during `step` with its keys in
    /// `drive` (−1 first key held, 1 second, 0 none; ignored for a motor without keys);
    /// None outside its window, or with none of its keys held.
    pub fn angular_driven_at(&self, step: u64, drive: i8) -> Option<f64> {
        let angular = self.angular_at(step)?;
        match (&self.keys, drive) {
            (None, _) => Some(angular),
            (Some(_), 0) => None,
            (Some(_), d) => Some(f64::from(d.signum()) * angular),
        }
    }

    /// The speed (radians per step) the motor drives at during `step`; None outside its
    /// window.
    pub fn angular_at(&self, step: u64) -> Option<f64> {
        if !(self.time0..self.time1).contains(&step) {
            return None;
        }
        let backwards = self.period > 0 && (step - self.time0) % self.period >= self.period / 2;
        Some(if backwards {
            -self.angular
        } else {
            self.angular
        })
    }
}

/// A placement `local` (x, y, orientation) given in a parent `frame` (x, y, orientation),
/// in the frame's own parent: origin + R(angle)·local, the angles added. A robot's body in
/// its scene, say.
pub fn compose(frame: (f64, f64, f64), local: (f64, f64, f64)) -> (f64, f64, f64) {
    let (s, c) = frame.2.sin_cos();
    let (x, y) = (local.0, local.1);
    (
        frame.0 + c * x - s * y,
        frame.1 + s * x + c * y,
        frame.2 + local.2,
    )
}

/// A starting velocity (extension: attributes `vx`, `vy`, `omega`, default 0): of the
/// placed point (a body's or a robot's origin) in length units per second, in the
/// coordinates its x and y are given in, and the spin about it in rad/s (positive: the
/// way a positive orientation turns).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StartVelocity {
    pub vx: f64,
    pub vy: f64,
    pub omega: f64,
}

impl StartVelocity {
    pub fn is_rest(&self) -> bool {
        *self == Self::default()
    }
}

/// A body placed in a robot's frame: `<body alias source x y orientation>`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Placement {
    /// The instance's name within its robot or scene.
    pub alias: String,
    /// The body definition's name in bodies.xml (surrounding whitespace is tolerated).
    pub source: String,
    pub x: f64,
    pub y: f64,
    pub orientation: f64,
    pub velocity: StartVelocity,
    pub extra: ExtraAttributes,
    pub location: Location,
}

#[derive(Debug, Clone, PartialEq, Default)]
pub struct RobotBody {
    pub placement: Placement,
    pub motors: Vec<BodyMotorDef>,
}

/// `<joint bodyA bodyB anchorAx anchorAy>`: the pin is at bodyA's placement plus the
/// anchor offset, in robot coordinates (thesis §6.6).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct JointDef {
    pub body_a: String,
    pub body_b: String,
    pub anchor_ax: f64,
    pub anchor_ay: f64,
    /// Extension (attribute `collide`): the two bodies also collide with each other.
    pub collide: bool,
    /// Extension (attributes `stiffness`, `damping`, `restAngle`, default 0): a rotational
    /// spring-damper across the joint, torque on B −stiffness·(θ − restAngle) −
    /// damping·(ω_B − ω_A), θ = 0 as placed. None without stiffness or damping.
    pub spring: Option<JointSpringDef>,
    /// Extension (attributes `lowerAngle`, `upperAngle`, radians): stops on the joint's
    /// angle θ (θ = 0 as placed); equal, a weld. Either may be left out (no stop there).
    pub lower_angle: Option<f64>,
    pub upper_angle: Option<f64>,
    pub motor: Option<JointMotorDef>,
    pub extra: ExtraAttributes,
    pub location: Location,
}

/// A joint's rotational spring-damper (see `JointDef::spring`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct JointSpringDef {
    /// Torque per radian.
    pub stiffness: f64,
    /// Torque per rad/s.
    pub damping: f64,
    /// Radians of θ at which the spring is slack.
    pub rest_angle: f64,
}

impl JointDef {
    /// The joint's point in robot coordinates, given bodyA's placement.
    pub fn point(&self, body_a: &Placement) -> [f64; 2] {
        [body_a.x + self.anchor_ax, body_a.y + self.anchor_ay]
    }
}

#[derive(Debug, Clone, PartialEq, Default)]
pub struct Robot {
    pub name: String,
    pub bodies: Vec<RobotBody>,
    pub joints: Vec<JointDef>,
    pub extra: ExtraAttributes,
    pub location: Location,
}

impl Robot {
    pub fn body(&self, alias: &str) -> Option<&RobotBody> {
        self.bodies
            .iter()
            .find(|b| same_name(&b.placement.alias, alias))
    }

    /// Each alias (trimmed, see `same_name`) and the index of the first body that has it:
    /// for looking up every joint's bodies in time linear in the robot, not quadratic.
    pub fn alias_index(&self) -> std::collections::HashMap<&str, usize> {
        let mut index = std::collections::HashMap::with_capacity(self.bodies.len());
        for (i, b) in self.bodies.iter().enumerate() {
            index.entry(b.placement.alias.trim()).or_insert(i);
        }
        index
    }
}

/// A robot placed in a scene: `<robot source x y orientation>`. Its starting velocity is
/// the whole robot's, as one rigid body: its origin's velocity and the spin about it.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SceneRobot {
    pub source: String,
    pub x: f64,
    pub y: f64,
    pub orientation: f64,
    pub velocity: StartVelocity,
    pub extra: ExtraAttributes,
    pub location: Location,
}

#[derive(Debug, Clone, PartialEq, Default)]
pub struct Scene {
    pub name: String,
    /// Gravity along +y (down on screen), in length units per s².
    pub gravitation: f64,
    /// Coulomb μ of every body without a `friction` of its own; a contact mixes its two
    /// bodies' μ by the geometric mean.
    pub friction: f64,
    /// Extension: the step h in seconds ([`DEFAULT_TIMESTEP`] when absent).
    pub timestep: Option<f64>,
    /// Extension: the contact solver's name (`auto`, the default, `exact`, `soft`, `thesis`,
    /// `sequential`).
    pub solver: Option<String>,
    pub robots: Vec<SceneRobot>,
    pub bodies: Vec<Placement>,
    pub extra: ExtraAttributes,
    pub location: Location,
}

/// The step when a scene gives none (thesis §6.1: the thesis's numbers behave at h ≪ 1).
pub const DEFAULT_TIMESTEP: f64 = 0.05;

impl Scene {
    pub fn timestep(&self) -> f64 {
        self.timestep.unwrap_or(DEFAULT_TIMESTEP)
    }
}

/// The three collections of a database, in file order.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Model {
    pub bodies: Vec<BodyDef>,
    pub robots: Vec<Robot>,
    pub scenes: Vec<Scene>,
}

/// Whether two names (or a name and a reference to it) are the same: whitespace around
/// either is ignored (the thesis's own example says `source=" housenka"`; a name written
/// `name=" box "` could otherwise never be referred to). Every lookup, rename and delete
/// matches names by this rule.
pub fn same_name(a: &str, b: &str) -> bool {
    a.trim() == b.trim()
}

impl Model {
    /// Looks a body definition up by name (see `same_name`).
    pub fn body(&self, name: &str) -> Option<&BodyDef> {
        self.bodies.iter().find(|b| same_name(&b.name, name))
    }

    pub fn body_mut(&mut self, name: &str) -> Option<&mut BodyDef> {
        self.bodies.iter_mut().find(|b| same_name(&b.name, name))
    }

    pub fn robot(&self, name: &str) -> Option<&Robot> {
        self.robots.iter().find(|r| same_name(&r.name, name))
    }

    pub fn robot_mut(&mut self, name: &str) -> Option<&mut Robot> {
        self.robots.iter_mut().find(|r| same_name(&r.name, name))
    }

    pub fn scene(&self, name: &str) -> Option<&Scene> {
        self.scenes.iter().find(|s| same_name(&s.name, name))
    }

    pub fn scene_mut(&mut self, name: &str) -> Option<&mut Scene> {
        self.scenes.iter_mut().find(|s| same_name(&s.name, name))
    }
}
