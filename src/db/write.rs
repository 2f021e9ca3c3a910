//! Model records back to the three files' text, in the element and attribute names of
//! thesis §4.3; extensions only where a record uses them, unknown attributes kept.

use crate::model::{BodyDef, ExtraAttributes, Robot, Scene, StartVelocity};
use quick_xml::escape::escape;
use std::fmt::Write;

/// The shortest text that reads back to the same f64: whole numbers without a point
/// (`1000000`, as a person would type them), everything else as Rust's round-trip repr.
pub fn number(v: f64) -> String {
    if v.fract() == 0.0 && v.abs() < 1e15 {
        format!("{v}")
    } else {
        format!("{v:?}")
    }
}

/// `value` escaped for a double-quoted attribute. Tabs and line breaks are written as
/// character references: a reader turns literal ones into spaces (XML's attribute-value
/// normalization), so a name with a newline would not load back the same.
fn attribute_value(value: &str) -> String {
    let escaped = escape(value);
    if !escaped.contains(['\t', '\n', '\r']) {
        return escaped.into_owned();
    }
    escaped
        .replace('\t', "&#9;")
        .replace('\n', "&#10;")
        .replace('\r', "&#13;")
}

struct Tag {
    text: String,
}

impl Tag {
    fn open(indent: usize, name: &str) -> Self {
        Self {
            text: format!("{:indent$}<{name}", "", indent = indent),
        }
    }

    fn text(mut self, key: &str, value: &str) -> Self {
        let _ = write!(self.text, " {key}=\"{}\"", attribute_value(value));
        self
    }

    fn num(self, key: &str, value: f64) -> Self {
        self.text(key, &number(value))
    }

    /// The starting velocity's attributes that are not 0 (a placement at rest has none).
    fn velocity(self, v: &StartVelocity) -> Self {
        [("vx", v.vx), ("vy", v.vy), ("omega", v.omega)]
            .into_iter()
            .filter(|&(_, value)| value != 0.0)
            .fold(self, |tag, (key, value)| tag.num(key, value))
    }

    fn extra(mut self, extra: &ExtraAttributes) -> Self {
        for (k, v) in extra {
            self = self.text(k, v);
        }
        self
    }

    /// `<name …/>`
    fn empty(self, out: &mut String) {
        out.push_str(&self.text);
        out.push_str("/>\n");
    }

    /// `<name …>`, children to follow.
    fn start(self, out: &mut String) {
        out.push_str(&self.text);
        out.push_str(">\n");
    }
}

const HEADER: &str = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";

/// A file of `records` under `root`: each record as `kept` gives its text (an unchanged
/// record's, as it was in the file) or else as `render` writes it.
pub fn file<T>(
    root: &str,
    records: &[T],
    kept: impl Fn(&T) -> Option<std::sync::Arc<str>>,
    render: impl Fn(&T, &mut String),
) -> String {
    let mut out = format!("{HEADER}<{root}>\n");
    for r in records {
        match kept(r) {
            Some(text) => {
                out.push_str("  ");
                out.push_str(&text);
                out.push('\n');
            }
            None => render(r, &mut out),
        }
    }
    let _ = writeln!(out, "</{root}>");
    out
}

pub fn bodies(bodies: &[BodyDef]) -> String {
    file("bodies", bodies, |_| None, body)
}

pub fn robots(robots: &[Robot]) -> String {
    file("robots", robots, |_| None, robot)
}

pub fn scenes(scenes: &[Scene]) -> String {
    file("scenes", scenes, |_| None, scene)
}

/// One `<body>` record.
pub fn body(b: &BodyDef, out: &mut String) {
    let mut tag = Tag::open(2, "body")
        .text("name", &b.name)
        .num("density", b.density)
        .num("cor", b.cor);
    if let Some(mu) = b.friction {
        tag = tag.num("friction", mu);
    }
    tag.extra(&b.extra).start(out);
    for v in &b.vertices {
        Tag::open(4, "vertex")
            .num("x", v[0])
            .num("y", v[1])
            .empty(out);
    }
    out.push_str("  </body>\n");
}

