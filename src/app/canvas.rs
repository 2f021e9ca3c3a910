//! The canvas: draws a simulation with its debug overlays, pans and zooms, selects a body
//! by clicking it, and drags a body by the grabbed point while it runs.

use super::camera::Camera;
use crate::sim::Simulation;
use egui::{Color32, Pos2, Rect, Sense, Shape, Stroke};
use pe::{BodyHandle, Vec2};

/// Which overlays to draw.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DebugDraw {
    pub contacts: bool,
    pub joints: bool,
    pub bounds: bool,
    pub centres: bool,
    pub velocities: bool,
    pub grid: bool,
    /// The view follows the selected body, or the moving bodies' mean position.
    pub follow: bool,
}

impl Default for DebugDraw {
    fn default() -> Self {
        Self {
            contacts: true,
            joints: true,
            bounds: false,
            centres: false,
            velocities: false,
            grid: true,
            follow: true,
        }
    }
}

/// A body held by the mouse: a damped spring from the grabbed point (in body space) to the
/// pointer, scaled by the body's mass so light and heavy bodies follow alike.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grab {
    pub body: BodyHandle,
    pub local_point: Vec2,
    pub target: Vec2,
}

impl Grab {
    /// Spring frequency of the mouse joint (Hz) and its damping ratio.
    const FREQUENCY: f64 = 4.0;
    const DAMPING: f64 = 0.9;

    pub fn apply(&self, sim: &mut Simulation) {
        let Some(body) = sim.world.body_mut(self.body) else {
            return;
        };
        if body.is_static() {
            return;
        }
        let point = body.to_world(self.local_point);
        let omega = 2.0 * std::f64::consts::PI * Self::FREQUENCY;
        let m = body.mass();
        let force = (self.target - point) * (m * omega * omega)
            - body.velocity_at(point) * (2.0 * m * Self::DAMPING * omega);
        body.apply_force_at(force, point);
    }
}

pub struct Outcome {
    pub fitted: bool,
    pub selection_changed: bool,
}

const BACKGROUND: Color32 = Color32::from_rgb(24, 26, 30);

/// A stable colour per robot (bodies of one robot share it) or per loose body.
fn colour_for(id: &str) -> Color32 {
    let key = id.split('/').next().unwrap_or(id);
    let hash = key
        .bytes()
        .fold(2166136261u32, |h, b| (h ^ b as u32).wrapping_mul(16777619));
    let hue = (hash % 360) as f32 / 360.0;
    egui::ecolor::Hsva::new(hue, 0.45, 0.75, 1.0).into()
}

