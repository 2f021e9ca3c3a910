//! The canvas: draws a simulation with its debug overlays, pans and zooms, selects a body
//! by clicking it, drags a body by the grabbed point while it runs, and at step 0 moves
//! and turns placements. It returns commands; the picture itself is `draw`'s.

pub mod body_editor;
pub mod draw;

use super::Command;
use super::camera::Camera;
use super::tools::{self, ShapeOptions, Tool};
use super::world_bound::WorldBound;
use crate::sim::Simulation;
use egui::{Color32, PointerButton, Rect, Sense, Stroke};
use pe::{Aabb, BodyHandle, Vec2};

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
    /// The physics islands of the last step, in a window of their own.
    pub islands: bool,
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
            islands: false,
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

/// How the canvas looks at the world, and what a click on it does.
#[derive(Debug, Clone, PartialEq)]
pub struct CanvasView {
    pub camera: Camera,
    /// The camera frames what is shown; false: fit it on the next frame.
    pub fitted: bool,
    /// What the next fit frames instead of the moving bodies.
    pub fit_area: Option<Aabb>,
    pub debug: DebugDraw,
    /// Where the canvas was drawn last frame (screen points), to map clicks to the world.
    pub rect: Rect,
    pub tool: Tool,
    /// Grid spacing edits snap to (None: free).
    pub snap_step: Option<f64>,
    /// The vertex being dragged in the body editor.
    pub vertex_drag: Option<usize>,
    /// How the drawing tools shape their bodies.
    pub shape: ShapeOptions,
    /// The drag of a drawing tool: where it started and where the pointer is (world,
    /// snapped).
    pub drawing: Option<(Vec2, Vec2)>,
    /// The rubber band being dragged out on empty canvas: where the drag started and
    /// where the pointer is (screen points).
    pub band: Option<(egui::Pos2, egui::Pos2)>,
    /// The PNG export this frame is drawn for: the canvas as the scene, without the
    /// editing hints written over it.
    pub png_pending: Option<std::path::PathBuf>,
}

impl Default for CanvasView {
    fn default() -> Self {
        Self {
            camera: Camera::default(),
            fitted: false,
            fit_area: None,
            debug: DebugDraw::default(),
            rect: Rect::NOTHING,
            tool: Tool::Select,
            snap_step: Some(0.5),
            vertex_drag: None,
            band: None,
            shape: ShapeOptions::default(),
            drawing: None,
            png_pending: None,
        }
    }
}

/// What the scene canvas shows this frame.
#[derive(Debug, Clone, Copy)]
pub struct Scene<'a> {
    pub sim: &'a Simulation,
    /// Paused at step 0: drags move placements instead of grabbing bodies.
    pub editing: bool,
    /// The body the inspector and plots follow (index into `sim.bodies`).
    pub followed: Option<usize>,
    /// The bodies selected (indices into `sim.bodies`), the followed one among them.
    pub picked: &'a [usize],
    pub overlaps: &'a [(usize, usize)],
    pub bound: Option<&'a WorldBound>,
}

/// The rubber band's colour.
const BAND: Color32 = Color32::from_rgb(120, 180, 255);

/// Points between a selected body's outline and its rotate handle.
const HANDLE_OFFSET: f32 = 24.0;
const HANDLE_RADIUS: f32 = 6.0;

impl CanvasView {
    /// Frames the scene (or the body being edited) on the next frame.
    pub fn fit(&mut self) {
        self.fitted = false;
        self.fit_area = None;
    }

    /// An empty canvas that says why.
    pub fn nothing(&mut self, ui: &mut egui::Ui, why: &str) {
        let (response, painter) = ui.allocate_painter(ui.available_size(), Sense::hover());
        self.rect = response.rect;
        painter.rect_filled(self.rect, 0.0, draw::BACKGROUND);
        painter.text(
            self.rect.center(),
            egui::Align2::CENTER_CENTER,
            why,
            egui::FontId::proportional(16.0),
            Color32::GRAY,
        );
    }

