//! Whether a model makes sense: ranges, shapes, unique names, references, connected
//! robots (thesis §4.1), anchors inside bodies. Every problem names file, line, element.

use super::problem::Problem;
use super::{FileKind, clip};
use crate::model::{
    BodyDef, BodyMotorDef, JointDef, JointMotorDef, JointSpringDef, Model, Placement, Robot, Scene,
    SceneRobot, StartVelocity, compose,
};
use pe::{ContactSolver, ConvexPolygon, Vec2};
use std::collections::BTreeMap;

/// The step range a scene may ask for: beyond it the motor and contact models stop
/// making sense (thesis §6.1 recommends 0.01–0.1; we allow a decade either side).
pub const TIMESTEP_RANGE: (f64, f64) = (1e-4, 1.0);

/// The largest magnitude each kind of number may have: the engine's own, so that what
/// passes here is what `pe` accepts (each placement as written, and a robot's bodies and
/// pins where its placement in a scene puts them).
pub use pe::limits;

/// "`what` {value} is beyond ±{limit}" when `value` exceeds `limit` in magnitude or is
/// not a number at all.
pub fn beyond(what: &str, value: f64, limit: f64) -> Option<String> {
    if value.is_nan() {
        return Some(format!("{what} is not a number"));
    }
    let limit_text = if limit == std::f64::consts::PI {
        "π (half a turn a step)".to_string()
    } else {
        format!("{limit:e}")
    };
    (value.abs() > limit).then(|| format!("{what} {value:e} is beyond ±{limit_text}"))
}

/// The messages of every `(what, value, limit)` whose value is beyond its limit.
pub fn beyond_all(numbers: &[(&str, f64, f64)]) -> Vec<String> {
    numbers
        .iter()
        .filter_map(|&(what, value, limit)| beyond(what, value, limit))
        .collect()
}

// The number checks of each record, in one place: `check` reports them as problems of
// the files, and the simulation refuses to build a scene that has any (the editor runs
// models whatever their problems), so both say the same thing in the same words.

/// Why step `h` (seconds) is not one a scene may take, if it is not.
pub fn timestep_problem(h: f64) -> Option<String> {
    (!(TIMESTEP_RANGE.0..=TIMESTEP_RANGE.1).contains(&h)).then(|| {
        format!(
            "timestep {} s is outside [{}, {}] s",
            super::write::number(h),
            TIMESTEP_RANGE.0,
            TIMESTEP_RANGE.1
        )
    })
}

/// A scene's physical numbers: friction and gravitation (its step is checked by
/// [`timestep_problem`], since a run may choose another).
pub fn scene_number_problems(scene: &Scene) -> Vec<String> {
    let mut out = Vec::new();
    if scene.friction < 0.0 {
        out.push(format!("friction {} is negative", scene.friction));
    }
    out.extend(beyond_all(&[
        ("friction", scene.friction, limits::FRICTION),
        ("gravitation", scene.gravitation, limits::GRAVITY),
    ]));
    out
}

/// A body motor's (`<force>`) numbers: their ranges and signs.
pub fn body_motor_problems(m: &BodyMotorDef) -> Vec<String> {
    let mut out = beyond_all(&[
        ("angular", m.angular, limits::ANGULAR),
        ("startTorque", m.start_torque, limits::TORQUE),
        ("maxTorque", m.max_torque, limits::TORQUE),
        ("increase", m.increase, limits::INCREASE),
    ]);
    if m.max_torque < 0.0 || m.start_torque < 0.0 || m.increase < 0.0 {
        out.push(
            "startTorque, maxTorque and increase must be ≥ 0 (the sign of angular gives the direction)"
                .to_string(),
        );
    }
    out
}

/// A starting velocity's numbers beyond what the engine takes (`pe::limits`).
fn velocity_beyond(v: &StartVelocity) -> Vec<String> {
    beyond_all(&[
        ("vx", v.vx, limits::SPEED),
        ("vy", v.vy, limits::SPEED),
        ("omega", v.omega, limits::SPIN),
    ])
}

/// A joint's stops: within `pe::limits`, the lower not above the upper.
pub fn joint_limit_problems(j: &JointDef) -> Vec<String> {
    let mut out = beyond_all(&[
        ("lowerAngle", j.lower_angle.unwrap_or(0.0), limits::ANGLE),
        ("upperAngle", j.upper_angle.unwrap_or(0.0), limits::ANGLE),
    ]);
    if let (Some(lower), Some(upper)) = (j.lower_angle, j.upper_angle)
        && lower > upper
    {
        out.push(format!("lowerAngle {lower} is above upperAngle {upper}"));
    }
    out
}

