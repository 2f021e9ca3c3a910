//! The meaning of the elements (thesis §4.3): element trees become model records. A record
//! whose attributes cannot be read is skipped with an error that names it; everything
//! else in the file still loads. Range and reference checks are `check.rs`'s.

use super::problem::{FileProblems, Problem};
use super::xml::{Element, clip};
use crate::model::{
    BodyDef, BodyMotorDef, ExtraAttributes, JointDef, JointMotorDef, JointSpringDef, Placement,
    Robot, RobotBody, Scene, SceneRobot, StartVelocity,
};

/// What reading a file gave: its records, the problems, and whether any record was
/// skipped (saving such a file would drop it, so the database asks first).
pub struct Read<T> {
    pub records: Vec<T>,
    /// Where each record's element lies in the file's text (see `xml::Element::span`).
    pub spans: Vec<Option<std::ops::Range<usize>>>,
    pub problems: Vec<Problem>,
    pub skipped: bool,
}

/// The attributes of one element, taken one by one; what is left over is kept as extra.
struct Fields<'a> {
    element: &'a Element,
    file: &'a str,
    /// How messages name the element: `<joint> in robot "housenka"`.
    what: String,
    used: Vec<&'static str>,
    problems: &'a mut FileProblems,
    failed: bool,
}

impl<'a> Fields<'a> {
    fn new(
        element: &'a Element,
        file: &'a str,
        what: String,
        problems: &'a mut FileProblems,
    ) -> Self {
        Self {
            element,
            file,
            what,
            used: Vec::new(),
            problems,
            failed: false,
        }
    }

    fn fail(&mut self, message: String) {
        let problem = Problem::error(self.file, &self.what, message).at(self.element.location);
        self.problems.push(problem);
        self.failed = true;
    }