pub fn show(
    ui: &mut egui::Ui,
    sim: Option<&mut Simulation>,
    camera: &mut Camera,
    fit: bool,
    debug: &mut DebugDraw,
    grab: &mut Option<Grab>,
    selected: &mut Option<usize>,
) -> Outcome {
    let (response, painter) = ui.allocate_painter(ui.available_size(), Sense::click_and_drag());
    let rect = response.rect;
    painter.rect_filled(rect, 0.0, BACKGROUND);
    let mut outcome = Outcome {
        fitted: false,
        selection_changed: false,
    };
    let Some(sim) = sim else {
        painter.text(
            rect.center(),
            egui::Align2::CENTER_CENTER,
            "nothing to show",
            egui::FontId::proportional(16.0),
            Color32::GRAY,
        );
        return outcome;
    };
    if fit {
        if let Some((min, max)) = bounds(sim) {
            camera.fit(rect, min, max);
        }
        outcome.fitted = true;
    }
    // Pan with the secondary or middle button, zoom with the wheel about the pointer.
    if response.dragged_by(egui::PointerButton::Secondary)
        || response.dragged_by(egui::PointerButton::Middle)
    {
        let d = response.drag_delta();
        camera.centre -= Vec2::new(d.x as f64, d.y as f64) / camera.zoom;
        debug.follow = false;
    }
    if debug.follow
        && !fit
        && let Some(target) = follow_point(sim, *selected)
    {
        // Ease towards the target so that the view does not shake with the bodies.
        camera.centre += (target - camera.centre) * 0.1;
    }
    if let Some(hover) = response.hover_pos() {
        let scroll = ui.input(|i| i.smooth_scroll_delta.y);
        if scroll != 0.0 {
            camera.zoom_about(rect, hover, (scroll as f64 * 0.002).exp());
        }
    }
    // Select or grab with the primary button.
    let pointer_world = response
        .interact_pointer_pos()
        .map(|p| camera.to_world(rect, p));
    if response.drag_started_by(egui::PointerButton::Primary) || response.clicked() {
        let hit = pointer_world.and_then(|p| body_at(sim, p));
        if *selected != hit {
            *selected = hit;
            outcome.selection_changed = true;
        }
        if response.drag_started_by(egui::PointerButton::Primary)
            && let (Some(i), Some(p)) = (hit, pointer_world)
            && let Some(body) = sim.world.body(sim.bodies[i].handle)
            && !body.is_static()
        {
            *grab = Some(Grab {
                body: sim.bodies[i].handle,
                local_point: body.to_local(p),
                target: p,
            });
        }
    }
    if let (Some(g), Some(p)) = (grab.as_mut(), pointer_world) {
        g.target = p;
    }
    if response.drag_stopped() || !ui.input(|i| i.pointer.primary_down()) {
        *grab = None;
    }

    if debug.grid {
        draw_grid(&painter, rect, camera);
    }
    let to_screen = |p: Vec2| camera.to_screen(rect, p);
    for (i, b) in sim.bodies.iter().enumerate() {
        let Some(body) = sim.world.body(b.handle) else {
            continue;
        };
        let points: Vec<Pos2> = body.world_vertices().map(to_screen).collect();
        let fill = if body.is_static() {
            Color32::from_rgb(70, 74, 82)
        } else {
            colour_for(&b.id)
        };
        let stroke = if *selected == Some(i) {
            Stroke::new(2.5, Color32::from_rgb(255, 220, 80))
        } else {
            Stroke::new(1.0, Color32::from_gray(230))
        };
        painter.add(Shape::convex_polygon(
            points,
            fill.gamma_multiply(0.85),
            stroke,
        ));
        if debug.centres {
            painter.circle_filled(to_screen(body.centroid()), 3.0, Color32::BLACK);
            painter.circle_stroke(
                to_screen(body.centroid()),
                3.0,
                Stroke::new(1.0, Color32::WHITE),
            );
        }
        if debug.velocities && !body.is_static() {
            let c = body.centroid();
            let tip = c + body.velocity * 0.1;
            painter.arrow(
                to_screen(c),
                to_screen(tip) - to_screen(c),
                Stroke::new(1.5, Color32::LIGHT_GREEN),
            );
        }
        if debug.bounds {
            let (mut min, mut max) = (Vec2::repeat(f64::INFINITY), Vec2::repeat(f64::NEG_INFINITY));
            for v in body.world_vertices() {
                min = min.inf(&v);
                max = max.sup(&v);
            }
            painter.rect_stroke(
                Rect::from_two_pos(to_screen(min), to_screen(max)),
                0.0,
                Stroke::new(1.0, Color32::from_rgb(120, 200, 255)),
                egui::StrokeKind::Middle,
            );
        }
    }
    if debug.joints {
        for j in &sim.joints {
            if let Some((a, b)) = sim.world.joint_anchors(j.handle) {
                painter.line_segment([to_screen(a), to_screen(b)], Stroke::new(2.0, Color32::RED));
                painter.circle_stroke(
                    to_screen(a),
                    4.0,
                    Stroke::new(1.5, Color32::from_rgb(255, 160, 40)),
                );
                painter.circle_filled(to_screen(b), 2.0, Color32::from_rgb(255, 160, 40));
            }
        }
    }
    if debug.contacts {
        for c in sim.world.contacts() {
            let p = to_screen(c.point);
            painter.circle_filled(p, 2.5, Color32::from_rgb(240, 90, 60));
            let n = egui::vec2(c.normal.x as f32, c.normal.y as f32) * 12.0;
            painter.line_segment([p, p + n], Stroke::new(1.0, Color32::from_rgb(240, 90, 60)));
        }
    }
    if let Some(g) = grab
        && let Some(body) = sim.world.body(g.body)
    {
        let from = to_screen(body.to_world(g.local_point));
        painter.line_segment(
            [from, to_screen(g.target)],
            Stroke::new(1.5, Color32::WHITE),
        );
        painter.circle_filled(from, 3.0, Color32::WHITE);
    }
    outcome
}

