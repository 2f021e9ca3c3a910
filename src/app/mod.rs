//! The desktop app (eframe/egui). UI code reads the model and emits edits; physics lives in
//! `pe` and the simulation layer, files in `db`.

pub mod camera;

use camera::Camera;
use egui::{Color32, Pos2, Sense, Shape, Stroke};
use pe::{BodyDef, ConvexPolygon, Vec2, World};

/// Runs the app in a native window until it is closed.
pub fn run(db: Option<std::path::PathBuf>) -> Result<(), String> {
    let _ = db;
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("RoboSim")
            .with_inner_size([1280.0, 800.0]),
        ..Default::default()
    };
    eframe::run_native(
        "RoboSim",
        options,
        Box::new(|_cc| Ok(Box::new(RoboSimApp::default()))),
    )
    .map_err(|e| e.to_string())
}

/// The app's state.
pub struct RoboSimApp {
    world: World,
    camera: Camera,
    running: bool,
    /// Simulated time owed to the physics: real time × speed, paid in whole steps.
    accumulator: f64,
    timestep: f64,
    camera_fitted: bool,
}

impl Default for RoboSimApp {
    fn default() -> Self {
        Self {
            world: falling_boxes(),
            camera: Camera::default(),
            running: true,
            accumulator: 0.0,
            timestep: 1.0 / 120.0,
            camera_fitted: false,
        }
    }
}

/// A floor and a loose pile of boxes above it, in centimetres (y down).
pub fn falling_boxes() -> World {
    let mut world = World::new(Vec2::new(0.0, 981.0));
    world.friction = 0.6;
    world.settings.length_scale = 30.0;
    let floor = ConvexPolygon::rectangle(1200.0, 40.0).expect("a rectangle is convex");
    world
        .add_body(BodyDef::new(floor, 0.0).at(Vec2::new(0.0, 300.0), 0.0))
        .expect("valid floor");
    for row in 0..6 {
        for col in 0..5 {
            let shape = if (row + col) % 3 == 0 {
                ConvexPolygon::regular(5 + col % 3, 22.0)
            } else {
                ConvexPolygon::rectangle(40.0, 30.0)
            }
            .expect("a regular polygon is convex");
            let x = -200.0 + 95.0 * col as f64 + 9.0 * row as f64;
            let y = 150.0 - 70.0 * row as f64;
            let def = BodyDef::new(shape, 0.001)
                .restitution(0.2)
                .at(Vec2::new(x, y), 0.3 * row as f64);
            world.add_body(def).expect("valid box");
        }
    }
    world
}

impl RoboSimApp {
    fn advance(&mut self, frame_seconds: f64) {
        if !self.running {
            return;
        }
        // A fixed step decoupled from the frame rate; cap the work so a stall cannot spiral.
        self.accumulator = (self.accumulator + frame_seconds).min(0.25);
        while self.accumulator >= self.timestep {
            self.world.step(self.timestep);
            self.accumulator -= self.timestep;
        }
    }

    fn canvas(&mut self, ui: &mut egui::Ui) {
        let (response, painter) = ui.allocate_painter(ui.available_size(), Sense::click_and_drag());
        let rect = response.rect;
        if !self.camera_fitted {
            self.camera
                .fit(rect, Vec2::new(-620.0, -300.0), Vec2::new(620.0, 330.0));
            self.camera_fitted = true;
        }
        if response.dragged() {
            let d = response.drag_delta();
            self.camera.centre -= Vec2::new(d.x as f64, d.y as f64) / self.camera.zoom;
        }
        if let Some(hover) = response.hover_pos() {
            let scroll = ui.input(|i| i.smooth_scroll_delta.y);
            if scroll != 0.0 {
                self.camera
                    .zoom_about(rect, hover, (scroll as f64 * 0.002).exp());
            }
        }
        painter.rect_filled(rect, 0.0, Color32::from_rgb(24, 26, 30));
        for (_, body) in self.world.bodies() {
            let points: Vec<Pos2> = body
                .world_vertices()
                .map(|v| self.camera.to_screen(rect, v))
                .collect();
            let fill = if body.is_static() {
                Color32::from_rgb(70, 74, 82)
            } else {
                Color32::from_rgb(64, 140, 200)
            };
            painter.add(Shape::convex_polygon(
                points,
                fill,
                Stroke::new(1.0, Color32::WHITE),
            ));
        }
        for c in self.world.contacts() {
            let p = self.camera.to_screen(rect, c.point);
            painter.circle_filled(p, 2.5, Color32::from_rgb(240, 90, 60));
        }
    }
}

impl eframe::App for RoboSimApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let frame_seconds = ui.input(|i| i.stable_dt as f64);
        self.advance(frame_seconds);
        egui::Panel::top("toolbar").show(ui, |ui| {
            ui.horizontal(|ui| {
                let label = if self.running { "Pause" } else { "Play" };
                if ui
                    .button(label)
                    .on_hover_text("Start or stop the simulation (Space)")
                    .clicked()
                {
                    self.running = !self.running;
                }
                if ui
                    .button("Reset")
                    .on_hover_text("Start the scene again")
                    .clicked()
                {
                    self.world = falling_boxes();
                    self.accumulator = 0.0;
                }
                ui.label(format!(
                    "step {}  ·  t = {:.2} s  ·  {} contacts",
                    self.world.step_count(),
                    self.world.step_count() as f64 * self.timestep,
                    self.world.contacts().len()
                ));
            });
        });
        egui::CentralPanel::default().show(ui, |ui| self.canvas(ui));
        if self.running {
            ui.ctx().request_repaint();
        }
    }
}
