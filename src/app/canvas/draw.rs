//! The picture of a simulation as egui shapes in screen points: the canvas paints them and
//! the SVG export writes the same list, so that an exported view is what was on screen.

use super::DebugDraw;
use crate::app::camera::Camera;
use crate::sim::Simulation;
use egui::{Color32, Pos2, Rect, Shape, Stroke};
use pe::Vec2;

pub const BACKGROUND: Color32 = Color32::from_rgb(24, 26, 30);
pub const OVERLAP: Color32 = Color32::from_rgb(255, 90, 70);
const SELECTED: Color32 = Color32::from_rgb(255, 220, 80);
const TERRAIN: Color32 = Color32::from_rgb(70, 74, 82);
const CONTACT: Color32 = Color32::from_rgb(240, 90, 60);
const PIN: Color32 = Color32::from_rgb(255, 160, 40);
/// A joint's stops (`stops_arc`).
const STOPS: Color32 = Color32::from_rgb(120, 220, 255);

/// What to draw besides the bodies.
#[derive(Debug, Clone, Copy)]
pub struct Highlights<'a> {
    /// Bodies (indices into `sim.bodies`) outlined as selected.
    pub selected: &'a [usize],
    /// Pairs outlined as overlapping (at step 0 only).
    pub overlaps: &'a [(usize, usize)],
}

/// A stable colour per robot (bodies of one robot share it) or per loose body.
pub fn colour_for(id: &str) -> Color32 {
    let key = id.split('/').next().unwrap_or(id);
    let hash = key
        .bytes()
        .fold(2166136261u32, |h, b| (h ^ b as u32).wrapping_mul(16777619));
    let hue = (hash % 360) as f32 / 360.0;
    egui::ecolor::Hsva::new(hue, 0.45, 0.75, 1.0).into()
}

/// Indices into `sim.bodies` bottom first: static bodies (the terrain) under the moving
/// ones, each group in scene order.
pub fn drawing_order(sim: &Simulation) -> Vec<usize> {
    let is_static = |i: usize| {
        sim.world
            .body(sim.bodies[i].handle)
            .is_none_or(|b| b.is_static())
    };
    let (mut order, moving): (Vec<usize>, Vec<usize>) =
        (0..sim.bodies.len()).partition(|&i| is_static(i));
    order.extend(moving);
    order
}

/// The grid, the bodies and the debug overlays of `sim` seen by `camera` in `rect`.
pub fn scene(
    sim: &Simulation,
    camera: &Camera,
    rect: Rect,
    debug: &DebugDraw,
    marks: Highlights<'_>,
) -> Vec<Shape> {
    let mut shapes = vec![Shape::rect_filled(rect, 0.0, BACKGROUND)];
    if debug.grid {
        grid(&mut shapes, rect, camera);
    }
    let to_screen = |p: Vec2| camera.to_screen(rect, p);
    let overlapping = |i: usize| marks.overlaps.iter().any(|&(a, b)| a == i || b == i);
    for i in drawing_order(sim) {
        let b = &sim.bodies[i];
        let Some(body) = sim.world.body(b.handle) else {
            continue;
        };
        let points: Vec<Pos2> = body.world_vertices().map(to_screen).collect();
        let fill = if body.is_static() {
            TERRAIN
        } else {
            colour_for(&b.id)
        };
        let stroke = if marks.selected.contains(&i) {
            Stroke::new(2.5, SELECTED)
        } else if overlapping(i) {
            Stroke::new(2.0, OVERLAP)
        } else {
            Stroke::new(1.0, Color32::from_gray(230))
        };
        let asleep = debug.sleeping && body.is_asleep();
        shapes.push(Shape::convex_polygon(
            points,
            fill.gamma_multiply(if asleep { 0.4 } else { 0.85 }),
            stroke,
        ));
        if asleep {
            let z = to_screen(body.position);
            shapes.push(Shape::line_segment(
                [z + egui::vec2(-3.0, -3.0), z + egui::vec2(3.0, -3.0)],
                Stroke::new(1.0, Color32::from_gray(200)),
            ));
            shapes.push(Shape::line_segment(
                [z + egui::vec2(3.0, -3.0), z + egui::vec2(-3.0, 3.0)],
                Stroke::new(1.0, Color32::from_gray(200)),
            ));
            shapes.push(Shape::line_segment(
                [z + egui::vec2(-3.0, 3.0), z + egui::vec2(3.0, 3.0)],
                Stroke::new(1.0, Color32::from_gray(200)),
            ));
        }
        // At step 0 a body given a starting velocity shows it (vx, vy, omega).
        let starts_moving = sim.step_count() == 0
            && !body.is_static()
            && (body.velocity.norm() > 0.0 || body.angular_velocity != 0.0);
        body_overlays(&mut shapes, body, debug, starts_moving, &to_screen);
    }
    joints_and_contacts(&mut shapes, sim, debug, &to_screen);
    shapes
}