/// A joint spring's numbers: stiffness and damping ≥ 0, all within `pe::limits`.
pub fn joint_spring_problems(s: &JointSpringDef) -> Vec<String> {
    let mut out = Vec::new();
    for (what, value) in [("stiffness", s.stiffness), ("damping", s.damping)] {
        if value < 0.0 {
            out.push(format!("{what} {value} must be ≥ 0"));
        }
    }
    out.extend(beyond_all(&[
        ("stiffness", s.stiffness, limits::TORQUE),
        ("damping", s.damping, limits::TORQUE),
        ("restAngle", s.rest_angle, limits::ANGLE),
    ]));
    out
}

/// A joint motor's numbers: its speed per step and its torque.
pub fn joint_motor_problems(m: &JointMotorDef) -> Vec<String> {
    let mut out = Vec::new();
    if m.max_torque < 0.0 {
        out.push(format!("maxTorque {} must be ≥ 0", m.max_torque));
    }
    if m.period == 1 {
        out.push("period 1 has no second half to turn back in: use 2 or more".to_string());
    }
    if m.period > 0 && m.target_angle.is_some() {
        out.push(
            "a servo (targetAngle) holds its angle: it cannot also swing (period)".to_string(),
        );
    }
    out.extend(beyond_all(&[(
        "targetAngle",
        m.target_angle.unwrap_or(0.0),
        limits::ANGLE,
    )]));
    if let Some([first, second]) = &m.keys {
        let named = |k: &str| crate::model::is_motor_key_name(k);
        if !named(first) || !named(second) || first == second {
            out.push(format!(
                "keys=\"{} {}\" is not two different keys of Left, Right, Up, Down, A–Z, 0–9",
                clip(first),
                clip(second)
            ));
        }
    }
    out.extend(beyond_all(&[
        ("angular", m.angular, limits::ANGULAR),
        ("maxTorque", m.max_torque, limits::TORQUE),
    ]));
    out
}

/// All problems of `model`, whose files are named by `file`.
pub fn check(model: &Model, file: impl Fn(FileKind) -> String) -> Vec<Problem> {
    let mut out = Vec::new();
    let bodies_file = file(FileKind::Bodies);
    let robots_file = file(FileKind::Robots);
    let scenes_file = file(FileKind::Scenes);
    duplicates(
        model.bodies.iter().map(|b| (&b.name, b.location)),
        &bodies_file,
        "body",
        &mut out,
    );
    for body in &model.bodies {
        check_body(body, &bodies_file, &mut out);
    }
    duplicates(
        model.robots.iter().map(|r| (&r.name, r.location)),
        &robots_file,
        "robot",
        &mut out,
    );
    for robot in &model.robots {
        check_robot(model, robot, &robots_file, &mut out);
    }
    duplicates(
        model.scenes.iter().map(|s| (&s.name, s.location)),
        &scenes_file,
        "scene",
        &mut out,
    );
    for scene in &model.scenes {
        check_scene(model, scene, &scenes_file, &mut out);
    }
    out
}

fn duplicates<'a>(
    names: impl Iterator<Item = (&'a String, crate::model::Location)>,
    file: &str,
    kind: &str,
    out: &mut Vec<Problem>,
) {
    let mut first: BTreeMap<&str, usize> = BTreeMap::new();
    for (name, location) in names {
        let key = name.trim();
        if key.is_empty() {
            out.push(Problem::error(file, &format!("<{kind}>"), "the name is empty").at(location));
        } else if let Some(line) = first.get(key) {
            out.push(
                Problem::error(
                    file,
                    &format!("<{kind}> \"{}\"", clip(key)),
                    format!("the name is already used on line {line}"),
                )
                .at(location),
            );
        } else {
            first.insert(key, location.line);
        }
    }
}

/// The body's polygon, or why it is not one.
pub fn polygon(body: &BodyDef) -> Result<ConvexPolygon, pe::ShapeError> {
    outline_polygon(&body.vertices)
}

/// The polygon of an outline as the files store it (the editor checks drafts with it).
pub fn outline_polygon(vertices: &[[f64; 2]]) -> Result<ConvexPolygon, pe::ShapeError> {
    let points: Vec<Vec2> = vertices.iter().map(|v| Vec2::new(v[0], v[1])).collect();
    ConvexPolygon::new(&points)
}