    /// The scene canvas; `grab` is the body the mouse holds while the scene runs.
    pub fn scene_ui(
        &mut self,
        ui: &mut egui::Ui,
        scene: Scene<'_>,
        grab: &mut Option<Grab>,
    ) -> Vec<Command> {
        let (response, painter) = ui.allocate_painter(ui.available_size(), Sense::click_and_drag());
        self.rect = response.rect;
        if !self.fitted {
            self.fit_now(scene.sim);
        } else {
            self.navigate(ui, &response, scene, grab.is_some());
        }
        let mut commands = Vec::new();
        let followed = self.pointer(ui, &response, scene, grab, &mut commands);
        self.rubber_band(ui, &response, scene, &mut commands);
        self.draw_gesture(ui, &response, scene, &mut commands);
        // A click this frame shows at once what it selected; the app's selection next frame.
        // While running, only the followed body: the one the plots show.
        let selected: Vec<usize> = if followed == scene.followed && scene.editing {
            scene.picked.to_vec()
        } else {
            followed.into_iter().collect()
        };
        let marks = draw::Highlights {
            selected: &selected,
            overlaps: if scene.editing { scene.overlaps } else { &[] },
        };
        painter.extend(draw::scene(
            scene.sim,
            &self.camera,
            self.rect,
            &self.debug,
            marks,
        ));
        self.handle_and_grab(&painter, scene, followed, grab.as_ref());
        if let Some((from, to)) = self.band {
            painter.rect(
                Rect::from_two_pos(from, to),
                0.0,
                BAND.gamma_multiply(0.15),
                Stroke::new(1.0, BAND),
                egui::StrokeKind::Inside,
            );
        }
        self.drawing_preview(&painter);
        self.hints(ui, &painter, scene);
        commands
    }

    fn fit_now(&mut self, sim: &Simulation) {
        let area = self.fit_area.map(|a| {
            let margin = (a.max - a.min) * 0.05;
            (a.min - margin, a.max + margin)
        });
        if let Some((min, max)) = area.or_else(|| fit_bounds(sim)) {
            self.camera.fit(self.rect, min, max);
        }
        self.fitted = true;
        self.fit_area = None;
    }

    /// Pans with the secondary or middle button, zooms with the wheel about the pointer,
    /// and eases towards what Follow follows, except while a body is held (`holding`).
    fn navigate(
        &mut self,
        ui: &egui::Ui,
        response: &egui::Response,
        scene: Scene<'_>,
        holding: bool,
    ) {
        if pan(&mut self.camera, response) {
            self.debug.follow = false;
        }
        zoom(&mut self.camera, ui, response, self.rect);
        // Following stops while editing, and while a body is held: the view must hold
        // still under the user's pointer (a view following the held body moves the world
        // point under a still pointer with it, and the pull never lets up).
        if self.debug.follow
            && !scene.editing
            && !holding
            && let Some(target) = follow_point(scene.sim, scene.followed, scene.bound)
        {
            // Ease towards the target so that the view does not shake with the bodies.
            self.camera.centre += (target - self.camera.centre) * 0.1;
        }
    }

