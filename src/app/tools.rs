//! The editor's tools as plain functions of the model: adding a vertex, pinning two bodies
//! at a point, snapping to the grid. The canvas turns clicks into calls; tests call them
//! directly.

use super::Selection;
use crate::db::outline_polygon;
use crate::model::{BodyDef, JointDef, Model, Placement, Robot, RobotBody, same_name};
use pe::Vec2;

/// What a click on the canvas does in a robot or scene (the body editor has its own).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Tool {
    /// Select a body; at step 0, dragging moves its placement.
    #[default]
    Select,
    /// Robots only: a click on a point covered by two bodies pins them together there.
    Joint,
    /// A drag from corner to corner draws a box: a new body, placed where it was drawn.
    Box,
    /// A drag from the centre out draws a regular polygon of that circumradius.
    Polygon,
}

impl Tool {
    /// Whether the tool draws new bodies (at step 0, into a scene or a robot).
    pub fn draws(self) -> bool {
        matches!(self, Tool::Box | Tool::Polygon)
    }
}

/// How the drawing tools shape and make their bodies.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShapeOptions {
    /// The polygon tool's number of sides.
    pub sides: u32,
    /// Draw static terrain (density 0) instead of a moving body (density 1).
    pub terrain: bool,
}

impl Default for ShapeOptions {
    fn default() -> Self {
        Self {
            sides: 6,
            terrain: false,
        }
    }
}

/// The sides the polygon tool offers.
pub const POLYGON_SIDES: std::ops::RangeInclusive<u32> = 3..=12;

/// A body drawn on the canvas: its outline about its own origin, and where that origin
/// goes (in the scene's or the robot's frame).
#[derive(Debug, Clone, PartialEq)]
pub struct DrawnShape {
    pub vertices: Vec<[f64; 2]>,
    pub at: Vec2,
    /// The start of its name: "box", "hexagon", …
    pub kind: String,
}

/// Drawn shapes smaller than this (world units) are refused: a slip, not a body.
const SMALLEST_DRAWN: f64 = 1.0;

/// The shape `tool` draws for a drag from `from` to `to`, or why there is none.
pub fn drawn_shape(
    tool: Tool,
    options: ShapeOptions,
    from: Vec2,
    to: Vec2,
) -> Result<DrawnShape, String> {
    match tool {
        Tool::Box => {
            let size = (to - from).abs();
            if size.x < SMALLEST_DRAWN || size.y < SMALLEST_DRAWN {
                return Err("drag further: a box needs a width and a height".into());
            }
            let (w, h) = (size.x / 2.0, size.y / 2.0);
            Ok(DrawnShape {
                vertices: vec![[-w, -h], [w, -h], [w, h], [-w, h]],
                at: (from + to) / 2.0,
                kind: "box".into(),
            })
        }
        Tool::Polygon => {
            let r = (to - from).norm();
            if r < SMALLEST_DRAWN {
                return Err("drag further: the drag from the centre sets the radius".into());
            }
            let n = options
                .sides
                .clamp(*POLYGON_SIDES.start(), *POLYGON_SIDES.end());
            Ok(DrawnShape {
                vertices: regular_polygon(n, r),
                at: from,
                kind: polygon_name(n),
            })
        }
        Tool::Select | Tool::Joint => Err("this tool draws nothing".into()),
    }
}

/// `v` to a thousandth, as the editor writes computed numbers (no `-0`: a file would keep
/// it).
fn to_thousandth(v: f64) -> f64 {
    (v * 1000.0).round() / 1000.0 + 0.0
}

/// A regular `n`-gon of circumradius `r` about the origin, with a flat edge at the bottom
/// (+y, down on screen) so that it rests on the ground as drawn; vertices in the order of
/// the app's other outlines, to a thousandth (no `-0`: a file would keep it).
pub fn regular_polygon(n: u32, r: f64) -> Vec<[f64; 2]> {
    use std::f64::consts::{FRAC_PI_2, PI, TAU};
    let start = FRAC_PI_2 + PI / n as f64;
    let round = to_thousandth;
    (0..n)
        .map(|k| {
            let a = start + TAU * k as f64 / n as f64;
            [round(r * a.cos()), round(r * a.sin())]
        })
        .collect()
}