fn check_body(body: &BodyDef, file: &str, out: &mut Vec<Problem>) {
    let what = format!("<body> \"{}\"", clip(&body.name));
    let mut error =
        |message: String| out.push(Problem::error(file, &what, message).at(body.location));
    if body.density < 0.0 {
        error(format!(
            "density {} is negative (0 makes a static body)",
            body.density
        ));
    }
    if !(0.0..=1.0).contains(&body.cor) {
        error(format!("cor {} is outside [0, 1]", body.cor));
    }
    if let Some(mu) = body.friction.filter(|mu| *mu < 0.0) {
        error(format!("friction {mu} is negative"));
    }
    match polygon(body) {
        Err(e) => error(format!("the vertices are not a usable convex polygon: {e}")),
        // What pe refuses to step, refused here in its words.
        Ok(polygon) if body.density > 0.0 && body.density.is_finite() => {
            let def = pe::BodyDef::new(polygon, body.density);
            if let Err(e @ pe::BodyError::TooLight(..)) = pe::Body::new(def) {
                error(e.to_string());
            }
        }
        Ok(_) => {}
    }
    let vertices = body
        .vertices
        .iter()
        .flatten()
        .map(|&v| ("vertex coordinate", v, limits::COORDINATE));
    let numbers = [
        ("density", body.density, limits::DENSITY),
        ("friction", body.friction.unwrap_or(0.0), limits::FRICTION),
    ];
    if let Some(message) = numbers
        .into_iter()
        .chain(vertices)
        .find_map(|(what, v, limit)| beyond(what, v, limit))
    {
        error(message);
    }
}

fn check_robot(model: &Model, robot: &Robot, file: &str, out: &mut Vec<Problem>) {
    let name = clip(&robot.name);
    let mut aliases: BTreeMap<&str, usize> = BTreeMap::new();
    for (i, b) in robot.bodies.iter().enumerate() {
        let p = &b.placement;
        let what = format!("<body> \"{}\" in robot \"{name}\"", clip(&p.alias));
        for message in beyond_all(&[
            ("x", p.x, limits::COORDINATE),
            ("y", p.y, limits::COORDINATE),
            ("orientation", p.orientation, limits::ANGLE),
        ])
        .into_iter()
        .chain(velocity_beyond(&p.velocity))
        {
            out.push(Problem::error(file, &what, message).at(p.location));
        }
        if aliases.insert(p.alias.trim(), i).is_some() {
            out.push(
                Problem::error(file, &what, "the alias is already used in this robot")
                    .at(p.location),
            );
        }
        if model.body(&p.source).is_none() {
            out.push(
                Problem::error(
                    file,
                    &what,
                    format!("source \"{}\" is not a body in bodies.xml", clip(&p.source)),
                )
                .at(p.location),
            );
        }
        check_body_motors(&b.motors, &what, file, out);
        let is_static = model.body(&p.source).is_some_and(|d| d.density == 0.0);
        if let Some(m) = b.motors.first().filter(|_| is_static) {
            out.push(
                Problem::warning(
                    file,
                    &format!("<force> on {what}"),
                    "the body is static (density 0): its motor turns nothing",
                )
                .at(m.location),
            );
        }
    }
    // Connectivity by union-find over aliases (thesis §4.1).
    let mut parent: Vec<usize> = (0..robot.bodies.len()).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for j in &robot.joints {
        let what = format!(
            "<joint> {}–{} in robot \"{name}\"",
            clip(&j.body_a),
            clip(&j.body_b)
        );
        let a = aliases.get(j.body_a.trim()).copied();
        let b = aliases.get(j.body_b.trim()).copied();
        for (end, alias, found) in [("bodyA", &j.body_a, a), ("bodyB", &j.body_b, b)] {
            if found.is_none() {
                out.push(
                    Problem::error(
                        file,
                        &what,
                        format!("{end} \"{}\" is not a body of this robot", clip(alias)),
                    )
                    .at(j.location),
                );
            }
        }
        for message in joint_limit_problems(j) {
            out.push(Problem::error(file, &what, message).at(j.location));
        }
        if let Some(spring) = &j.spring {
            for message in joint_spring_problems(spring) {
                out.push(Problem::error(file, &what, message).at(j.location));
            }
        }
        if let Some(m) = &j.motor {
            let motor = format!("<motor> of {what}");
            for message in joint_motor_problems(m) {
                out.push(Problem::error(file, &motor, message).at(m.location));
            }
        }
        for message in beyond_all(&[
            ("anchor coordinate", j.anchor_ax, limits::COORDINATE),
            ("anchor coordinate", j.anchor_ay, limits::COORDINATE),
        ]) {
            out.push(Problem::error(file, &what, message).at(j.location));
        }
        let (Some(a), Some(b)) = (a, b) else { continue };
        if a == b {
            out.push(
                Problem::error(file, &what, "a joint needs two different bodies").at(j.location),
            );
            continue;
        }
        let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
        parent[ra] = rb;
        // The pin should lie in both bodies (thesis §4.3.2: the centre of their overlap).
        let point = j.point(&robot.bodies[a].placement);
        let inside = [a, b]
            .iter()
            .any(|&i| lies_in(model, &robot.bodies[i].placement, point));
        if !inside {
            out.push(
                Problem::warning(
                    file,
                    &what,
                    format!(
                        "the pin at ({}, {}) lies in neither body",
                        point[0], point[1]
                    ),
                )
                .at(j.location),
            );
        }
    }
    let roots: std::collections::BTreeSet<usize> = (0..robot.bodies.len())
        .map(|i| root(&mut parent, i))
        .collect();
    if roots.len() > 1 {
        let first = root(&mut parent, 0);
        let loose: Vec<usize> = (0..robot.bodies.len())
            .filter(|&i| root(&mut parent, i) != first)
            .collect();
        // A few names, and how many more: the line stays a line for 30,000 loose bodies.
        const NAMED: usize = 5;
        let mut named: Vec<String> = loose
            .iter()
            .take(NAMED)
            .map(|&i| format!("\"{}\"", clip(&robot.bodies[i].placement.alias)))
            .collect();
        if loose.len() > NAMED {
            named.push(format!("and {} more", loose.len() - NAMED));
        }
        let loose = named.join(", ");
        out.push(
            Problem::error(
                file,
                &format!("<robot> \"{name}\""),
                format!(
                    "not all bodies are connected through joints: {loose} are not joined to \"{}\"",
                    clip(&robot.bodies[0].placement.alias)
                ),
            )
            .at(robot.location),
        );
    }
}