    fn raw(&mut self, key: &'static str) -> Option<&'a str> {
        self.used.push(key);
        self.element
            .attributes
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }

    fn text(&mut self, key: &'static str) -> String {
        match self.raw(key) {
            Some(v) => v.to_string(),
            None => {
                self.fail(format!("missing attribute {key}"));
                String::new()
            }
        }
    }

    fn optional_text(&mut self, key: &'static str) -> Option<String> {
        self.raw(key).map(str::to_string)
    }

    fn parse_number(&mut self, key: &'static str, value: &str) -> f64 {
        match value.trim().parse::<f64>() {
            Ok(v) if v.is_finite() => v,
            Ok(_) => {
                self.fail(format!("{key}=\"{}\" is not a finite number", clip(value)));
                0.0
            }
            Err(_) => {
                self.fail(format!("{key}=\"{}\" is not a number", clip(value)));
                0.0
            }
        }
    }

    fn number(&mut self, key: &'static str) -> f64 {
        match self.raw(key) {
            Some(v) => self.parse_number(key, v),
            None => {
                self.fail(format!("missing attribute {key}"));
                0.0
            }
        }
    }

    fn optional_number(&mut self, key: &'static str) -> Option<f64> {
        self.raw(key).map(|v| self.parse_number(key, v))
    }

    /// A step count: a whole number ≥ 0 (written as a float by some programs: `1e+003`).
    fn steps(&mut self, key: &'static str) -> u64 {
        let v = self.number(key);
        self.whole_steps(key, v)
    }

    /// A step count that may be left out.
    fn optional_steps(&mut self, key: &'static str) -> Option<u64> {
        let v = self.optional_number(key)?;
        Some(self.whole_steps(key, v))
    }

    fn whole_steps(&mut self, key: &'static str, v: f64) -> u64 {
        if v < 0.0 || v.fract() != 0.0 || v > 9.0e15 {
            self.fail(format!("{key}={v} is not a whole number of steps"));
            return 0;
        }
        v as u64
    }

    fn flag(&mut self, key: &'static str) -> bool {
        match self.raw(key).map(str::trim) {
            None | Some("0") | Some("false") => false,
            Some("1") | Some("true") => true,
            Some(other) => {
                self.fail(format!("{key}=\"{}\" is not true or false", clip(other)));
                false
            }
        }
    }

    fn extra(&self) -> ExtraAttributes {
        self.element
            .attributes
            .iter()
            .filter(|(k, _)| !self.used.contains(&k.as_str()))
            .cloned()
            .collect()
    }
}

fn unknown_child(file: &str, parent: &str, child: &Element, problems: &mut FileProblems) {
    problems.push(
        Problem::warning(
            file,
            &format!("<{}> in {parent}", child.name),
            "unknown element, ignored (and not kept when this file is saved)",
        )
        .at(child.location),
    );
}

/// The name a record goes by in messages before its name is known.
fn named(element: &Element, kind: &str) -> String {
    match element.attributes.iter().find(|(k, _)| k == "name") {
        Some((_, name)) => format!("<{kind}> \"{}\"", clip(name)),
        None => format!("<{kind}>"),
    }
}

pub fn bodies(root: &Element, file: &str) -> Read<BodyDef> {
    let mut problems = FileProblems::default();
    let mut records = Vec::new();
    let mut spans = Vec::new();
    let mut skipped = false;
    for el in &root.children {
        if el.name != "body" {
            unknown_child(file, &format!("<{}>", root.name), el, &mut problems);
            continue;
        }
        let what = named(el, "body");
        let problems_before = problems.len();
        let mut f = Fields::new(el, file, what.clone(), &mut problems);
        let mut body = BodyDef {
            name: f.text("name"),
            density: f.number("density"),
            cor: f.number("cor"),
            friction: f.optional_number("friction"),
            vertices: Vec::new(),
            extra: Vec::new(),
            location: el.location,
        };
        body.extra = f.extra();
        let mut failed = f.failed;
        for v in &el.children {
            if v.name != "vertex" {
                unknown_child(file, &what, v, &mut problems);
                continue;
            }
            let mut f = Fields::new(v, file, format!("<vertex> of {what}"), &mut problems);
            let point = [f.number("x"), f.number("y")];
            let dropped: Vec<String> = f
                .extra()
                .into_iter()
                .map(|(k, _)| format!("\"{}\"", clip(&k)))
                .collect();
            failed |= f.failed;
            if !dropped.is_empty() {
                problems.push(
                    Problem::warning(
                        file,
                        &format!("<vertex> of {what}"),
                        format!("unknown attributes {} are not kept", dropped.join(", ")),
                    )
                    .at(v.location),
                );
            }
            body.vertices.push(point);
        }
        if failed {
            skipped = true;
        } else {
            records.push(body);
            // A record read with a problem is written afresh, not as it was.
            spans.push(
                el.span
                    .as_deref()
                    .cloned()
                    .filter(|_| problems.len() == problems_before),
            );
        }
    }
    Read {
        records,
        spans,
        problems: problems.into_vec(file),
        skipped,
    }
}

fn placement(
    el: &Element,
    file: &str,
    what: String,
    problems: &mut FileProblems,
    aliased: bool,
) -> (Placement, bool) {
    let mut f = Fields::new(el, file, what, problems);
    let alias = if aliased {
        f.text("alias")
    } else {
        String::new()
    };
    let placement = Placement {
        alias,
        source: f.text("source"),
        x: f.number("x"),
        y: f.number("y"),
        // The thesis always writes it; files from elsewhere may not: 0 is the natural default.
        orientation: f.optional_number("orientation").unwrap_or(0.0),
        velocity: StartVelocity {
            vx: f.optional_number("vx").unwrap_or(0.0),
            vy: f.optional_number("vy").unwrap_or(0.0),
            omega: f.optional_number("omega").unwrap_or(0.0),
        },
        extra: f.extra(),
        location: el.location,
    };
    (placement, f.failed)
}

pub fn robots(root: &Element, file: &str) -> Read<Robot> {
    let mut problems = FileProblems::default();
    let mut records = Vec::new();
    let mut spans = Vec::new();
    let mut skipped = false;
    for el in &root.children {
        if el.name != "robot" {
            unknown_child(file, &format!("<{}>", root.name), el, &mut problems);
            continue;
        }
        let what = named(el, "robot");
        let problems_before = problems.len();
        let mut f = Fields::new(el, file, what.clone(), &mut problems);
        let mut robot = Robot {
            name: f.text("name"),
            location: el.location,
            ..Robot::default()
        };
        robot.extra = f.extra();
        let mut failed = f.failed;
        for child in &el.children {
            match &*child.name {
                "body" => {
                    let in_robot = format!("<body> in robot \"{}\"", robot.name);
                    let (placement, bad) =
                        placement(child, file, in_robot.clone(), &mut problems, true);
                    failed |= bad;
                    let mut body = RobotBody {
                        placement,
                        motors: Vec::new(),
                    };
                    for m in &child.children {
                        if m.name != "force" {
                            unknown_child(file, &in_robot, m, &mut problems);
                            continue;
                        }
                        let mut f =
                            Fields::new(m, file, format!("<force> on {in_robot}"), &mut problems);
                        let mut motor = BodyMotorDef {
                            time0: f.steps("time0"),
                            time1: f.steps("time1"),
                            angular: f.number("angular"),
                            start_torque: f.number("startTorque"),
                            max_torque: f.number("maxTorque"),
                            increase: f.number("increase"),
                            extra: Vec::new(),
                            location: m.location,
                        };
                        motor.extra = f.extra();
                        failed |= f.failed;
                        body.motors.push(motor);
                    }
                    robot.bodies.push(body);
                }
                "joint" => {
                    let in_robot = format!("<joint> in robot \"{}\"", robot.name);
                    let mut f = Fields::new(child, file, in_robot.clone(), &mut problems);
                    let mut joint = JointDef {
                        body_a: f.text("bodyA"),
                        body_b: f.text("bodyB"),
                        anchor_ax: f.number("anchorAx"),
                        anchor_ay: f.number("anchorAy"),
                        collide: f.flag("collide"),
                        spring: None,
                        lower_angle: None,
                        upper_angle: None,
                        motor: None,
                        extra: Vec::new(),
                        location: child.location,
                    };
                    joint.lower_angle = f.optional_number("lowerAngle");
                    joint.upper_angle = f.optional_number("upperAngle");
                    let (stiffness, damping) =
                        (f.optional_number("stiffness"), f.optional_number("damping"));
                    let rest_angle = f.optional_number("restAngle");
                    if stiffness.is_some() || damping.is_some() || rest_angle.is_some() {
                        joint.spring = Some(JointSpringDef {
                            stiffness: stiffness.unwrap_or(0.0),
                            damping: damping.unwrap_or(0.0),
                            rest_angle: rest_angle.unwrap_or(0.0),
                        });
                    }
                    joint.extra = f.extra();
                    failed |= f.failed;
                    for m in &child.children {
                        if m.name != "motor" || joint.motor.is_some() {
                            unknown_child(file, &in_robot, m, &mut problems);
                            continue;
                        }
                        let mut f =
                            Fields::new(m, file, format!("<motor> of {in_robot}"), &mut problems);
                        let mut motor = JointMotorDef {
                            time0: f.steps("time0"),
                            time1: f.steps("time1"),
                            angular: f.number("angular"),
                            max_torque: f.number("maxTorque"),
                            period: f.optional_steps("period").unwrap_or(0),
                            target_angle: f.optional_number("targetAngle"),
                            keys: f.optional_text("keys").map(|k| {
                                let mut names = k.split_whitespace().map(str::to_string);
                                let first = names.next().unwrap_or_default();
                                let rest: Vec<String> = names.collect();
                                [first, rest.join(" ")]
                            }),
                            extra: Vec::new(),
                            location: m.location,
                        };
                        motor.extra = f.extra();
                        failed |= f.failed;
                        joint.motor = Some(motor);
                    }
                    robot.joints.push(joint);
                }
                _ => unknown_child(file, &what, child, &mut problems),
            }
        }
        if failed {
            skipped = true;
        } else {
            records.push(robot);
            // A record read with a problem is written afresh, not as it was.
            spans.push(
                el.span
                    .as_deref()
                    .cloned()
                    .filter(|_| problems.len() == problems_before),
            );
        }
    }
    Read {
        records,
        spans,
        problems: problems.into_vec(file),
        skipped,
    }
}

pub fn scenes(root: &Element, file: &str) -> Read<Scene> {
    let mut problems = FileProblems::default();
    let mut records = Vec::new();
    let mut spans = Vec::new();
    let mut skipped = false;
    for el in &root.children {
        if el.name != "scene" {
            unknown_child(file, &format!("<{}>", root.name), el, &mut problems);
            continue;
        }
        let what = named(el, "scene");
        let problems_before = problems.len();
        let mut f = Fields::new(el, file, what.clone(), &mut problems);
        let mut scene = Scene {
            name: f.text("name"),
            gravitation: f.number("gravitation"),
            friction: f.number("friction"),
            timestep: f.optional_number("timestep"),
            solver: f.raw("solver").map(str::to_string),
            location: el.location,
            ..Scene::default()
        };
        scene.extra = f.extra();
        let mut failed = f.failed;
        for child in &el.children {
            let in_scene = format!("<{}> in scene \"{}\"", child.name, scene.name);
            match &*child.name {
                "robot" => {
                    let (p, bad) = placement(child, file, in_scene, &mut problems, false);
                    failed |= bad;
                    scene.robots.push(SceneRobot {
                        source: p.source,
                        x: p.x,
                        y: p.y,
                        orientation: p.orientation,
                        velocity: p.velocity,
                        extra: p.extra,
                        location: p.location,
                    });
                }
                "body" => {
                    let (p, bad) = placement(child, file, in_scene, &mut problems, true);
                    failed |= bad;
                    scene.bodies.push(p);
                }
                _ => unknown_child(file, &what, child, &mut problems),
            }
        }
        if failed {
            skipped = true;
        } else {
            records.push(scene);
            // A record read with a problem is written afresh, not as it was.
            spans.push(
                el.span
                    .as_deref()
                    .cloned()
                    .filter(|_| problems.len() == problems_before),
            );
        }
    }
    Read {
        records,
        spans,
        problems: problems.into_vec(file),
        skipped,
    }
}