    /// Clicks and drags with the primary button; returns the body followed after them.
    fn pointer(
        &mut self,
        ui: &egui::Ui,
        response: &egui::Response,
        scene: Scene<'_>,
        grab: &mut Option<Grab>,
        commands: &mut Vec<Command>,
    ) -> Option<usize> {
        let (camera, rect, sim) = (self.camera, self.rect, scene.sim);
        let pointer = response
            .interact_pointer_pos()
            .map(|p| camera.to_world(rect, p));
        // A drag is recognised only once the pointer has moved a few points: pick and grab
        // where the button went down, not where the pointer is by then.
        let pressed_screen = ui.input(|i| i.pointer.press_origin());
        let pressed = pressed_screen.map(|p| camera.to_world(rect, p));
        let drag_started = response.drag_started_by(PointerButton::Primary);
        let selecting = !scene.editing || self.tool == Tool::Select;
        if scene.editing && self.tool == Tool::Joint && response.clicked() {
            commands.extend(pointer.map(Command::UseTool));
        }
        let turning_id = response.id.with("turning");
        if scene.editing
            && drag_started
            && let Some(p) = pressed_screen
        {
            let on_handle = self.on_handle(scene, p);
            ui.ctx().data_mut(|d| d.insert_temp(turning_id, on_handle));
        }
        let turning = scene.editing && ui.ctx().data(|d| d.get_temp(turning_id).unwrap_or(false));
        let mut followed = scene.followed;
        // The body a drag at step 0 moves (with the selection, if it is in it).
        let dragged_id = response.id.with("dragged body");
        if selecting && !turning && (drag_started || response.clicked()) {
            let at = if drag_started { pressed } else { pointer };
            let hit = at.and_then(|p| body_at(sim, p, scene.followed));
            let shift = ui.input(|i| i.modifiers.shift);
            let in_selection = hit.is_some_and(|i| scene.picked.contains(&i));
            if scene.editing && shift && response.clicked() {
                commands.extend(hit.map(Command::TogglePick));
            } else if scene.editing && drag_started && (hit.is_none() || in_selection) {
                // On empty canvas a drag draws a rubber band; on a selected body it moves
                // the whole selection: neither changes what is selected yet.
            } else if hit != followed || (response.clicked() && scene.picked.len() > 1) {
                followed = hit;
                commands.push(Command::Follow(hit));
            }
            if drag_started {
                ui.ctx().data_mut(|d| d.insert_temp(dragged_id, hit));
            }
            if drag_started && !scene.editing {
                *grab = hit.zip(at).and_then(|(i, p)| grab_at(sim, i, p));
            }
        }
        if let (Some(g), Some(p)) = (grab.as_mut(), pointer) {
            g.target = p;
        }
        let dragged = ui.ctx().data(|d| d.get_temp::<Option<usize>>(dragged_id));
        if scene.editing
            && selecting
            && let Some(p) = pointer
        {
            let dragging = response.dragged_by(PointerButton::Primary)
                && response.drag_delta() != egui::Vec2::ZERO;
            if turning {
                commands.extend(followed.and_then(|i| turn(ui, sim, i, pressed, p, dragging)));
            } else if let Some(i) = dragged.flatten() {
                commands.extend(move_by_drag(ui, response, sim, i, pressed, p, dragging));
            }
        }
        if response.drag_stopped() || !ui.input(|i| i.pointer.primary_down()) {
            *grab = None;
            ui.ctx().data_mut(|d| {
                d.insert_temp(turning_id, false);
                d.remove::<Option<usize>>(dragged_id);
            });
        }
        followed
    }

    /// At step 0 with the select tool, a drag that starts on empty canvas draws a rubber
    /// band; on release the placements whose bodies it touches are selected (Shift: added).
    fn rubber_band(
        &mut self,
        ui: &egui::Ui,
        response: &egui::Response,
        scene: Scene<'_>,
        commands: &mut Vec<Command>,
    ) {
        if !scene.editing || self.tool != Tool::Select {
            self.band = None;
            return;
        }
        let (camera, rect) = (self.camera, self.rect);
        if response.drag_started_by(PointerButton::Primary) {
            // Empty canvas, the rotate handle aside: a drag from the handle turns.
            let empty = ui.input(|i| i.pointer.press_origin()).filter(|&p| {
                body_at(scene.sim, camera.to_world(rect, p), None).is_none()
                    && !self.on_handle(scene, p)
            });
            self.band = empty.map(|p| (p, p));
        }
        let Some((from, to)) = self.band.as_mut() else {
            return;
        };
        if let Some(p) = response.interact_pointer_pos() {
            *to = p;
        }
        if response.drag_stopped() || !ui.input(|i| i.pointer.primary_down()) {
            let (a, b) = (camera.to_world(rect, *from), camera.to_world(rect, *to));
            let bodies = bodies_touching(scene.sim, a.inf(&b), a.sup(&b));
            let add = ui.input(|i| i.modifiers.shift);
            commands.push(Command::Pick { bodies, add });
            self.band = None;
        }
    }

    /// At step 0 with a drawing tool, a drag sizes a new body (from corner to corner, or
    /// from the centre out); on release the app makes it and places it there.
    fn draw_gesture(
        &mut self,
        ui: &egui::Ui,
        response: &egui::Response,
        scene: Scene<'_>,
        commands: &mut Vec<Command>,
    ) {
        if !scene.editing || !self.tool.draws() {
            self.drawing = None;
            return;
        }
        let (camera, rect) = (self.camera, self.rect);
        let snap = |p: Vec2| {
            Vec2::new(
                tools::snap(p.x, self.snap_step),
                tools::snap(p.y, self.snap_step),
            )
        };
        if response.drag_started_by(PointerButton::Primary) {
            let start = ui.input(|i| i.pointer.press_origin());
            self.drawing = start.map(|p| {
                let w = snap(camera.to_world(rect, p));
                (w, w)
            });
        } else if response.clicked() {
            commands.push(Command::Inform(
                "drag to draw: a box from corner to corner, a polygon from its centre out".into(),
            ));
        }
        let Some((from, to)) = self.drawing.as_mut() else {
            return;
        };
        if let Some(p) = response.interact_pointer_pos() {
            *to = snap(camera.to_world(rect, p));
        }
        if response.drag_stopped() || !ui.input(|i| i.pointer.primary_down()) {
            commands.push(Command::DrawShape {
                from: *from,
                to: *to,
            });
            self.drawing = None;
        }
    }