/// A body's motors (`<force>`): their times, ranges and signs.
fn check_body_motors(motors: &[BodyMotorDef], what: &str, file: &str, out: &mut Vec<Problem>) {
    for m in motors {
        let what = format!("<force> on {what}");
        if m.time1 < m.time0 {
            out.push(
                Problem::warning(file, &what, "time1 is before time0: the motor never runs")
                    .at(m.location),
            );
        }
        for message in body_motor_problems(m) {
            out.push(Problem::error(file, &what, message).at(m.location));
        }
    }
}

/// Whether `point` (robot coordinates) lies in the body placed by `placement`.
fn lies_in(model: &Model, placement: &Placement, point: [f64; 2]) -> bool {
    let p = placement;
    model
        .body(&p.source)
        .and_then(|d| polygon(d).ok())
        .is_some_and(|poly| {
            let (s, c) = p.orientation.sin_cos();
            let (dx, dy) = (point[0] - p.x, point[1] - p.y);
            poly.contains(Vec2::new(c * dx + s * dy, -s * dx + c * dy))
        })
}

fn check_scene(model: &Model, scene: &Scene, file: &str, out: &mut Vec<Problem>) {
    let what = format!("<scene> \"{}\"", clip(&scene.name));
    let mut error =
        |message: String| out.push(Problem::error(file, &what, message).at(scene.location));
    let step = scene.timestep.and_then(timestep_problem);
    for message in scene_number_problems(scene).into_iter().chain(step) {
        error(message);
    }
    if let Some(solver) = &scene.solver
        && ContactSolver::from_name(solver.trim()).is_none()
    {
        let names: Vec<_> = ContactSolver::ALL.iter().map(|s| s.name()).collect();
        error(format!(
            "solver \"{}\" is not one of {names:?}",
            clip(solver)
        ));
    }
    let what = format!("<robot> in scene \"{}\"", clip(&scene.name));
    for r in &scene.robots {
        for message in beyond_all(&[
            ("x", r.x, limits::COORDINATE),
            ("y", r.y, limits::COORDINATE),
            ("orientation", r.orientation, limits::ANGLE),
        ])
        .into_iter()
        .chain(velocity_beyond(&r.velocity))
        {
            out.push(Problem::error(file, &what, message).at(r.location));
        }
        if let Some(robot) = model.robot(&r.source) {
            for message in placed_robot_beyond(robot, r) {
                out.push(Problem::error(file, &what, message).at(r.location));
            }
        } else {
            out.push(
                Problem::error(
                    file,
                    &what,
                    format!(
                        "source \"{}\" is not a robot in robots.xml",
                        clip(&r.source)
                    ),
                )
                .at(r.location),
            );
        }
    }
    if let Some(message) = falls_too_far(model, scene) {
        let what = format!("<scene> \"{}\"", clip(&scene.name));
        out.push(Problem::error(file, &what, message).at(scene.location));
    }
    let mut aliases: BTreeMap<&str, ()> = BTreeMap::new();
    for b in &scene.bodies {
        let what = format!(
            "<body> \"{}\" in scene \"{}\"",
            clip(&b.alias),
            clip(&scene.name)
        );
        for message in beyond_all(&[
            ("x", b.x, limits::COORDINATE),
            ("y", b.y, limits::COORDINATE),
            ("orientation", b.orientation, limits::ANGLE),
        ])
        .into_iter()
        .chain(velocity_beyond(&b.velocity))
        {
            out.push(Problem::error(file, &what, message).at(b.location));
        }
        if aliases.insert(b.alias.trim(), ()).is_some() {
            out.push(
                Problem::error(file, &what, "the alias is already used in this scene")
                    .at(b.location),
            );
        }
        if model.body(&b.source).is_none() {
            out.push(
                Problem::error(
                    file,
                    &what,
                    format!("source \"{}\" is not a body in bodies.xml", clip(&b.source)),
                )
                .at(b.location),
            );
        }
    }
}

