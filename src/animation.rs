//! A run as an animated GIF, for sharing: the bodies' outlines captured every few steps,
//! drawn by a software rasteriser (tiny-skia) with one camera that frames the whole run,
//! and encoded with the `gif` crate. No GUI: the command line and the editor share it.

use crate::sim::Simulation;
use pe::{Aabb, Vec2};
use std::path::Path;
use tiny_skia::{FillRule, Paint, PathBuilder, Pixmap, Stroke, Transform};

/// Frames per second a GIF aims at: smooth, and a frame delay (whole hundredths of a
/// second) that browsers honour (they slow anything under 2 cs down to 10 cs).
pub const FPS: f64 = 25.0;
/// The picture's size in pixels.
pub const WIDTH: u32 = 640;
pub const HEIGHT: u32 = 480;
/// At most this many frames (40 s at 25 frames a second): a longer run is sampled more
/// sparsely, which keeps the recording's memory and the file's size in bounds.
pub const MAX_FRAMES: u64 = 1000;

const BACKGROUND: [u8; 3] = [24, 26, 30];
const TERRAIN: [u8; 3] = [70, 74, 82];
const OUTLINE: [u8; 3] = [230, 230, 230];

/// One body in one frame: its outline in world coordinates and its fill.
#[derive(Debug, Clone)]
struct Outline {
    points: Vec<Vec2>,
    fill: [u8; 3],
    moving: bool,
}

/// The frames of a run as it is simulated, and their times.
#[derive(Debug, Clone, Default)]
pub struct Recording {
    frames: Vec<(f64, Vec<Outline>)>,
}

/// The fewest steps between frames that keep a run of `steps` steps within `MAX_FRAMES`
/// frames (step 0 is one).
pub fn every_for_at_most_max_frames(steps: u64) -> u64 {
    steps.div_ceil(MAX_FRAMES - 1).max(1)
}

/// Steps between frames for a step of `dt` seconds: one frame every 1/FPS s, or every
/// step when steps are longer than that.
pub fn steps_per_frame(dt: f64) -> u64 {
    ((1.0 / FPS) / dt).round().max(1.0) as u64
}

impl Recording {
    /// Adds the bodies of `sim` as they stand as the next frame.
    pub fn capture(&mut self, sim: &Simulation) {
        let outlines: Vec<Outline> = sim
            .bodies
            .iter()
            .filter_map(|b| {
                let body = sim.world.body(b.handle)?;
                Some(Outline {
                    points: body.world_vertices().collect(),
                    fill: if body.is_static() {
                        TERRAIN
                    } else {
                        colour_for(&b.id)
                    },
                    moving: !body.is_static(),
                })
            })
            .collect();
        self.frames.push((sim.time(), outlines));
    }

    pub fn frame_count(&self) -> usize {
        self.frames.len()
    }

    /// The world box each frame shows. The camera follows the moving bodies as the
    /// editor's Follow does: each frame centred on their box, eased so that it does not
    /// shake with them, at one zoom for the whole run that fits the widest of those boxes
    /// with room to move (a body that flies off stretches it at most tenfold). With
    /// nothing moving, every body at step 0.
    fn views(&self) -> Vec<Aabb> {
        let moving: Vec<Option<Aabb>> = self
            .frames
            .iter()
            .map(|(_, outlines)| {
                bounds(
                    outlines
                        .iter()
                        .filter(|o| o.moving)
                        .flat_map(|o| o.points.iter().copied()),
                )
            })
            .collect();
        let all_at_start = self
            .frames
            .first()
            .and_then(|(_, o)| bounds(o.iter().flat_map(|o| o.points.iter().copied())))
            .unwrap_or(Aabb {
                min: Vec2::repeat(-1.0),
                max: Vec2::repeat(1.0),
            });
        let Some(first) = moving.first().copied().flatten() else {
            return vec![all_at_start; self.frames.len()];
        };
        let widest = moving
            .iter()
            .flatten()
            .fold(Vec2::zeros(), |w, b| w.sup(&(b.max - b.min)));
        let start_size = first.max - first.min;
        // Room around the bodies for them to move, as the editor's fit leaves.
        let size = (widest.inf(&(start_size * 10.0)) * 2.0).sup(&Vec2::repeat(1.0));
        let mut centre = (first.min + first.max) / 2.0;
        moving
            .iter()
            .map(|b| {
                if let Some(b) = b {
                    centre += ((b.min + b.max) / 2.0 - centre) * 0.2;
                }
                Aabb {
                    min: centre - size / 2.0,
                    max: centre + size / 2.0,
                }
            })
            .collect()
    }

