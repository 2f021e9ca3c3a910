//! The canvas view: world coordinates (y down, like the screen) to screen points.

use egui::{Pos2, Rect, Vec2 as ScreenVec};

/// Pan and zoom of the canvas. World and screen share their axes, so no flip is needed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// World point shown at the centre of the canvas.
    pub centre: pe::Vec2,
    /// Screen points per world unit.
    pub zoom: f64,
}

impl Default for Camera {
    fn default() -> Self {
        Self {
            centre: pe::Vec2::zeros(),
            zoom: 1.0,
        }
    }
}

impl Camera {
    pub fn to_screen(&self, canvas: Rect, p: pe::Vec2) -> Pos2 {
        let d = (p - self.centre) * self.zoom;
        canvas.center() + ScreenVec::new(d.x as f32, d.y as f32)
    }

    pub fn to_world(&self, canvas: Rect, p: Pos2) -> pe::Vec2 {
        let d = p - canvas.center();
        self.centre + pe::Vec2::new(d.x as f64, d.y as f64) / self.zoom
    }

    /// Zooms by `factor` keeping the world point under `anchor` fixed on screen.
    pub fn zoom_about(&mut self, canvas: Rect, anchor: Pos2, factor: f64) {
        let before = self.to_world(canvas, anchor);
        self.zoom = (self.zoom * factor).clamp(1e-4, 1e4);
        let after = self.to_world(canvas, anchor);
        self.centre += before - after;
    }

    /// Frames the world rectangle `[min, max]` in the canvas with a margin.
    pub fn fit(&mut self, canvas: Rect, min: pe::Vec2, max: pe::Vec2) {
        let size = (max - min).abs();
        self.centre = (min + max) * 0.5;
        let zx = canvas.width() as f64 / size.x.max(1e-9);
        let zy = canvas.height() as f64 / size.y.max(1e-9);
        self.zoom = (0.9 * zx.min(zy)).clamp(1e-4, 1e4);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn screen_and_world_round_trip_and_zoom_keeps_the_anchor() {
        let canvas = Rect::from_min_size(Pos2::new(10.0, 20.0), ScreenVec::new(800.0, 600.0));
        let mut cam = Camera {
            centre: pe::Vec2::new(100.0, 50.0),
            zoom: 2.0,
        };
        let p = pe::Vec2::new(130.0, 20.0);
        let s = cam.to_screen(canvas, p);
        assert!((cam.to_world(canvas, s) - p).norm() < 1e-4);
        cam.zoom_about(canvas, s, 1.5);
        assert!((cam.to_screen(canvas, p) - s).length() < 1e-3);
    }
}