/// What pe would refuse at the scene's first step: gravity carrying a body more than
/// `pe::FALL_PER_STEP` length scales in a step (the length scale as the simulation takes
/// it: the median size of the scene's moving bodies).
fn falls_too_far(model: &Model, scene: &Scene) -> Option<String> {
    let robot_bodies = scene
        .robots
        .iter()
        .filter_map(|r| model.robot(&r.source))
        .flat_map(|r| r.bodies.iter().map(|b| &b.placement.source));
    let sources = scene.bodies.iter().map(|b| &b.source).chain(robot_bodies);
    let mut sizes: Vec<f64> = sources
        .filter_map(|source| model.body(source))
        .filter(|def| def.density > 0.0)
        .filter_map(|def| {
            let body = pe::Body::new(pe::BodyDef::new(polygon(def).ok()?, def.density)).ok()?;
            Some(body.bounding_radius())
        })
        .collect();
    sizes.sort_by(f64::total_cmp);
    let length_scale = sizes.get(sizes.len() / 2).copied().unwrap_or(1.0);
    let h = scene.timestep();
    let fall = scene.gravitation.abs() * h * h;
    let limit = pe::FALL_PER_STEP * length_scale;
    (fall > limit).then(|| {
        format!(
            "gravitation {} at timestep {} s carries a body {fall:.3e} per step from rest, \
             more than {} times the typical body's size ({length_scale:.3e}): bodies would \
             fall through each other; take a smaller timestep",
            super::write::number(scene.gravitation),
            super::write::number(h),
            pe::FALL_PER_STEP,
        )
    })
}

/// Where robot `robot`, placed in a scene by `placed`, puts its bodies and pins beyond the
/// engine's limits, though each placement is within them as written (those are reported
/// where they are written).
fn placed_robot_beyond(robot: &Robot, placed: &SceneRobot) -> Vec<String> {
    let frame = (placed.x, placed.y, placed.orientation);
    let within = |(x, y, angle): (f64, f64, f64)| {
        beyond_all(&[
            ("x", x, limits::COORDINATE),
            ("y", y, limits::COORDINATE),
            ("orientation", angle, limits::ANGLE),
        ])
        .is_empty()
    };
    if !within(frame) {
        return Vec::new();
    }
    let mut out = Vec::new();
    for b in &robot.bodies {
        let p = &b.placement;
        if !within((p.x, p.y, p.orientation)) {
            continue;
        }
        let (x, y, angle) = compose(frame, (p.x, p.y, p.orientation));
        for message in beyond_all(&[
            ("x", x, limits::COORDINATE),
            ("y", y, limits::COORDINATE),
            ("orientation", angle, limits::ANGLE),
        ]) {
            out.push(format!(
                "body \"{}\" of robot \"{}\", placed in the scene: {message}",
                clip(&p.alias),
                clip(&robot.name)
            ));
        }
    }
    let aliases = robot.alias_index();
    for j in &robot.joints {
        let Some(a) = aliases.get(j.body_a.trim()).map(|&i| &robot.bodies[i]) else {
            continue;
        };
        let [px, py] = j.point(&a.placement);
        if !within((px, py, 0.0)) {
            continue;
        }
        let (x, y, _) = compose(frame, (px, py, 0.0));
        for message in beyond_all(&[("x", x, limits::COORDINATE), ("y", y, limits::COORDINATE)]) {
            out.push(format!(
                "the pin of \"{}\" and \"{}\" (robot \"{}\"), placed in the scene: {message}",
                clip(&j.body_a),
                clip(&j.body_b),
                clip(&robot.name)
            ));
        }
    }
    out
}