fn polygon_name(n: u32) -> String {
    match n {
        3 => "triangle".into(),
        4 => "square".into(),
        5 => "pentagon".into(),
        6 => "hexagon".into(),
        7 => "heptagon".into(),
        8 => "octagon".into(),
        _ => format!("{n}-gon"),
    }
}

/// Adds `shape` as a new body definition (density 1, or 0 as `terrain`) and places it
/// where it was drawn in scene or robot `into`. Its name is the first "kind k" that is
/// neither a body's name nor a placement's alias there, so that both can be the same.
/// Returns the name.
pub fn add_drawn_body(
    model: &mut Model,
    into: &Selection,
    shape: DrawnShape,
    terrain: bool,
) -> Result<String, String> {
    let aliases: Vec<String> = match into {
        Selection::Scene(n) => model
            .scene(n)
            .map(|s| s.bodies.iter().map(|b| b.alias.clone()).collect()),
        Selection::Robot(n) => model
            .robot(n)
            .map(|r| r.bodies.iter().map(|b| b.placement.alias.clone()).collect()),
        Selection::Body(_) => None,
    }
    .ok_or("draw into a scene or a robot")?;
    let name = (1..)
        .map(|k| format!("{} {k}", shape.kind))
        .find(|c| model.body(c).is_none() && !aliases.iter().any(|a| same_name(a, c)))
        .expect("some number is free");
    model.bodies.push(BodyDef {
        name: name.clone(),
        density: if terrain { 0.0 } else { 1.0 },
        // The restitution of the app's other new bodies.
        cor: 0.2,
        vertices: shape.vertices,
        ..BodyDef::default()
    });
    let placement = Placement {
        alias: name.clone(),
        source: name.clone(),
        x: shape.at.x,
        y: shape.at.y,
        ..Placement::default()
    };
    match into {
        Selection::Scene(n) => model.scene_mut(n).map(|s| s.bodies.push(placement)),
        Selection::Robot(n) => model.robot_mut(n).map(|r| {
            r.bodies.push(RobotBody {
                placement,
                motors: Vec::new(),
            })
        }),
        Selection::Body(_) => None,
    };
    Ok(name)
}

/// Grid spacings offered for snapping (world units); `None` is off.
pub const SNAP_STEPS: [Option<f64>; 5] = [None, Some(0.5), Some(1.0), Some(5.0), Some(10.0)];

/// `v` rounded to the nearest multiple of `step` (unchanged when snapping is off).
pub fn snap(v: f64, step: Option<f64>) -> f64 {
    match step {
        // `+ 0.0`: a point snapped to zero from below is 0, not -0 (written `-0`).
        Some(s) if s > 0.0 => (v / s).round() * s + 0.0,
        _ => v,
    }
}

/// Adds the vertex `p` to a body outline. With fewer than three vertices it is appended
/// (the outline is still being drawn). Otherwise it goes into the edge it is nearest to,
/// and a point that would leave the outline non-convex is refused with the reason.
pub fn add_vertex(vertices: &[[f64; 2]], p: [f64; 2]) -> Result<Vec<[f64; 2]>, String> {
    if vertices.contains(&p) {
        return Err(format!("({}, {}) is already a vertex", p[0], p[1]));
    }
    if vertices.len() < 3 {
        let mut v = vertices.to_vec();
        v.push(p);
        return Ok(v);
    }
    // Try the edges nearest the point first: that is where the user means to put it.
    let point = Vec2::new(p[0], p[1]);
    let mut edges: Vec<(f64, usize)> = (0..vertices.len())
        .map(|i| {
            let a = Vec2::new(vertices[i][0], vertices[i][1]);
            let j = (i + 1) % vertices.len();
            let b = Vec2::new(vertices[j][0], vertices[j][1]);
            (distance_to_segment(point, a, b), i)
        })
        .collect();
    edges.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut candidates = Vec::new();
    for (_, i) in edges {
        let mut v = vertices.to_vec();
        v.insert(i + 1, p);
        if outline_polygon(&v).is_ok() {
            return Ok(v);
        }
        candidates.push(v);
    }
    let reason = candidates
        .first()
        .and_then(|v| outline_polygon(v).err())
        .map_or_else(String::new, |e| format!(" ({e})"));
    Err(format!(
        "a vertex at ({}, {}) would make the body non-convex{reason}; Shift+click adds it anyway, then Convex hull repairs the outline",
        p[0], p[1]
    ))
}

