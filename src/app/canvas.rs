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
    /// Sleeping bodies drawn faded, with a "z".
    pub sleeping: bool,
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
            sleeping: true,
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
        sim.world.wake_body(self.body);
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

/// How this frame's canvas behaves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Mode {
    /// Frame the bodies (a new scene was just shown).
    pub fit: bool,
    /// Paused at step 0: dragging a body moves its placement instead of grabbing it.
    pub editing: bool,
    /// What a primary click does while editing.
    pub tool: super::tools::Tool,
}

pub struct Outcome {
    pub fitted: bool,
    pub selection_changed: bool,
    /// While editing: the body (index into `sim.bodies`) being dragged, and where the
    /// pointer asks its reference point to be.
    pub moved: Option<(usize, Vec2)>,
    /// While editing with a tool other than Select: the clicked world point.
    pub tool_click: Option<Vec2>,
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
    mode: Mode,
    debug: &mut DebugDraw,
    grab: &mut Option<Grab>,
    selected: &mut Option<usize>,
) -> Outcome {
    let Mode { fit, editing, tool } = mode;
    let (response, painter) = ui.allocate_painter(ui.available_size(), Sense::click_and_drag());
    let rect = response.rect;
    painter.rect_filled(rect, 0.0, BACKGROUND);
    let mut outcome = Outcome {
        fitted: false,
        selection_changed: false,
        moved: None,
        tool_click: None,
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
    // Following stops while editing: the view must hold still under the user's clicks.
    if debug.follow
        && !fit
        && !editing
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
    let selecting = !editing || tool == super::tools::Tool::Select;
    if editing && !selecting && response.clicked() {
        outcome.tool_click = pointer_world;
    }
    // A drag is recognised only once the pointer has moved a few pixels: pick and grab
    // where the button went down, not where the pointer is by then.
    let press_world = ui
        .input(|i| i.pointer.press_origin())
        .map(|p| camera.to_world(rect, p));
    let drag_started = response.drag_started_by(egui::PointerButton::Primary);
    let offset_id = response.id.with("placement drag offset");
    if selecting && (drag_started || response.clicked()) {
        let picked_at = if drag_started {
            press_world
        } else {
            pointer_world
        };
        let hit = picked_at.and_then(|p| body_at(sim, p));
        if *selected != hit {
            *selected = hit;
            outcome.selection_changed = true;
        }
        if drag_started
            && !editing
            && let (Some(i), Some(p)) = (hit, picked_at)
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
    // Editing (step 0, paused): dragging a body moves its placement in the files, keeping
    // the grabbed point under the pointer.
    if editing
        && selecting
        && let (Some(i), Some(p)) = (*selected, pointer_world)
        && let Some(origin) = sim
            .bodies
            .get(i)
            .and_then(|b| sim.world.body(b.handle))
            .map(|b| b.origin())
    {
        if drag_started && let Some(pressed) = press_world {
            ui.data_mut(|d| d.insert_temp(offset_id, pressed - origin));
        }
        if response.dragged_by(egui::PointerButton::Primary)
            && response.drag_delta() != egui::Vec2::ZERO
            && let Some(offset) = ui.data(|d| d.get_temp::<Vec2>(offset_id))
        {
            outcome.moved = Some((i, p - offset));
        }
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
        let asleep = debug.sleeping && body.is_asleep();
        painter.add(Shape::convex_polygon(
            points,
            fill.gamma_multiply(if asleep { 0.4 } else { 0.85 }),
            stroke,
        ));
        if asleep {
            painter.text(
                to_screen(body.position),
                egui::Align2::CENTER_CENTER,
                "z",
                egui::FontId::proportional(12.0),
                Color32::from_gray(200),
            );
        }
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
    if editing {
        let hint = match tool {
            super::tools::Tool::Select => {
                "editing at step 0: drag a body to move it · Q / E rotate the selected body · Play runs"
            }
            super::tools::Tool::Joint => {
                "joint tool: click a point where two bodies overlap to pin them there"
            }
        };
        painter.text(
            rect.left_top() + egui::vec2(8.0, 8.0),
            egui::Align2::LEFT_TOP,
            hint,
            egui::FontId::proportional(13.0),
            Color32::from_gray(170),
        );
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

/// What the body editor did this frame.
pub enum VertexEdit {
    None,
    /// The vertex list was changed (a drag, an added point).
    Changed(Vec<[f64; 2]>),
    /// A click asked for a vertex that would break the outline; why.
    Refused(String),
}

/// The body editor's canvas: the vertex list as drawn (valid or not), handles to drag,
/// a click on empty space adds a vertex there. Green when it is a usable convex polygon.
pub fn edit_vertices(
    ui: &mut egui::Ui,
    vertices: &[[f64; 2]],
    camera: &mut Camera,
    fit: bool,
    dragging: &mut Option<usize>,
    snap_step: Option<f64>,
) -> VertexEdit {
    let snap = |v: f64| super::tools::snap(v, snap_step);
    let (response, painter) = ui.allocate_painter(ui.available_size(), Sense::click_and_drag());
    let rect = response.rect;
    painter.rect_filled(rect, 0.0, BACKGROUND);
    if fit {
        // At least a 40-unit square, so that an empty body has room to be drawn.
        let (mut min, mut max) = (Vec2::repeat(-20.0), Vec2::repeat(20.0));
        for v in vertices {
            min = min.inf(&Vec2::new(v[0], v[1]));
            max = max.sup(&Vec2::new(v[0], v[1]));
        }
        let margin = (max - min) * 0.4;
        camera.fit(rect, min - margin, max + margin);
    }
    draw_grid(&painter, rect, camera);
    if response.dragged_by(egui::PointerButton::Secondary)
        || response.dragged_by(egui::PointerButton::Middle)
    {
        let d = response.drag_delta();
        camera.centre -= Vec2::new(d.x as f64, d.y as f64) / camera.zoom;
    }
    if let Some(hover) = response.hover_pos() {
        let scroll = ui.input(|i| i.smooth_scroll_delta.y);
        if scroll != 0.0 {
            camera.zoom_about(rect, hover, (scroll as f64 * 0.002).exp());
        }
    }
    let to_screen = |v: &[f64; 2]| camera.to_screen(rect, Vec2::new(v[0], v[1]));
    let points: Vec<Pos2> = vertices.iter().map(to_screen).collect();
    let valid = crate::db::outline_polygon(vertices);
    let colour = if valid.is_ok() {
        Color32::from_rgb(90, 200, 120)
    } else {
        Color32::from_rgb(230, 80, 70)
    };
    if valid.is_ok() {
        painter.add(Shape::convex_polygon(
            points.clone(),
            colour.gamma_multiply(0.3),
            Stroke::new(1.5, colour),
        ));
    } else if points.len() >= 2 {
        painter.add(Shape::closed_line(points.clone(), Stroke::new(1.5, colour)));
    }
    // The origin: where a placement puts (x, y).
    let origin = camera.to_screen(rect, Vec2::zeros());
    painter.line_segment(
        [origin - egui::vec2(8.0, 0.0), origin + egui::vec2(8.0, 0.0)],
        Stroke::new(1.0, Color32::GRAY),
    );
    painter.line_segment(
        [origin - egui::vec2(0.0, 8.0), origin + egui::vec2(0.0, 8.0)],
        Stroke::new(1.0, Color32::GRAY),
    );
    let pointer = response.interact_pointer_pos();
    let near = |p: Pos2| points.iter().position(|q| q.distance(p) < 8.0);
    if response.drag_started_by(egui::PointerButton::Primary) {
        *dragging = pointer.and_then(near);
    }
    let mut edit = VertexEdit::None;
    if let (Some(i), Some(p)) = (*dragging, pointer)
        && response.dragged_by(egui::PointerButton::Primary)
    {
        let w = camera.to_world(rect, p);
        let mut new = vertices.to_vec();
        new[i] = [snap(w.x), snap(w.y)];
        if new != vertices {
            edit = VertexEdit::Changed(new);
        }
    }
    if response.drag_stopped() {
        *dragging = None;
    }
    if response.clicked()
        && let Some(p) = pointer
        && near(p).is_none()
    {
        let w = camera.to_world(rect, p);
        let point = [snap(w.x), snap(w.y)];
        let anyway = ui.input(|i| i.modifiers.shift);
        edit = match super::tools::add_vertex(vertices, point) {
            Ok(new) => VertexEdit::Changed(new),
            Err(_) if anyway && !vertices.contains(&point) => {
                let mut new = vertices.to_vec();
                new.push(point);
                VertexEdit::Changed(new)
            }
            Err(why) => VertexEdit::Refused(why),
        };
    }
    for (i, p) in points.iter().enumerate() {
        painter.circle_filled(
            *p,
            5.0,
            if Some(i) == *dragging {
                Color32::YELLOW
            } else {
                Color32::WHITE
            },
        );
        painter.text(
            *p + egui::vec2(7.0, -7.0),
            egui::Align2::LEFT_BOTTOM,
            format!("{i}"),
            egui::FontId::proportional(11.0),
            Color32::GRAY,
        );
    }
    let hint = match &valid {
        Ok(_) => {
            "click to add a vertex · drag a vertex to move it · the cross is the body's origin"
                .to_string()
        }
        Err(_) if vertices.len() < 3 => "click to place vertices (at least three)".to_string(),
        Err(e) => format!("{e} — keep adding vertices, or use Convex hull"),
    };
    painter.text(
        rect.left_top() + egui::vec2(8.0, 8.0),
        egui::Align2::LEFT_TOP,
        hint,
        egui::FontId::proportional(13.0),
        colour,
    );
    edit
}