/// One `<robot>` record.
pub fn robot(r: &Robot, out: &mut String) {
    Tag::open(2, "robot")
        .text("name", &r.name)
        .extra(&r.extra)
        .start(out);
    for b in &r.bodies {
        let p = &b.placement;
        let tag = Tag::open(4, "body")
            .text("alias", &p.alias)
            .text("source", &p.source)
            .num("x", p.x)
            .num("y", p.y)
            .num("orientation", p.orientation)
            .velocity(&p.velocity)
            .extra(&p.extra);
        if b.motors.is_empty() {
            tag.empty(out);
            continue;
        }
        tag.start(out);
        for m in &b.motors {
            Tag::open(6, "force")
                .num("time0", m.time0 as f64)
                .num("time1", m.time1 as f64)
                .num("angular", m.angular)
                .num("startTorque", m.start_torque)
                .num("maxTorque", m.max_torque)
                .num("increase", m.increase)
                .extra(&m.extra)
                .empty(out);
        }
        out.push_str("    </body>\n");
    }
    for j in &r.joints {
        let mut tag = Tag::open(4, "joint")
            .text("bodyA", &j.body_a)
            .text("bodyB", &j.body_b)
            .num("anchorAx", j.anchor_ax)
            .num("anchorAy", j.anchor_ay);
        if j.collide {
            tag = tag.text("collide", "true");
        }
        if let Some(lower) = j.lower_angle {
            tag = tag.num("lowerAngle", lower);
        }
        if let Some(upper) = j.upper_angle {
            tag = tag.num("upperAngle", upper);
        }
        if let Some(spring) = &j.spring {
            tag = tag
                .num("stiffness", spring.stiffness)
                .num("damping", spring.damping)
                .num("restAngle", spring.rest_angle);
        }
        let tag = tag.extra(&j.extra);
        match &j.motor {
            None => tag.empty(out),
            Some(m) => {
                tag.start(out);
                let mut motor = Tag::open(6, "motor")
                    .num("time0", m.time0 as f64)
                    .num("time1", m.time1 as f64)
                    .num("angular", m.angular)
                    .num("maxTorque", m.max_torque);
                if m.period > 0 {
                    motor = motor.num("period", m.period as f64);
                }
                if let Some(angle) = m.target_angle {
                    motor = motor.num("targetAngle", angle);
                }
                if let Some([first, second]) = &m.keys {
                    motor = motor.text("keys", &format!("{first} {second}"));
                }
                motor.extra(&m.extra).empty(out);
                out.push_str("    </joint>\n");
            }
        }
    }
    out.push_str("  </robot>\n");
}

/// One `<scene>` record.
pub fn scene(s: &Scene, out: &mut String) {
    let mut tag = Tag::open(2, "scene")
        .text("name", &s.name)
        .num("gravitation", s.gravitation)
        .num("friction", s.friction);
    if let Some(h) = s.timestep {
        tag = tag.num("timestep", h);
    }
    if let Some(solver) = &s.solver {
        tag = tag.text("solver", solver);
    }
    tag.extra(&s.extra).start(out);
    for r in &s.robots {
        Tag::open(4, "robot")
            .text("source", &r.source)
            .num("x", r.x)
            .num("y", r.y)
            .num("orientation", r.orientation)
            .velocity(&r.velocity)
            .extra(&r.extra)
            .empty(out);
    }
    for b in &s.bodies {
        Tag::open(4, "body")
            .text("alias", &b.alias)
            .text("source", &b.source)
            .num("x", b.x)
            .num("y", b.y)
            .num("orientation", b.orientation)
            .velocity(&b.velocity)
            .extra(&b.extra)
            .empty(out);
    }
    out.push_str("  </scene>\n");
}