    /// The outline a drawing drag would make, with its size.
    fn drawing_preview(&self, painter: &egui::Painter) {
        let Some((from, to)) = self.drawing else {
            return;
        };
        let Ok(shape) = tools::drawn_shape(self.tool, self.shape, from, to) else {
            return;
        };
        let points: Vec<egui::Pos2> = shape
            .vertices
            .iter()
            .map(|v| {
                self.camera
                    .to_screen(self.rect, shape.at + Vec2::new(v[0], v[1]))
            })
            .collect();
        let label = points.iter().fold(egui::Pos2::ZERO, |m, p| m.max(*p));
        painter.add(egui::Shape::closed_line(points, Stroke::new(1.5, BAND)));
        let size = (to - from).abs();
        let text = match self.tool {
            Tool::Box => format!("{} × {}", size.x, size.y),
            _ => format!("r {:.1}", (to - from).norm()),
        };
        painter.text(
            label + egui::vec2(6.0, 6.0),
            egui::Align2::LEFT_TOP,
            text,
            egui::FontId::proportional(13.0),
            BAND,
        );
    }

    /// Whether screen point `p` is on the rotate handle of the followed body.
    fn on_handle(&self, scene: Scene<'_>, p: egui::Pos2) -> bool {
        self.handle(scene.sim, scene.followed, scene.picked)
            .is_some_and(|h| h.distance(p) <= HANDLE_RADIUS + 4.0)
    }

    /// Where the rotate handle of body `i` is on screen: above its outline.
    /// With others selected, it stands above them all, clear of the group it turns.
    fn handle(&self, sim: &Simulation, i: Option<usize>, picked: &[usize]) -> Option<egui::Pos2> {
        let body = sim.bodies.get(i?).and_then(|b| sim.world.body(b.handle))?;
        let group = picked
            .iter()
            .filter_map(|&k| sim.world.body(sim.bodies.get(k)?.handle));
        let top = std::iter::once(body)
            .chain(group)
            .flat_map(|b| b.world_vertices().collect::<Vec<_>>())
            .map(|v| self.camera.to_screen(self.rect, v).y)
            .fold(f32::INFINITY, f32::min);
        let origin = self.camera.to_screen(self.rect, body.origin());
        Some(egui::pos2(origin.x, top - HANDLE_OFFSET))
    }

    fn handle_and_grab(
        &self,
        painter: &egui::Painter,
        scene: Scene<'_>,
        followed: Option<usize>,
        grab: Option<&Grab>,
    ) {
        let to_screen = |p: Vec2| self.camera.to_screen(self.rect, p);
        if scene.editing
            && self.tool == Tool::Select
            && let Some(h) = self.handle(scene.sim, followed, scene.picked)
            && let Some(body) = followed
                .and_then(|i| scene.sim.bodies.get(i))
                .and_then(|b| scene.sim.world.body(b.handle))
        {
            let stroke = Stroke::new(1.5, Color32::from_rgb(255, 220, 80));
            painter.line_segment([to_screen(body.origin()), h], stroke);
            painter.circle(h, HANDLE_RADIUS, Color32::from_rgb(60, 60, 70), stroke);
        }
        if let Some(g) = grab
            && let Some(body) = scene.sim.world.body(g.body)
        {
            let from = to_screen(body.to_world(g.local_point));
            painter.line_segment(
                [from, to_screen(g.target)],
                Stroke::new(1.5, Color32::WHITE),
            );
            painter.circle_filled(from, 3.0, Color32::WHITE);
        }
    }

