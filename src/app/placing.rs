//! Where new placements go and which placed bodies overlap: plain functions of a scene's
//! bodies at step 0, so that the app and the tests share them.

use crate::sim::{PlacedBy, Simulation};
use pe::{Aabb, Vec2};

/// The box around a set of points (None when there are none or one is not finite).
pub fn bounds_of(points: impl IntoIterator<Item = Vec2>) -> Option<Aabb> {
    let mut aabb = Aabb {
        min: Vec2::repeat(f64::INFINITY),
        max: Vec2::repeat(f64::NEG_INFINITY),
    };
    for p in points {
        aabb.min = aabb.min.inf(&p);
        aabb.max = aabb.max.sup(&p);
    }
    (aabb.min.x.is_finite() && aabb.max.x.is_finite() && aabb.min.y.is_finite()).then_some(aabb)
}

/// Every body's box in `sim` as it stands.
pub fn body_boxes(sim: &Simulation) -> Vec<Aabb> {
    sim.bodies
        .iter()
        .filter_map(|b| sim.world.body(b.handle))
        .filter_map(|b| bounds_of(b.world_vertices()))
        .collect()
}

/// The reference point for an item whose box relative to that point is `item`, with the
/// box's middle as near `centre` as it can be without the box (plus a small gap)
/// touching any of `occupied`.
/// Among equally near places, higher ones (smaller y) win: a robot dropped over the
/// ground lands on it. Falls back to `centre` when the neighbourhood is full.
pub fn free_spot(occupied: &[Aabb], item: Aabb, centre: Vec2) -> Vec2 {
    let size = item.max - item.min;
    let gap = 0.05 * size.x.max(size.y).max(1.0);
    // Candidates a quarter of the item apart, up to ten item sizes away.
    let step = Vec2::new(size.x.max(1.0), size.y.max(1.0)) * 0.25;
    const RINGS: i32 = 40;
    let middle = (item.min + item.max) * 0.5;
    let mut candidates: Vec<(f64, i32, Vec2)> = Vec::new();
    for i in -RINGS..=RINGS {
        for j in -RINGS..=RINGS {
            let offset = Vec2::new(i as f64 * step.x, j as f64 * step.y);
            candidates.push((offset.norm(), j, centre + offset - middle));
        }
    }
    candidates.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    candidates
        .into_iter()
        .map(|(_, _, p)| p)
        .find(|&p| {
            let placed = Aabb {
                min: item.min + p,
                max: item.max + p,
            }
            .grown(gap);
            !occupied.iter().any(|o| o.overlaps(&placed))
        })
        .unwrap_or(centre - middle)
}

/// How deep two convex outlines overlap along their axis of least overlap (separating
/// axis theorem, thesis §3.1); 0 or less when they are apart. Either vertex order works.
pub fn overlap_depth(a: &[Vec2], b: &[Vec2]) -> f64 {
    let mut depth = f64::INFINITY;
    for poly in [a, b] {
        for k in 0..poly.len() {
            let edge = poly[(k + 1) % poly.len()] - poly[k];
            let Some(axis) = Vec2::new(-edge.y, edge.x).try_normalize(1e-12) else {
                continue;
            };
            let project = |p: &[Vec2]| {
                p.iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                        let d = v.dot(&axis);
                        (lo.min(d), hi.max(d))
                    })
            };
            let ((min_a, max_a), (min_b, max_b)) = (project(a), project(b));
            depth = depth.min((max_a - min_b).min(max_b - min_a));
            if depth <= 0.0 {
                return depth;
            }
        }
    }
    depth
}

/// Pairs of bodies (indices into `sim.bodies`) that overlap more than a twentieth of the
/// typical body size: the first step would push them apart. Bodies of one placed robot
/// may overlap (around their joints, by design), and two static bodies never collide,
/// so neither counts.
pub fn overlapping_pairs(sim: &Simulation) -> Vec<(usize, usize)> {
    let tolerance = 0.05 * sim.world.settings.length_scale;
    let shapes: Vec<Option<(Vec<Vec2>, Aabb, bool)>> = sim
        .bodies
        .iter()
        .map(|b| {
            let body = sim.world.body(b.handle)?;
            let vertices: Vec<Vec2> = body.world_vertices().collect();
            let aabb = bounds_of(vertices.iter().copied())?;
            Some((vertices, aabb, body.is_static()))
        })
        .collect();
    let robot_of = |i: usize| match sim.bodies[i].placed_by {
        PlacedBy::RobotBody { robot, .. } => Some(robot),
        PlacedBy::SceneBody(_) => None,
    };
    let mut pairs = Vec::new();
    for i in 0..shapes.len() {
        for j in i + 1..shapes.len() {
            let (Some((va, ba, sa)), Some((vb, bb, sb))) = (&shapes[i], &shapes[j]) else {
                continue;
            };
            let same_robot = robot_of(i).is_some() && robot_of(i) == robot_of(j);
            if (*sa && *sb) || same_robot || !ba.overlaps(bb) {
                continue;
            }
            if overlap_depth(va, vb) > tolerance {
                pairs.push((i, j));
            }
        }
    }
    pairs
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(x: f64, y: f64, half: f64) -> Vec<Vec2> {
        vec![
            Vec2::new(x - half, y - half),
            Vec2::new(x + half, y - half),
            Vec2::new(x + half, y + half),
            Vec2::new(x - half, y + half),
        ]
    }

    #[test]
    fn overlap_depth_is_the_least_push_apart() {
        assert!(
            (overlap_depth(&square(0.0, 0.0, 1.0), &square(1.5, 0.2, 1.0)) - 0.5).abs() < 1e-12
        );
        assert!(overlap_depth(&square(0.0, 0.0, 1.0), &square(3.0, 0.0, 1.0)) < 0.0);
        let mut reversed = square(1.5, 0.0, 1.0);
        reversed.reverse();
        assert!((overlap_depth(&square(0.0, 0.0, 1.0), &reversed) - 0.5).abs() < 1e-12);
    }

    #[test]
    fn a_free_spot_is_the_nearest_clear_place_preferring_higher() {
        let floor = Aabb {
            min: Vec2::new(-100.0, -10.0),
            max: Vec2::new(100.0, 10.0),
        };
        let item = Aabb {
            min: Vec2::new(-5.0, -5.0),
            max: Vec2::new(5.0, 5.0),
        };
        let p = free_spot(&[floor], item, Vec2::zeros());
        assert_eq!(p.x, 0.0);
        assert!(p.y < -15.0 && p.y > -25.0, "just above the floor: {p}");
        assert_eq!(
            free_spot(&[], item, Vec2::new(3.0, 4.0)),
            Vec2::new(3.0, 4.0)
        );
    }
}