    /// The recording as GIF bytes: `width` × `height` pixels, looping, each frame shown
    /// for the simulated time until the next.
    pub fn to_gif(&self, width: u32, height: u32) -> Result<Vec<u8>, String> {
        let (w, h) = (width.clamp(16, 4096), height.clamp(16, 4096));
        let mut pixmap = Pixmap::new(w, h).ok_or("cannot make a picture of that size")?;
        let views = self.views();
        let failed = |e: gif::EncodingError| format!("cannot encode the GIF: {e}");
        let mut encoder = gif::Encoder::new(Vec::new(), w as u16, h as u16, &[]).map_err(failed)?;
        encoder.set_repeat(gif::Repeat::Infinite).map_err(failed)?;
        for (k, ((time, outlines), view)) in self.frames.iter().zip(views).enumerate() {
            paint(&mut pixmap, outlines, &camera(view, w as f64, h as f64));
            let mut rgba = pixmap.data().to_vec();
            // Quantising speed 10: the encoder's default balance of palette and time.
            let mut frame = gif::Frame::from_rgba_speed(w as u16, h as u16, &mut rgba, 10);
            // Delays in whole centiseconds, rounded on the running time so they add up.
            let next = self.frames.get(k + 1).map_or(time + 1.0 / FPS, |f| f.0);
            let delay = (next * 100.0).round() - (time * 100.0).round();
            frame.delay = delay.clamp(2.0, 65535.0) as u16;
            encoder.write_frame(&frame).map_err(failed)?;
        }
        encoder.into_inner().map_err(failed)
    }
}

/// Simulates `sim` for `steps` steps and records it every `every` steps, from step 0
/// (`every` grows so that there are at most `MAX_FRAMES` frames). Err: why a step failed.
pub fn record(sim: &mut Simulation, steps: u64, every: u64) -> Result<Recording, String> {
    let every = every.max(every_for_at_most_max_frames(steps));
    let mut recording = Recording::default();
    recording.capture(sim);
    for _ in 0..steps {
        sim.try_step()
            .map_err(|e| format!("step {}: {e}", sim.step_count()))?;
        if sim.step_count().is_multiple_of(every) {
            recording.capture(sim);
        }
    }
    Ok(recording)
}

/// Writes `bytes` to `path` atomically: a temporary file beside it, then renamed over it,
/// so that a failure never leaves half a file. Err: one line saying why.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), String> {
    use std::io::Write;
    // tempfile names its temporary file in its errors ("… at path /x/.robosim-…"): the
    // user asked for `path`, so the message names that alone.
    let failed = |e: &dyn std::fmt::Display| {
        let why = e.to_string();
        let why = why
            .split(" at path ")
            .next()
            .unwrap_or_default()
            .to_string();
        format!("cannot write {}: {why}", path.display())
    };
    // Written through a symbolic link to where it points, as the database's saving does;
    // a device or a FIFO (`/dev/stdout`) is written as it is, not replaced.
    let target = crate::paths::resolve_links(path).map_err(|e| failed(&e))?;
    if std::fs::metadata(&target).is_ok_and(|m| !m.is_file() && !m.is_dir()) {
        let mut device = std::fs::OpenOptions::new()
            .write(true)
            .open(&target)
            .map_err(|e| failed(&e))?;
        return device
            .write_all(bytes)
            .and_then(|()| device.flush())
            .map_err(|e| failed(&e));
    }
    let folder = match target.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let mut file = tempfile::Builder::new()
        .prefix(".robosim-")
        .suffix(".tmp")
        .tempfile_in(folder)
        .map_err(|e| failed(&e))?;
    file.write_all(bytes).map_err(|e| failed(&e))?;
    #[cfg(unix)]
    {
        // As the user's files usually are, not tempfile's private 0600.
        use std::os::unix::fs::PermissionsExt;
        let readable = std::fs::Permissions::from_mode(0o644);
        file.as_file()
            .set_permissions(readable)
            .map_err(|e| failed(&e))?;
    }
    file.as_file().sync_all().map_err(|e| failed(&e))?;
    file.persist(&target).map_err(|e| failed(&e.error))?;
    Ok(())
}

/// World to pixels: `view` scaled to fit `w` × `h`, centred, y down as in the files.
fn camera(view: Aabb, w: f64, h: f64) -> impl Fn(Vec2) -> (f32, f32) {
    let size = view.max - view.min;
    let zoom = (w / size.x.max(1e-9)).min(h / size.y.max(1e-9));
    let centre = (view.min + view.max) / 2.0;
    move |p: Vec2| {
        let d = (p - centre) * zoom;
        ((w / 2.0 + d.x) as f32, (h / 2.0 + d.y) as f32)
    }
}

