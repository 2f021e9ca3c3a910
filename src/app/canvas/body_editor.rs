//! The body editor's canvas: the vertex list as drawn (valid or not), handles to drag, a
//! click on empty space adds a vertex there. Green when it is a usable convex polygon.

use super::{CanvasView, draw, pan, zoom};
use crate::app::Command;
use crate::app::tools;
use egui::{Color32, PointerButton, Pos2, Sense, Shape, Stroke};
use pe::Vec2;

/// How near (screen points) a press must be to a vertex to take it.
const VERTEX_REACH: f32 = 10.0;

impl CanvasView {
    /// Edits the outline `vertices` of the selected body.
    pub fn body_ui(&mut self, ui: &mut egui::Ui, vertices: &[[f64; 2]]) -> Vec<Command> {
        let (response, painter) = ui.allocate_painter(ui.available_size(), Sense::click_and_drag());
        self.rect = response.rect;
        if !self.fitted {
            self.fit_outline(vertices);
        }
        pan(&mut self.camera, &response);
        zoom(&mut self.camera, ui, &response, self.rect);
        let mut shapes = vec![Shape::rect_filled(self.rect, 0.0, draw::BACKGROUND)];
        draw::grid(&mut shapes, self.rect, &self.camera);
        painter.extend(shapes);
        let points: Vec<Pos2> = vertices
            .iter()
            .map(|v| self.camera.to_screen(self.rect, Vec2::new(v[0], v[1])))
            .collect();
        let valid = crate::db::outline_polygon(vertices);
        let colour = if valid.is_ok() {
            Color32::from_rgb(90, 200, 120)
        } else {
            Color32::from_rgb(230, 80, 70)
        };
        outline(&painter, &points, valid.is_ok(), colour);
        self.origin_cross(&painter);
        let commands = self.vertex_input(ui, &response, vertices, &points);
        for (i, p) in points.iter().enumerate() {
            let dragged = Some(i) == self.vertex_drag;
            painter.circle_filled(
                *p,
                5.0,
                if dragged {
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
            Err(e) => format!("{e}: keep adding vertices, or use Convex hull"),
        };
        painter.text(
            self.rect.left_top() + egui::vec2(8.0, 8.0),
            egui::Align2::LEFT_TOP,
            hint,
            egui::FontId::proportional(13.0),
            colour,
        );
        commands
    }

    /// At least a 40-unit square, so that an empty body has room to be drawn.
    fn fit_outline(&mut self, vertices: &[[f64; 2]]) {
        let (mut min, mut max) = (Vec2::repeat(-20.0), Vec2::repeat(20.0));
        for v in vertices {
            min = min.inf(&Vec2::new(v[0], v[1]));
            max = max.sup(&Vec2::new(v[0], v[1]));
        }
        let margin = (max - min) * 0.4;
        self.camera.fit(self.rect, min - margin, max + margin);
        self.fitted = true;
    }

    /// The origin: where a placement puts (x, y).
    fn origin_cross(&self, painter: &egui::Painter) {
        let origin = self.camera.to_screen(self.rect, Vec2::zeros());
        let stroke = Stroke::new(1.0, Color32::GRAY);
        painter.line_segment(
            [origin - egui::vec2(8.0, 0.0), origin + egui::vec2(8.0, 0.0)],
            stroke,
        );
        painter.line_segment(
            [origin - egui::vec2(0.0, 8.0), origin + egui::vec2(0.0, 8.0)],
            stroke,
        );
    }

    /// Drags of vertices and clicks that add one.
    fn vertex_input(
        &mut self,
        ui: &egui::Ui,
        response: &egui::Response,
        vertices: &[[f64; 2]],
        points: &[Pos2],
    ) -> Vec<Command> {
        let snap_step = self.snap_step;
        let snap = |w: Vec2| [tools::snap(w.x, snap_step), tools::snap(w.y, snap_step)];
        let near = |p: Pos2| {
            points
                .iter()
                .enumerate()
                .map(|(i, q)| (i, q.distance(p)))
                .filter(|&(_, d)| d < VERTEX_REACH)
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .map(|(i, _)| i)
        };
        let pointer = response.interact_pointer_pos();
        // egui calls it a drag only once the pointer has moved a few points: take the vertex
        // where the button went down, and keep the offset it was grabbed at.
        let grab_id = response.id.with("vertex grab offset");
        if response.drag_started_by(PointerButton::Primary) {
            let pressed = ui.input(|i| i.pointer.press_origin());
            self.vertex_drag = pressed.and_then(near);
            if let (Some(i), Some(p)) = (self.vertex_drag, pressed) {
                let grabbed =
                    self.camera.to_world(self.rect, p) - Vec2::new(vertices[i][0], vertices[i][1]);
                ui.ctx().data_mut(|d| d.insert_temp(grab_id, grabbed));
            }
        }
        let mut commands = Vec::new();
        if let (Some(i), Some(p)) = (self.vertex_drag, pointer)
            && i < vertices.len()
            && response.dragged_by(PointerButton::Primary)
        {
            let offset = ui
                .ctx()
                .data(|d| d.get_temp::<Vec2>(grab_id))
                .unwrap_or_default();
            let mut new = vertices.to_vec();
            new[i] = snap(self.camera.to_world(self.rect, p) - offset);
            if new != vertices {
                commands.push(Command::SetVertices {
                    vertices: new,
                    key: format!("vertex {i}"),
                });
            }
        }
        if response.drag_stopped() {
            self.vertex_drag = None;
        }
        if response.clicked()
            && let Some(p) = pointer
            && near(p).is_none()
        {
            let point = snap(self.camera.to_world(self.rect, p));
            let anyway = ui.input(|i| i.modifiers.shift);
            commands.push(match tools::add_vertex(vertices, point) {
                Ok(new) => Command::SetVertices {
                    vertices: new,
                    key: "add vertex".into(),
                },
                Err(_) if anyway && !vertices.contains(&point) => Command::SetVertices {
                    vertices: tools::add_vertex_anyway(vertices, point),
                    key: "add vertex".into(),
                },
                Err(why) => Command::Complain(why),
            });
        }
        commands
    }
}

/// The outline: filled when it is a usable convex polygon, a closed line otherwise.
fn outline(painter: &egui::Painter, points: &[Pos2], valid: bool, colour: Color32) {
    if valid {
        painter.add(Shape::convex_polygon(
            points.to_vec(),
            colour.gamma_multiply(0.3),
            Stroke::new(1.5, colour),
        ));
    } else if points.len() >= 2 {
        painter.add(Shape::closed_line(
            points.to_vec(),
            Stroke::new(1.5, colour),
        ));
    }
}