/// Centre of mass, velocity and bounding box of one body, as `debug` asks; its velocity
/// also where `starts_moving` (a starting velocity, shown at step 0).
fn body_overlays(
    shapes: &mut Vec<Shape>,
    body: &pe::Body,
    debug: &DebugDraw,
    starts_moving: bool,
    to_screen: &impl Fn(Vec2) -> Pos2,
) {
    if debug.centres {
        let c = to_screen(body.centroid());
        shapes.push(Shape::circle_filled(c, 3.0, Color32::BLACK));
        shapes.push(Shape::circle_stroke(
            c,
            3.0,
            Stroke::new(1.0, Color32::WHITE),
        ));
    }
    if (debug.velocities || starts_moving) && !body.is_static() {
        let c = body.centroid();
        let (from, to) = (to_screen(c), to_screen(c + body.velocity * 0.1));
        let stroke = Stroke::new(1.5, Color32::LIGHT_GREEN);
        shapes.push(Shape::line_segment([from, to], stroke));
        let back = (from - to).normalized() * 6.0;
        shapes.push(Shape::line_segment([to, to + back.rot90() + back], stroke));
        shapes.push(Shape::line_segment([to, to - back.rot90() + back], stroke));
    }
    if debug.bounds
        && let Some(aabb) = crate::app::placing::bounds_of(body.world_vertices())
    {
        shapes.push(Shape::rect_stroke(
            Rect::from_two_pos(to_screen(aabb.min), to_screen(aabb.max)),
            0.0,
            Stroke::new(1.0, Color32::from_rgb(120, 200, 255)),
            egui::StrokeKind::Middle,
        ));
    }
}

fn joints_and_contacts(
    shapes: &mut Vec<Shape>,
    sim: &Simulation,
    debug: &DebugDraw,
    to_screen: &impl Fn(Vec2) -> Pos2,
) {
    if debug.joints {
        for j in &sim.joints {
            if let Some((a, b)) = sim.world.joint_anchors(j.handle) {
                let (a, b) = (to_screen(a), to_screen(b));
                shapes.push(Shape::line_segment([a, b], Stroke::new(2.0, Color32::RED)));
                shapes.push(Shape::circle_stroke(a, 4.0, Stroke::new(1.5, PIN)));
                shapes.push(Shape::circle_filled(b, 2.0, PIN));
                stops_arc(shapes, sim, j.handle, a);
            }
        }
    }
    if debug.contacts {
        for c in sim.world.contacts() {
            let p = to_screen(c.point);
            shapes.push(Shape::circle_filled(p, 2.5, CONTACT));
            let n = egui::vec2(c.normal.x as f32, c.normal.y as f32) * 12.0;
            shapes.push(Shape::line_segment([p, p + n], Stroke::new(1.0, CONTACT)));
        }
    }
}

/// A joint's stops as an arc about its pin at `at` (screen): the directions body B's x
/// axis may take (θ from the lower stop to the upper, a turn at most), a tick at each
/// stop and a line where it points now.
fn stops_arc(shapes: &mut Vec<Shape>, sim: &Simulation, joint: pe::JointHandle, at: Pos2) {
    use std::f64::consts::PI;
    let Some(j) = sim.world.joint(joint) else {
        return;
    };
    let (Some(limits), Some(theta)) = (j.limits, sim.world.joint_angle(joint)) else {
        return;
    };
    let zero = sim.world.body(j.body_a).map_or(0.0, |a| a.angle) + j.reference_angle;
    let (lower, upper) = (limits.lower.max(-PI), limits.upper.min(PI));
    let towards = |angle: f64, radius: f32| {
        let (s, c) = (zero + angle).sin_cos();
        at + egui::vec2(c as f32, s as f32) * radius
    };
    let stroke = Stroke::new(1.5, STOPS);
    const RADIUS: f32 = 22.0;
    let segments = ((upper - lower) / (PI / 24.0)).ceil().max(1.0) as usize;
    let arc: Vec<Pos2> = (0..=segments)
        .map(|k| towards(lower + (upper - lower) * k as f64 / segments as f64, RADIUS))
        .collect();
    shapes.push(Shape::line(arc, stroke));
    for (stop, kept) in [(lower, limits.lower >= -PI), (upper, limits.upper <= PI)] {
        if kept {
            shapes.push(Shape::line_segment(
                [towards(stop, RADIUS - 4.0), towards(stop, RADIUS + 4.0)],
                stroke,
            ));
        }
    }
    shapes.push(Shape::line_segment(
        [at, towards(theta, RADIUS + 6.0)],
        stroke,
    ));
}