    fn hints(&self, ui: &mut egui::Ui, painter: &egui::Painter, scene: Scene<'_>) {
        if !scene.editing || self.png_pending.is_some() {
            return;
        }
        let hint = match self.tool {
            Tool::Select => {
                "step 0: drag a body to move it · drag on empty space to select several (Shift adds) · handle or Q / E turns · Play runs"
            }
            Tool::Joint => "joint tool: click a point where two bodies overlap to pin them there",
            Tool::Box => "box tool: drag from corner to corner to draw a new body · Esc selects",
            Tool::Polygon => {
                "polygon tool: drag from the centre out to draw a new body · Esc selects"
            }
        };
        painter.text(
            self.rect.left_top() + egui::vec2(8.0, 8.0),
            egui::Align2::LEFT_TOP,
            hint,
            egui::FontId::proportional(13.0),
            Color32::from_gray(170),
        );
        if !scene.overlaps.is_empty() {
            let text = overlap_note(scene.sim, scene.overlaps);
            draw::note(ui, self.rect, 1, draw::OVERLAP, &text);
        }
    }
}

/// Pans the camera with the secondary or middle button; whether it moved.
pub fn pan(camera: &mut Camera, response: &egui::Response) -> bool {
    if response.dragged_by(PointerButton::Secondary) || response.dragged_by(PointerButton::Middle) {
        let d = response.drag_delta();
        camera.centre -= Vec2::new(d.x as f64, d.y as f64) / camera.zoom;
        return true;
    }
    false
}

/// Zooms with the wheel about the pointer.
pub fn zoom(camera: &mut Camera, ui: &egui::Ui, response: &egui::Response, rect: Rect) {
    if let Some(hover) = response.hover_pos() {
        let scroll = ui.input(|i| i.smooth_scroll_delta.y);
        if scroll != 0.0 {
            camera.zoom_about(rect, hover, (scroll as f64 * 0.002).exp());
        }
    }
}

/// The mouse spring on body `i` of `sim` at world point `p`, unless it is static.
fn grab_at(sim: &Simulation, i: usize, p: Vec2) -> Option<Grab> {
    let handle = sim.bodies.get(i)?.handle;
    let body = sim.world.body(handle).filter(|b| !b.is_static())?;
    Some(Grab {
        body: handle,
        local_point: body.to_local(p),
        target: p,
    })
}

/// Dragging body `i` at step 0 moves its placement, keeping the grabbed point under the
/// pointer `p`.
fn move_by_drag(
    ui: &egui::Ui,
    response: &egui::Response,
    sim: &Simulation,
    i: usize,
    pressed: Option<Vec2>,
    p: Vec2,
    dragging: bool,
) -> Option<Command> {
    let origin = sim
        .bodies
        .get(i)
        .and_then(|b| sim.world.body(b.handle))?
        .origin();
    let offset_id = response.id.with("placement drag offset");
    if response.drag_started_by(PointerButton::Primary)
        && let Some(pressed) = pressed
    {
        ui.ctx()
            .data_mut(|d| d.insert_temp(offset_id, pressed - origin));
    }
    let offset = ui.ctx().data(|d| d.get_temp::<Vec2>(offset_id))?;
    dragging.then_some(Command::MovePlacement {
        body: i,
        to: p - offset,
    })
}

/// Dragging the rotate handle of body `i` turns its placement by the angle the pointer
/// swept about the body's origin; with Shift held, to whole 15° steps.
fn turn(
    ui: &egui::Ui,
    sim: &Simulation,
    i: usize,
    pressed: Option<Vec2>,
    p: Vec2,
    dragging: bool,
) -> Option<Command> {
    let body = sim.bodies.get(i).and_then(|b| sim.world.body(b.handle))?;
    let origin = body.origin();
    let start_id = egui::Id::unique(("turn start", i));
    // The angle and bearing at the press hold until the button is released: a frame in
    // which the pointer rests is still the same drag (forgetting them there made the next
    // move add the whole sweep since the press again).
    if !ui.input(|i| i.pointer.primary_down()) {
        ui.ctx().data_mut(|d| d.remove::<(f64, f64)>(start_id));
        return None;
    }
    if !dragging {
        return None;
    }
    let pressed = pressed?;
    let bearing = |q: Vec2| (q.y - origin.y).atan2(q.x - origin.x);
    let (angle_at_press, bearing_at_press) = ui
        .ctx()
        .data_mut(|d| *d.get_temp_mut_or_insert_with(start_id, || (body.angle, bearing(pressed))));
    let mut target = angle_at_press + bearing(p) - bearing_at_press;
    if ui.input(|i| i.modifiers.shift) {
        let step = 15f64.to_radians();
        target = (target / step).round() * step;
    }
    let delta = target - body.angle;
    (delta.abs() > 1e-9).then_some(Command::TurnPlacement {
        body: i,
        angle: delta,
    })
}