/// `vertices` with `p` put into the edge nearest to it, convex or not: what Shift+click
/// adds (a dent the user means, to be repaired later) where `add_vertex` refuses.
pub fn add_vertex_anyway(vertices: &[[f64; 2]], p: [f64; 2]) -> Vec<[f64; 2]> {
    let point = Vec2::new(p[0], p[1]);
    let n = vertices.len();
    let nearest = (0..n).min_by(|&i, &k| {
        let edge = |i: usize| {
            let a = Vec2::new(vertices[i][0], vertices[i][1]);
            let b = Vec2::new(vertices[(i + 1) % n][0], vertices[(i + 1) % n][1]);
            distance_to_segment(point, a, b)
        };
        edge(i).total_cmp(&edge(k))
    });
    let mut v = vertices.to_vec();
    match nearest {
        Some(i) if n >= 3 => v.insert(i + 1, p),
        _ => v.push(p),
    }
    v
}

fn distance_to_segment(p: Vec2, a: Vec2, b: Vec2) -> f64 {
    let ab = b - a;
    let t = ((p - a).dot(&ab) / ab.norm_squared().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
    (a + ab * t - p).norm()
}

/// Whether the body placed by `placement` covers `p` (in the placement's parent frame).
fn covers(model: &Model, placement: &Placement, p: Vec2) -> bool {
    let Some(polygon) = model
        .body(&placement.source)
        .and_then(|d| outline_polygon(&d.vertices).ok())
    else {
        return false;
    };
    // Into the body's own frame: p_local = R(−orientation)·(p − origin).
    let (s, c) = placement.orientation.sin_cos();
    let d = p - Vec2::new(placement.x, placement.y);
    polygon.contains(Vec2::new(c * d.x + s * d.y, -s * d.x + c * d.y))
}

/// The aliases of `robot`'s bodies whose outlines cover `p` (robot coordinates), topmost
/// (last drawn) first.
pub fn bodies_at(model: &Model, robot: &Robot, p: Vec2) -> Vec<String> {
    robot
        .bodies
        .iter()
        .rev()
        .filter(|b| covers(model, &b.placement, p))
        .map(|b| b.placement.alias.clone())
        .collect()
}

/// The centre of mass or vertex of one of `robot`'s bodies nearest to `p` (robot
/// coordinates) within `radius`, centres first: a wheel's axle lands on its centre, not a
/// pixel off, when the joint tool is clicked near it.
pub fn joint_snap_point(model: &Model, robot: &Robot, p: Vec2, radius: f64) -> Option<Vec2> {
    let mut centres = Vec::new();
    let mut vertices = Vec::new();
    for b in &robot.bodies {
        let Some(polygon) = model
            .body(&b.placement.source)
            .and_then(|d| outline_polygon(&d.vertices).ok())
        else {
            continue;
        };
        let pl = &b.placement;
        let (s, c) = pl.orientation.sin_cos();
        let place = |v: Vec2| Vec2::new(pl.x + c * v.x - s * v.y, pl.y + s * v.x + c * v.y);
        // To a thousandth, as the editor's other numbers: a centroid found by summing
        // (5.000000000000002 for a hexagon's) would be written as it is.
        let centre = place(polygon.mass_properties().centroid);
        centres.push(Vec2::new(to_thousandth(centre.x), to_thousandth(centre.y)));
        vertices.extend(polygon.vertices().iter().map(|&v| place(v)));
    }
    let nearest = |points: &[Vec2]| {
        points
            .iter()
            .copied()
            .filter(|q| (q - p).norm() <= radius)
            .min_by(|a, b| (a - p).norm().total_cmp(&(b - p).norm()))
    };
    nearest(&centres).or_else(|| nearest(&vertices))
}

/// Pins the two topmost bodies of robot `robot_name` that cover `p` (robot coordinates):
/// the new joint's anchor is `p` relative to bodyA's placement (thesis §6.6).
pub fn add_joint(model: &mut Model, robot_name: &str, p: Vec2) -> Result<JointDef, String> {
    let robot = model
        .robot(robot_name)
        .ok_or_else(|| format!("no robot named {robot_name:?}"))?;
    let hits = bodies_at(model, robot, p);
    let [a, b] = match hits.as_slice() {
        [a, b, ..] => [a.clone(), b.clone()],
        _ => {
            return Err(format!(
                "a joint needs a point covered by two bodies; ({:.1}, {:.1}) is covered by {}",
                p.x,
                p.y,
                hits.len()
            ));
        }
    };
    // bodyA is the one drawn below, as the thesis's robots list the carrier first.
    let (body_a, body_b) = (b, a);
    if robot.joints.iter().any(|j| {
        let pins = |a: &str, b: &str| same_name(&j.body_a, a) && same_name(&j.body_b, b);
        pins(&body_a, &body_b) || pins(&body_b, &body_a)
    }) {
        return Err(format!("{body_a} and {body_b} are already pinned together"));
    }
    let origin = robot
        .body(&body_a)
        .map(|rb| (rb.placement.x, rb.placement.y))
        .unwrap_or_default();
    let joint = JointDef {
        body_a,
        body_b,
        anchor_ax: p.x - origin.0,
        anchor_ay: p.y - origin.1,
        ..JointDef::default()
    };
    let robot = model.robot_mut(robot_name).expect("found above");
    robot.joints.push(joint.clone());
    Ok(joint)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> Vec<[f64; 2]> {
        vec![[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]
    }

    #[test]
    fn the_joint_tool_snaps_to_a_centre_then_a_vertex_within_its_radius() {
        let mut model = Model::default();
        model.bodies.push(BodyDef {
            name: "wheel".into(),
            density: 1.0,
            vertices: vec![[-10.0, -10.0], [10.0, -10.0], [10.0, 10.0], [-10.0, 10.0]],
            ..Default::default()
        });
        let robot = Robot {
            name: "r".into(),
            bodies: vec![RobotBody {
                placement: Placement {
                    alias: "w".into(),
                    source: "wheel".into(),
                    x: 100.0,
                    y: 50.0,
                    orientation: std::f64::consts::FRAC_PI_4,
                    ..Default::default()
                },
                motors: Vec::new(),
            }],
            ..Default::default()
        };
        let near = |x, y| joint_snap_point(&model, &robot, Vec2::new(x, y), 3.0);
        assert_eq!(
            near(101.0, 51.0),
            Some(Vec2::new(100.0, 50.0)),
            "the centre"
        );
        // The corner (10, 10) turned 45°: (0, 10√2) from the centre.
        let corner = near(100.5, 50.0 + 14.0).unwrap();
        assert!((corner - Vec2::new(100.0, 50.0 + 200f64.sqrt())).norm() < 1e-9);
        assert_eq!(near(106.0, 50.0), None, "nothing within the radius");
    }

    #[test]
    fn shift_click_puts_a_dent_into_the_nearest_edge_and_snaps_to_plus_zero() {
        // Inside the square near its bottom edge (0,0)-(10,0): a dent there, not at the end.
        let dented = add_vertex_anyway(&square(), [5.0, 1.0]);
        assert_eq!(dented[1], [5.0, 1.0]);
        assert_eq!(dented.len(), 5);
        let zero = snap(-0.1, Some(0.5));
        assert!(zero == 0.0 && zero.is_sign_positive(), "{zero:?}");
    }

    #[test]
    fn a_vertex_goes_into_its_nearest_edge_and_a_dent_is_refused() {
        let v = add_vertex(&square(), [5.0, -3.0]).unwrap();
        assert_eq!(v[1], [5.0, -3.0], "between (0,0) and (10,0)");
        assert!(outline_polygon(&v).is_ok());
        let err = add_vertex(&square(), [5.0, 5.0]).unwrap_err();
        assert!(err.contains("non-convex"), "{err}");
        assert!(
            add_vertex(&square(), [10.0, 10.0]).is_err(),
            "a repeated point"
        );
        // Drawing from nothing: the first points are appended as they come.
        let mut drawn = Vec::new();
        for p in [[0.0, 0.0], [4.0, 0.0], [4.0, 3.0]] {
            drawn = add_vertex(&drawn, p).unwrap();
        }
        assert_eq!(drawn.len(), 3);
        assert!(outline_polygon(&drawn).is_ok());
    }

    #[test]
    fn a_drawn_polygon_is_regular_convex_and_flat_at_the_bottom() {
        let hexagon = regular_polygon(6, 10.0);
        assert_eq!(hexagon.len(), 6);
        assert!(outline_polygon(&hexagon).is_ok());
        for v in &hexagon {
            assert!((v[0].hypot(v[1]) - 10.0).abs() < 1e-3, "{v:?}");
        }
        // The two lowest vertices (largest y) are level.
        let mut ys: Vec<f64> = hexagon.iter().map(|v| v[1]).collect();
        ys.sort_by(f64::total_cmp);
        assert_eq!(ys[4], ys[5]);
        let square = regular_polygon(4, 2f64.sqrt());
        assert_eq!(square, [[-1.0, 1.0], [-1.0, -1.0], [1.0, -1.0], [1.0, 1.0]]);
        let slip = drawn_shape(
            Tool::Box,
            ShapeOptions::default(),
            Vec2::zeros(),
            Vec2::new(5.0, 0.5),
        );
        assert!(slip.is_err());
    }

    #[test]
    fn snapping_rounds_to_the_grid_or_not_at_all() {
        assert_eq!(snap(12.3, Some(5.0)), 10.0);
        assert_eq!(snap(-2.6, Some(0.5)), -2.5);
        assert_eq!(snap(12.3, None), 12.3);
    }

    #[test]
    fn a_joint_pins_the_two_bodies_under_the_point() {
        let mut model = Model {
            bodies: vec![BodyDef {
                name: "sq".into(),
                density: 1.0,
                vertices: square(),
                ..BodyDef::default()
            }],
            robots: vec![Robot {
                name: "r".into(),
                bodies: ["a", "b"]
                    .iter()
                    .enumerate()
                    .map(|(i, alias)| RobotBody {
                        placement: Placement {
                            alias: alias.to_string(),
                            source: "sq".into(),
                            x: 8.0 * i as f64,
                            y: 1.0,
                            ..Placement::default()
                        },
                        motors: Vec::new(),
                    })
                    .collect(),
                ..Robot::default()
            }],
            ..Model::default()
        };
        let err = add_joint(&mut model, "r", Vec2::new(2.0, 5.0)).unwrap_err();
        assert!(err.contains("covered by 1"), "{err}");
        let j = add_joint(&mut model, "r", Vec2::new(9.0, 5.0)).unwrap();
        assert_eq!((j.body_a.as_str(), j.body_b.as_str()), ("a", "b"));
        assert_eq!(
            (j.anchor_ax, j.anchor_ay),
            (9.0, 4.0),
            "relative to a at (0, 1)"
        );
        assert_eq!(model.robots[0].joints.len(), 1);
        assert!(
            add_joint(&mut model, "r", Vec2::new(9.5, 5.0)).is_err(),
            "already pinned"
        );
    }
}