/// Grid lines at a spacing that stays between 25 and 250 screen points at any zoom.
pub fn grid(shapes: &mut Vec<Shape>, rect: Rect, camera: &Camera) {
    let mut spacing = 10f64.powf((25.0 / camera.zoom).log10().ceil());
    if spacing * camera.zoom > 250.0 {
        spacing /= 10.0;
    }
    let min = camera.to_world(rect, rect.min);
    let max = camera.to_world(rect, rect.max);
    let stroke = Stroke::new(1.0, Color32::from_gray(40));
    let mut x = (min.x / spacing).floor() * spacing;
    while x <= max.x {
        let sx = camera.to_screen(rect, Vec2::new(x, 0.0)).x;
        shapes.push(Shape::line_segment(
            [Pos2::new(sx, rect.top()), Pos2::new(sx, rect.bottom())],
            stroke,
        ));
        x += spacing;
    }
    let mut y = (min.y / spacing).floor() * spacing;
    while y <= max.y {
        let sy = camera.to_screen(rect, Vec2::new(0.0, y)).y;
        shapes.push(Shape::line_segment(
            [Pos2::new(rect.left(), sy), Pos2::new(rect.right(), sy)],
            stroke,
        ));
        y += spacing;
    }
}

/// A line of text over the canvas below its hint (`row` 1, 2, …), as a label that
/// screen readers and tests can find.
pub fn note(ui: &mut egui::Ui, canvas: Rect, row: usize, colour: Color32, text: &str) {
    let top = canvas.top() + 8.0 + 20.0 * row as f32;
    let area = Rect::from_min_max(
        egui::pos2(canvas.left() + 8.0, top),
        egui::pos2(canvas.right() - 8.0, top + 20.0),
    );
    ui.scope_builder(egui::UiBuilder::new().max_rect(area), |ui| {
        ui.add(egui::Label::new(egui::RichText::new(text).color(colour)).selectable(false));
    });
}

/// A path's stroke colour (the canvas only draws plain colours).
fn path_colour(stroke: &egui::epaint::PathStroke) -> Color32 {
    match &stroke.color {
        egui::epaint::ColorMode::Solid(c) => *c,
        _ => Color32::GRAY,
    }
}

/// `attribute="rgb(…)" attribute-opacity="…"` for an SVG element.
fn paint(attribute: &str, c: Color32) -> String {
    let [r, g, b, a] = c.to_srgba_unmultiplied();
    format!(
        "{attribute}=\"rgb({r},{g},{b})\" {attribute}-opacity=\"{:.3}\"",
        a as f32 / 255.0
    )
}

/// `shapes` (as `scene` makes them) as an SVG document of the canvas `rect`.
pub fn svg(shapes: &[Shape], rect: Rect) -> String {
    let mut out = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" viewBox=\"{x} {y} {w} {h}\">\n",
        x = rect.left(),
        y = rect.top(),
        w = rect.width(),
        h = rect.height()
    );
    for shape in shapes {
        match shape {
            Shape::Rect(r) => out.push_str(&format!(
                "<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" {} {} stroke-width=\"{}\"/>\n",
                r.rect.left(),
                r.rect.top(),
                r.rect.width(),
                r.rect.height(),
                paint("fill", r.fill),
                paint("stroke", r.stroke.color),
                r.stroke.width
            )),
            Shape::Path(p) => {
                let points: Vec<String> = p
                    .points
                    .iter()
                    .map(|q| format!("{},{}", q.x, q.y))
                    .collect();
                let tag = if p.closed { "polygon" } else { "polyline" };
                out.push_str(&format!(
                    "<{tag} points=\"{}\" {} {} stroke-width=\"{}\"/>\n",
                    points.join(" "),
                    paint("fill", p.fill),
                    paint("stroke", path_colour(&p.stroke)),
                    p.stroke.width
                ));
            }
            Shape::LineSegment { points, stroke } => out.push_str(&format!(
                "<line x1=\"{}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" {} stroke-width=\"{}\"/>\n",
                points[0].x,
                points[0].y,
                points[1].x,
                points[1].y,
                paint("stroke", stroke.color),
                stroke.width
            )),
            Shape::Circle(c) => out.push_str(&format!(
                "<circle cx=\"{}\" cy=\"{}\" r=\"{}\" {} {} stroke-width=\"{}\"/>\n",
                c.center.x,
                c.center.y,
                c.radius,
                paint("fill", c.fill),
                paint("stroke", c.stroke.color),
                c.stroke.width
            )),
            _ => {}
        }
    }
    out.push_str("</svg>\n");
    out
}