/// Draws one frame: the background, then static bodies under the moving ones.
fn paint(pixmap: &mut Pixmap, outlines: &[Outline], to_pixels: &impl Fn(Vec2) -> (f32, f32)) {
    let [r, g, b] = BACKGROUND;
    pixmap.fill(tiny_skia::Color::from_rgba8(r, g, b, 255));
    let stroke = Stroke {
        width: 1.0,
        ..Stroke::default()
    };
    let mut outline_paint = Paint::default();
    let [r, g, b] = OUTLINE;
    outline_paint.set_color_rgba8(r, g, b, 255);
    outline_paint.anti_alias = true;
    for moving in [false, true] {
        for o in outlines.iter().filter(|o| o.moving == moving) {
            let mut path = PathBuilder::new();
            for (k, p) in o.points.iter().enumerate() {
                let (x, y) = to_pixels(*p);
                if k == 0 {
                    path.move_to(x, y);
                } else {
                    path.line_to(x, y);
                }
            }
            path.close();
            let Some(path) = path.finish() else {
                continue;
            };
            let mut fill = Paint::default();
            let [r, g, b] = o.fill;
            fill.set_color_rgba8(r, g, b, 255);
            fill.anti_alias = true;
            pixmap.fill_path(&path, &fill, FillRule::Winding, Transform::identity(), None);
            pixmap.stroke_path(&path, &outline_paint, &stroke, Transform::identity(), None);
        }
    }
}

/// The box around `points` (None when there are none or one is not finite).
fn bounds(points: impl Iterator<Item = Vec2>) -> Option<Aabb> {
    let mut aabb = Aabb {
        min: Vec2::repeat(f64::INFINITY),
        max: Vec2::repeat(f64::NEG_INFINITY),
    };
    for p in points.filter(|p| p.x.is_finite() && p.y.is_finite()) {
        aabb.min = aabb.min.inf(&p);
        aabb.max = aabb.max.sup(&p);
    }
    (aabb.min.x <= aabb.max.x).then_some(aabb)
}

/// A stable colour per robot (its bodies share it) or per loose body, as the editor
/// picks it (`app::canvas::draw::colour_for`): hue from an FNV-1a hash of the name,
/// saturation 0.45 and value 0.75 in linear light, encoded as sRGB, and drawn 85 % opaque
/// over the background.
pub fn colour_for(id: &str) -> [u8; 3] {
    let key = id.split('/').next().unwrap_or(id);
    let hash = key
        .bytes()
        .fold(2166136261u32, |h, b| (h ^ b as u32).wrapping_mul(16777619));
    let linear = hsv_to_rgb((hash % 360) as f64, 0.45, 0.75);
    std::array::from_fn(|k| {
        let over = 0.85 * srgb(linear[k]) + 0.15 * BACKGROUND[k] as f64 / 255.0;
        (over * 255.0).round().clamp(0.0, 255.0) as u8
    })
}

/// Linear light to sRGB's encoding (IEC 61966-2-1).
fn srgb(l: f64) -> f64 {
    if l <= 0.0031308 {
        12.92 * l
    } else {
        1.055 * l.powf(1.0 / 2.4) - 0.055
    }
}

/// HSV (hue in degrees) to RGB in [0, 1].
fn hsv_to_rgb(hue: f64, s: f64, v: f64) -> [f64; 3] {
    let c = v * s;
    let x = c * (1.0 - ((hue / 60.0) % 2.0 - 1.0).abs());
    let m = v - c;
    let (r, g, b) = match (hue / 60.0) as u32 {
        0 => (c, x, 0.0),
        1 => (x, c, 0.0),
        2 => (0.0, c, x),
        3 => (0.0, x, c),
        4 => (x, 0.0, c),
        _ => (c, 0.0, x),
    };
    [r + m, g + m, b + m]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_come_every_25th_of_a_second_or_every_step() {
        assert_eq!(steps_per_frame(1.0 / 60.0), 2);
        assert_eq!(steps_per_frame(0.05), 1);
        assert_eq!(steps_per_frame(0.001), 40);
    }

    #[test]
    fn hues_go_round_the_colour_wheel() {
        assert_eq!(hsv_to_rgb(0.0, 1.0, 1.0), [1.0, 0.0, 0.0]);
        assert_eq!(hsv_to_rgb(120.0, 1.0, 1.0), [0.0, 1.0, 0.0]);
        assert_eq!(hsv_to_rgb(240.0, 1.0, 1.0), [0.0, 0.0, 1.0]);
    }
}
