//! The editor's tools as plain functions of the model: adding a vertex, pinning two bodies
//! at a point, snapping to the grid. The canvas turns clicks into calls; tests call them
//! directly.

use crate::db::outline_polygon;
use crate::model::{JointDef, Model, Placement, Robot, same_name};
use pe::Vec2;

/// What a click on the canvas does in a robot or scene (the body editor has its own).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Tool {
    /// Select a body; at step 0, dragging moves its placement.
    #[default]
    Select,
    /// Robots only: a click on a point covered by two bodies pins them together there.
    Joint,
}

/// Grid spacings offered for snapping (world units); `None` is off.
pub const SNAP_STEPS: [Option<f64>; 5] = [None, Some(0.5), Some(1.0), Some(5.0), Some(10.0)];

/// `v` rounded to the nearest multiple of `step` (unchanged when snapping is off).
pub fn snap(v: f64, step: Option<f64>) -> f64 {
    match step {
        Some(s) if s > 0.0 => (v / s).round() * s,
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

/// Pins the two topmost bodies of robot `robot_name` that cover `p` (robot coordinates):
/// the new joint's anchor is `p` relative to bodyA's placement (SPEC §6.6).
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
    use crate::model::{BodyDef, RobotBody};

    fn square() -> Vec<[f64; 2]> {
        vec![[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]
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