/// "a overlaps b: …" for the first overlapping pair, with a count of the others.
fn overlap_note(sim: &Simulation, overlaps: &[(usize, usize)]) -> String {
    let Some(&(a, b)) = overlaps.first() else {
        return String::new();
    };
    let more = match overlaps.len() - 1 {
        0 => String::new(),
        n => format!(" (and {n} more pairs)"),
    };
    format!(
        "{} overlaps {}{more}: the first step pushes them apart; drag one clear",
        sim.bodies[a].id, sim.bodies[b].id
    )
}

/// The selected body's centroid if it can move, or the mean centroid of the moving
/// bodies (those inside the world bound).
fn follow_point(
    sim: &Simulation,
    selected: Option<usize>,
    bound: Option<&WorldBound>,
) -> Option<Vec2> {
    // A static body selected (terrain just drawn) does not move: the view follows what
    // does.
    if let Some(body) = selected
        .and_then(|i| sim.bodies.get(i))
        .and_then(|b| sim.world.body(b.handle))
        .filter(|b| !b.is_static())
    {
        return Some(body.centroid());
    }
    let moving: Vec<Vec2> = sim
        .world
        .bodies()
        .filter(|(h, b)| !b.is_static() && !bound.is_some_and(|w| w.is_stopped(*h)))
        .map(|(_, b)| b.centroid())
        .collect();
    (!moving.is_empty()).then(|| moving.iter().sum::<Vec2>() / moving.len() as f64)
}

/// Whether body `i` of `sim` covers `p`.
fn covers(sim: &Simulation, i: usize, p: Vec2) -> bool {
    let Some(body) = sim.bodies.get(i).and_then(|b| sim.world.body(b.handle)) else {
        return false;
    };
    let verts: Vec<Vec2> = body.world_vertices().collect();
    let side = |k: usize| {
        let (a, c) = (verts[k], verts[(k + 1) % verts.len()]);
        (c - a).perp(&(p - a))
    };
    (0..verts.len()).all(|k| side(k) >= 0.0) || (0..verts.len()).all(|k| side(k) <= 0.0)
}

/// The body a press at `p` takes: the selected one if it covers `p`, else the topmost
/// (last drawn) that does.
pub fn body_at(sim: &Simulation, p: Vec2, selected: Option<usize>) -> Option<usize> {
    if let Some(i) = selected
        && covers(sim, i, p)
    {
        return Some(i);
    }
    draw::drawing_order(sim)
        .into_iter()
        .rev()
        .find(|&i| covers(sim, i, p))
}

/// The bodies (indices into `sim.bodies`) whose outlines touch or lie inside the world
/// rectangle from `min` to `max`.
pub fn bodies_touching(sim: &Simulation, min: Vec2, max: Vec2) -> Vec<usize> {
    let band = [min, Vec2::new(max.x, min.y), max, Vec2::new(min.x, max.y)];
    (0..sim.bodies.len())
        .filter(|&i| {
            sim.world.body(sim.bodies[i].handle).is_some_and(|b| {
                let outline: Vec<Vec2> = b.world_vertices().collect();
                super::placing::overlap_depth(&band, &outline) >= 0.0
            })
        })
        .collect()
}

/// The world rectangle around every body, the static ones clipped to the dynamic ones'
/// neighbourhood so that a long floor does not shrink the robots to dots.
fn fit_bounds(sim: &Simulation) -> Option<(Vec2, Vec2)> {
    let dynamic = super::placing::bounds_of(
        sim.world
            .bodies()
            .filter(|(_, b)| !b.is_static())
            .flat_map(|(_, b)| b.world_vertices().collect::<Vec<_>>()),
    );
    let all = || {
        super::placing::bounds_of(
            sim.world
                .bodies()
                .flat_map(|(_, b)| b.world_vertices().collect::<Vec<_>>()),
        )
    };
    let aabb = dynamic.or_else(all)?;
    // Room around the bodies for them to move, and the ground below them.
    let size = (aabb.max - aabb.min).norm().max(50.0);
    Some((
        aabb.min - Vec2::repeat(0.6 * size),
        aabb.max + Vec2::repeat(0.6 * size),
    ))
}