/// The selected body's centroid, or the mean centroid of the moving bodies.
fn follow_point(sim: &Simulation, selected: Option<usize>) -> Option<Vec2> {
    if let Some(body) = selected
        .and_then(|i| sim.bodies.get(i))
        .and_then(|b| sim.world.body(b.handle))
    {
        return Some(body.centroid());
    }
    let moving: Vec<Vec2> = sim
        .world
        .bodies()
        .filter(|(_, b)| !b.is_static())
        .map(|(_, b)| b.centroid())
        .collect();
    (!moving.is_empty()).then(|| moving.iter().sum::<Vec2>() / moving.len() as f64)
}

/// The index of the topmost body under `p`.
fn body_at(sim: &Simulation, p: Vec2) -> Option<usize> {
    sim.bodies.iter().enumerate().rev().find_map(|(i, b)| {
        let body = sim.world.body(b.handle)?;
        let verts: Vec<Vec2> = body.world_vertices().collect();
        let inside = (0..verts.len()).all(|k| {
            let (a, c) = (verts[k], verts[(k + 1) % verts.len()]);
            pe::math::cross(c - a, p - a) >= 0.0
        }) || (0..verts.len()).all(|k| {
            let (a, c) = (verts[k], verts[(k + 1) % verts.len()]);
            pe::math::cross(c - a, p - a) <= 0.0
        });
        inside.then_some(i)
    })
}

/// The world rectangle around every body, the static ones clipped to the dynamic ones'
/// neighbourhood so that a long floor does not shrink the robots to dots.
fn bounds(sim: &Simulation) -> Option<(Vec2, Vec2)> {
    let mut min = Vec2::repeat(f64::INFINITY);
    let mut max = Vec2::repeat(f64::NEG_INFINITY);
    let mut any_dynamic = false;
    for (_, body) in sim.world.bodies() {
        if body.is_static() {
            continue;
        }
        any_dynamic = true;
        for v in body.world_vertices() {
            min = min.inf(&v);
            max = max.sup(&v);
        }
    }
    if !any_dynamic {
        for (_, body) in sim.world.bodies() {
            for v in body.world_vertices() {
                min = min.inf(&v);
                max = max.sup(&v);
            }
        }
    }
    if !min.x.is_finite() {
        return None;
    }
    // Room around the bodies for them to move, and the ground below them.
    let size = (max - min).norm().max(50.0);
    Some((
        min - Vec2::repeat(0.6 * size),
        max + Vec2::repeat(0.6 * size),
    ))
}

fn draw_grid(painter: &egui::Painter, rect: Rect, camera: &Camera) {
    // A spacing that stays between 25 and 250 screen points at any zoom.
    let mut spacing = 10f64.powf((25.0 / camera.zoom).log10().ceil());
    if spacing * camera.zoom > 250.0 {
        spacing /= 10.0;
    }
    let min = camera.to_world(rect, rect.min);
    let max = camera.to_world(rect, rect.max);
    let colour = Color32::from_gray(40);
    let mut x = (min.x / spacing).floor() * spacing;
    while x <= max.x {
        let sx = camera.to_screen(rect, Vec2::new(x, 0.0)).x;
        painter.line_segment(
            [Pos2::new(sx, rect.top()), Pos2::new(sx, rect.bottom())],
            Stroke::new(1.0, colour),
        );
        x += spacing;
    }
    let mut y = (min.y / spacing).floor() * spacing;
    while y <= max.y {
        let sy = camera.to_screen(rect, Vec2::new(0.0, y)).y;
        painter.line_segment(
            [Pos2::new(rect.left(), sy), Pos2::new(rect.right(), sy)],
            Stroke::new(1.0, colour),
        );
        y += spacing;
    }
}
