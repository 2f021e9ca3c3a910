//! Separating-axis narrow phase with reference/incident edge clipping (thesis §3.1).
//!
//! The axes are the outward edge normals of both polygons, each tested on its outward side
//! only: those are exactly the edge normals of the Minkowski difference, so the least
//! overlap found is the true penetration depth, also for deep penetration and containment.
//! This gives the same depth as the thesis's two-sided test and a reference edge that faces the
//! other body.

use super::{ContactPoint, FeatureId, Manifold, WorldPolygon};
use crate::body::BodyHandle;
use crate::math::Vec2;

/// Contacts of `a` and `b`, or `None` when they are farther apart than `margin`.
///
/// Points up to `margin` apart are kept (with negative depth) so that resting contacts
/// persist. An axis of `b` replaces the best axis of `a` only when it is better by more than
/// `tie_tolerance`, so parallel faces keep a stable reference edge from step to step.
pub fn collide_polygons(
    a: (BodyHandle, &WorldPolygon),
    b: (BodyHandle, &WorldPolygon),
    margin: f64,
    tie_tolerance: f64,
) -> Option<Manifold> {
    let mut found = Vec::with_capacity(1);
    collide_polygons_into(a, b, (margin, tie_tolerance), &mut found).then(|| found[0])
}

/// `collide_polygons`, the manifold pushed onto `manifolds`; `false` if there is none.
/// A narrow phase's list: returned by value and then pushed, each manifold was copied
/// through the stack, and the copy's wide loads waited on the narrower stores that had
/// just written it (a sixth of `World::detect_contacts`' own samples in the smash).
pub(crate) fn collide_polygons_into(
    (handle_a, a): (BodyHandle, &WorldPolygon),
    (handle_b, b): (BodyHandle, &WorldPolygon),
    (margin, tie_tolerance): (f64, f64),
    manifolds: &mut Vec<Manifold>,
) -> bool {
    let (edge_a, separation_a) = separation_beyond(a, b, f64::NEG_INFINITY, margin);
    if separation_a > margin {
        return false;
    }
    // B's best edge matters only if it beats A's by the tie tolerance or parts the pair
    // (beyond the margin): below the lower of the two, B's search need not find it.
    let floor = (separation_a + tie_tolerance).min(margin);
    let (edge_b, separation_b) = separation_beyond(b, a, floor, margin);
    if separation_b > margin {
        return false;
    }
    let reference_is_b = separation_b > separation_a + tie_tolerance;
    let (reference, incident, edge) = if reference_is_b {
        (b, a, edge_b)
    } else {
        (a, b, edge_a)
    };
    let u = reference.normals[edge];
    // The normal points from B to A: the reference normal if B is the reference, else −u.
    let normal = if reference_is_b { u } else { -u };
    // The points are found as values and the manifold made once, at the end: pushed into
    // a manifold made empty, and clipped through segments passed by value, each was
    // stored in pieces and read back whole, which stalled the loads that forward stores
    // (a third of this function's samples in the smash).
    let mut ends = incident_edge(reference, incident, edge);
    let r1 = reference.vertices[edge];
    let r2 = reference.vertices[next_vertex(edge, reference.vertices.len())];
    // The edge's direction, (r2 − r1)/|r2 − r1|: its normal turned back a quarter turn,
    // the same quotients (`WorldPolygon::ensure_normals`) without another square root.
    let tangent = Vec2::new(-u.y, u.x);
    // Keep t·p ≥ t·r1, then t·p ≤ t·r2.
    let kept =
        clip(&mut ends, -tangent, -tangent.dot(&r1)) && clip(&mut ends, tangent, tangent.dot(&r2));
    // Each end's point, and whether it lies within the margin.
    let point_at = |end: &EdgeEnd| {
        let separation = u.dot(&(end.point - r1));
        let (vertex_a, vertex_b) = if reference_is_b {
            (end.incident_vertex, end.reference_vertex)
        } else {
            (end.reference_vertex, end.incident_vertex)
        };
        let point = ContactPoint {
            position: end.point - u * (0.5 * separation),
            depth: -separation,
            id: end_id(vertex_a, vertex_b),
        };
        (point, kept && separation <= margin)
    };
    let ((first, first_kept), (second, second_kept)) = (point_at(&ends[0]), point_at(&ends[1]));
    let none = ContactPoint::default();
    let points = match (first_kept, second_kept) {
        (true, true) => ([first, second], 2),
        (true, false) => ([first, none], 1),
        (false, true) => ([second, none], 1),
        (false, false) => {
            // Clipping can lose both points in a deep, skewed overlap: fall back to the
            // incident vertex that reaches deepest past the reference edge.
            let (k, separation) = deepest_vertex(incident, u, r1);
            let role = if reference_is_b { 1 << 30 } else { 0 };
            let deepest = ContactPoint {
                position: incident.vertices[k] - u * (0.5 * separation),
                depth: -separation,
                id: FeatureId(1 << 31 | role | ((edge as u32) << 16) | k as u32),
            };
            ([deepest, none], 1)
        }
    };
    manifolds.push(Manifold::with_points(
        (handle_a, handle_b),
        normal,
        points,
        reference_is_b,
    ));
    true
}

/// The edge of `p` whose outward normal separates `q` most, and that separation
/// (negative = overlap). Earlier edges win ties.
pub(super) fn max_separation(p: &WorldPolygon, q: &WorldPolygon) -> (usize, f64) {
    separation_beyond(p, q, f64::NEG_INFINITY, f64::INFINITY)
}

/// `max_separation` where it is above `floor` (else `floor`, with edge 0), except that it
/// may stop at the first edge that separates by more than `enough` (the pair is then
/// apart, whichever edge separates most).
fn separation_beyond(p: &WorldPolygon, q: &WorldPolygon, floor: f64, enough: f64) -> (usize, f64) {
    #[cfg(target_arch = "x86_64")]
    if (1..=4).contains(&q.vertices.len()) {
        // SAFETY: SSE2 is part of the x86-64 baseline: every x86-64 processor has it.
        return unsafe { separation_beyond_of_four(p, q, floor, enough) };
    }
    separation_beyond_vertex_by_vertex(p, q, floor, enough)
}

/// `separation_beyond` for any `q`, each edge's separation over `q`'s vertices one at a
/// time, stopping once the edge cannot beat the best one.
fn separation_beyond_vertex_by_vertex(
    p: &WorldPolygon,
    q: &WorldPolygon,
    floor: f64,
    enough: f64,
) -> (usize, f64) {
    let mut best = (0, floor);
    for (i, (n, v)) in p.normals.iter().zip(&p.vertices).enumerate() {
        let mut separation = f64::INFINITY;
        for w in &q.vertices {
            separation = separation.min(n.dot(&(w - v)));
            if separation <= best.1 {
                break; // this edge cannot beat the best one
            }
        }
        if separation > best.1 {
            best = (i, separation);
            if separation > enough {
                break;
            }
        }
    }
    best
}

/// `separation_beyond` for a `q` of at most four vertices, each edge's separation taken
/// over all of them at once in two pairs of lanes (SSE2, which every x86-64 has). A box's
/// four vertices cost as much as one, where the scalar loop's early exit at each vertex
/// went either way: the separating-axis loops were two fifths of `collide_polygons` in the
/// smash. Each lane computes n·(w − v) as the scalar loop does, and a minimum of finite
/// numbers is exact, so the separations, and the edge chosen, are the same to the bit.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "sse2")]
fn separation_beyond_of_four(
    p: &WorldPolygon,
    q: &WorldPolygon,
    floor: f64,
    enough: f64,
) -> (usize, f64) {
    use std::arch::x86_64::*;
    let w = &q.vertices;
    // A triangle's last vertex is taken twice: the minimum does not change.
    let at = |k: usize| w[k.min(w.len() - 1)];
    let (w0, w1, w2, w3) = (at(0), at(1), at(2), at(3));
    let (x01, y01) = (_mm_set_pd(w1.x, w0.x), _mm_set_pd(w1.y, w0.y));
    let (x23, y23) = (_mm_set_pd(w3.x, w2.x), _mm_set_pd(w3.y, w2.y));
    let mut best = (0, floor);
    for (i, (n, v)) in p.normals.iter().zip(&p.vertices).enumerate() {
        let (nx, ny) = (_mm_set1_pd(n.x), _mm_set1_pd(n.y));
        let (vx, vy) = (_mm_set1_pd(v.x), _mm_set1_pd(v.y));
        let along = |xs, ys| {
            let dx = _mm_mul_pd(nx, _mm_sub_pd(xs, vx));
            _mm_add_pd(dx, _mm_mul_pd(ny, _mm_sub_pd(ys, vy)))
        };
        let both = _mm_min_pd(along(x01, y01), along(x23, y23));
        let separation = _mm_cvtsd_f64(_mm_min_sd(both, _mm_unpackhi_pd(both, both)));
        if separation > best.1 {
            best = (i, separation);
            if separation > enough {
                break;
            }
        }
    }
    best
}

fn deepest_vertex(p: &WorldPolygon, u: Vec2, on_plane: Vec2) -> (usize, f64) {
    let mut best = (0, f64::INFINITY);
    for (k, v) in p.vertices.iter().enumerate() {
        let s = u.dot(&(v - on_plane));
        if s < best.1 {
            best = (k, s);
        }
    }
    best
}

/// A clipped point's id: the vertices of A's and of B's touching edges at its end of the
/// contact. The incident edge runs against the reference edge, so the end at the
/// reference edge's first vertex is the incident edge's second, and the other way round.
/// Which body holds the reference edge does not enter: when near-parallel faces swap the
/// reference between steps, each point keeps its id, and so its warm start.
/// Indices are below `shape::MAX_VERTICES` (2¹⁵), so bit 31 stays free for the fallback's
/// ids.
fn end_id(vertex_a: u32, vertex_b: u32) -> FeatureId {
    FeatureId((vertex_a << 16) | vertex_b)
}

/// One end of the incident edge as it is clipped: where it lies, and the vertices of the
/// reference and of the incident edge at that end of the contact (see `end_id`).
#[derive(Debug, Clone, Copy)]
struct EdgeEnd {
    point: Vec2,
    reference_vertex: u32,
    incident_vertex: u32,
}

/// The next vertex of a polygon of `n`, wrapped without the division of `%` (two per pair
/// tested).
fn next_vertex(i: usize, n: usize) -> usize {
    if i + 1 == n { 0 } else { i + 1 }
}

/// The ends of the incident edge: `incident`'s edge most anti-parallel to the normal of
/// `reference`'s edge `edge`.
fn incident_edge(reference: &WorldPolygon, incident: &WorldPolygon, edge: usize) -> [EdgeEnd; 2] {
    let u = reference.normals[edge];
    let mut k = 0;
    let mut most_negative = f64::INFINITY;
    for (j, m) in incident.normals.iter().enumerate() {
        let d = u.dot(m);
        if d < most_negative {
            most_negative = d;
            k = j;
        }
    }
    let edge2 = next_vertex(edge, reference.vertices.len());
    let k2 = next_vertex(k, incident.vertices.len());
    [
        EdgeEnd {
            point: incident.vertices[k],
            reference_vertex: edge2 as u32,
            incident_vertex: k as u32,
        },
        EdgeEnd {
            point: incident.vertices[k2],
            reference_vertex: edge as u32,
            incident_vertex: k2 as u32,
        },
    ]
}

/// Keeps the part of a segment with `normal·p ≤ offset`, in place: false if nothing is
/// left. A cut end keeps its end's vertices.
fn clip(ends: &mut [EdgeEnd; 2], normal: Vec2, offset: f64) -> bool {
    let d0 = normal.dot(&ends[0].point) - offset;
    let d1 = normal.dot(&ends[1].point) - offset;
    match (d0 <= 0.0, d1 <= 0.0) {
        (true, true) => true,
        (false, false) => false,
        (inside0, _) => {
            let t = d0 / (d0 - d1);
            let cut = ends[0].point + (ends[1].point - ends[0].point) * t;
            // The end outside moves to the cut.
            ends[usize::from(inside0)].point = cut;
            true
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::{Body, BodyDef};
    use crate::shape::ConvexPolygon;

    const A: BodyHandle = BodyHandle(0);
    const B: BodyHandle = BodyHandle(1);

    fn poly(points: &[(f64, f64)], at: (f64, f64), angle: f64) -> WorldPolygon {
        let pts: Vec<Vec2> = points.iter().map(|&(x, y)| Vec2::new(x, y)).collect();
        let body = Body::new(
            BodyDef::new(ConvexPolygon::new(&pts).unwrap(), 1.0).at(Vec2::new(at.0, at.1), angle),
        )
        .unwrap();
        let mut wp = WorldPolygon::default();
        wp.update(&body);
        wp
    }

    fn square(size: f64, at: (f64, f64), angle: f64) -> WorldPolygon {
        let h = size / 2.0;
        poly(&[(-h, -h), (h, -h), (h, h), (-h, h)], at, angle)
    }

    fn collide(a: &WorldPolygon, b: &WorldPolygon) -> Option<Manifold> {
        collide_polygons((A, a), (B, b), 0.0, 1e-9)
    }

    fn assert_vec(v: Vec2, x: f64, y: f64) {
        assert!((v - Vec2::new(x, y)).norm() < 1e-12, "{v:?} != ({x}, {y})");
    }

    #[test]
    fn separated_boxes_do_not_touch() {
        assert!(collide(&square(2.0, (0.0, 0.0), 0.0), &square(2.0, (2.5, 0.0), 0.0)).is_none());
        assert!(
            collide(
                &square(2.0, (0.0, 0.0), 0.0),
                &square(2.0, (0.0, -2.01), 0.0)
            )
            .is_none()
        );
    }

    #[test]
    fn margin_keeps_near_contacts_with_negative_depth() {
        let m = collide_polygons(
            (A, &square(2.0, (0.0, 0.0), 0.0)),
            (B, &square(2.0, (2.1, 0.0), 0.0)),
            0.2,
            1e-9,
        )
        .unwrap();
        assert_eq!(m.points().len(), 2);
        assert!(m.points().iter().all(|p| (p.depth + 0.1).abs() < 1e-12));
    }

    #[test]
    fn touching_boxes_have_zero_depth() {
        let m = collide(&square(2.0, (0.0, 0.0), 0.0), &square(2.0, (2.0, 0.5), 0.0)).unwrap();
        assert_vec(m.normal, -1.0, 0.0);
        assert_eq!(m.points().len(), 2);
        assert!(m.points().iter().all(|p| p.depth.abs() < 1e-12));
    }

    #[test]
    fn overlap_along_each_axis_points_from_b_to_a() {
        // B to the right, left, below (+y) and above A, overlapping by 0.25.
        for (bx, by, nx, ny) in [
            (1.75, 0.0, -1.0, 0.0),
            (-1.75, 0.0, 1.0, 0.0),
            (0.0, 1.75, 0.0, -1.0),
            (0.0, -1.75, 0.0, 1.0),
        ] {
            let m = collide(&square(2.0, (0.0, 0.0), 0.0), &square(2.0, (bx, by), 0.0)).unwrap();
            assert_vec(m.normal, nx, ny);
            assert_eq!(m.points().len(), 2, "B at ({bx}, {by})");
            for p in m.points() {
                assert!((p.depth - 0.25).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn box_on_wide_plate_gives_two_points_at_the_box_corners() {
        // A 2×2 box resting 0.1 deep in a 10×1 plate below it (y down).
        let plate = poly(
            &[(-5.0, -0.5), (5.0, -0.5), (5.0, 0.5), (-5.0, 0.5)],
            (0.0, 1.5),
            0.0,
        );
        let m = collide(&square(2.0, (0.0, 0.1), 0.0), &plate).unwrap();
        assert_vec(m.normal, 0.0, -1.0);
        let mut xs: Vec<f64> = m.points().iter().map(|p| p.position.x).collect();
        xs.sort_by(f64::total_cmp);
        assert!((xs[0] + 1.0).abs() < 1e-12 && (xs[1] - 1.0).abs() < 1e-12);
        for p in m.points() {
            assert!((p.depth - 0.1).abs() < 1e-12);
            assert!(
                (p.position.y - 1.05).abs() < 1e-12,
                "halfway between the surfaces"
            );
        }
    }

    #[test]
    fn vertex_into_edge_gives_one_point() {
        // A box turned 45° pokes a corner 0.1 into the top of a plate.
        let r = 2.0f64.sqrt();
        let plate = poly(
            &[(-5.0, -0.5), (5.0, -0.5), (5.0, 0.5), (-5.0, 0.5)],
            (0.0, 0.5),
            0.0,
        );
        let m = collide(
            &square(2.0, (0.0, -r + 0.1), std::f64::consts::FRAC_PI_4),
            &plate,
        )
        .unwrap();
        assert_vec(m.normal, 0.0, -1.0);
        assert_eq!(m.points().len(), 1);
        assert!((m.points()[0].depth - 0.1).abs() < 1e-12);
        assert_vec(m.points()[0].position, 0.0, 0.05);
    }

    #[test]
    fn vertex_to_vertex_touch_is_detected() {
        let r = 2.0f64.sqrt();
        let a = square(2.0, (0.0, 0.0), std::f64::consts::FRAC_PI_4);
        let b = square(2.0, (2.0 * r - 0.01, 0.0), std::f64::consts::FRAC_PI_4);
        let m = collide(&a, &b).unwrap();
        // The faces at the meeting corners are parallel, so clipping keeps the short overlap
        // of two edges: both points sit within 0.01 of the corners, 0.01·cos 45° deep.
        assert!(!m.points().is_empty());
        for p in m.points() {
            assert!((p.depth - 0.01 / r).abs() < 1e-12);
            assert!((p.position - Vec2::new(r - 0.005, 0.0)).norm() < 0.01);
        }
        assert!(m.normal.x < 0.0, "B is to the right, so n points left");
    }

    #[test]
    fn rotated_boxes_overlap_with_the_right_depth() {
        // Two unit squares, one turned by 30°, centres 0.9 apart on x.
        let a = square(1.0, (0.0, 0.0), 0.0);
        let b = square(1.0, (0.9, 0.0), 30f64.to_radians());
        let m = collide(&a, &b).unwrap();
        // Depth along A's right face: B's leftmost vertex reaches 0.9 − (cos30+sin30)/2.
        let depth = 0.5 - (0.9 - (30f64.to_radians().cos() + 30f64.to_radians().sin()) / 2.0);
        assert!(
            (m.depth() - depth).abs() < 1e-12,
            "{} vs {depth}",
            m.depth()
        );
        assert_vec(m.normal, -1.0, 0.0);
        assert_eq!(m.points().len(), 1);
    }

    #[test]
    fn containment_pushes_out_through_the_nearest_face() {
        // A small box deep inside a big one, near its right face.
        let big = square(20.0, (0.0, 0.0), 0.0);
        let small = square(1.0, (8.75, 0.0), 0.0);
        let m = collide(&big, &small).unwrap();
        // B (small) leaves through +x, so n (B→A) points to −x; depth = 10 − 8.25.
        assert_vec(m.normal, -1.0, 0.0);
        assert!((m.depth() - 1.75).abs() < 1e-12);
        assert_eq!(m.points().len(), 2);
        let m = collide(&small, &big).unwrap();
        assert_vec(m.normal, 1.0, 0.0);
        assert!((m.depth() - 1.75).abs() < 1e-12);
    }

    #[test]
    fn nearly_parallel_edges_keep_two_points_and_a_stable_reference() {
        let a = square(2.0, (0.0, 0.0), 0.0);
        let b = square(2.0, (0.1, 1.95), 1e-4);
        let m1 = collide(&a, &b).unwrap();
        assert_eq!(m1.points().len(), 2);
        assert!((m1.normal - Vec2::new(0.0, -1.0)).norm() < 1e-3);
        // Equal boxes, swapped roles: A's face is kept as reference on exact ties.
        let c = square(2.0, (0.0, 1.9), 0.0);
        let m2 = collide(&a, &c).unwrap();
        assert!(!m2.reference_is_b, "reference stays on A");
    }

    /// Near-parallel faces can take either body's edge as the reference from one step to
    /// the next. A negative tie tolerance forces B's; the points must keep their ids
    /// (their warm start) and move by no more than the tilt can explain. (The swap
    /// reverses their order, which the solvers do not match by.)
    #[test]
    fn swapping_the_reference_face_keeps_each_points_id() {
        let tilt = 2e-4;
        for (a, b) in [
            (
                square(1.0, (0.0, 0.0), 0.0),
                square(1.0, (0.3, 0.999), tilt),
            ),
            (
                square(1.0, (0.2, 0.999), -tilt),
                square(1.0, (0.0, 0.0), tilt),
            ),
            (
                square(2.0, (0.0, 0.0), 0.0),
                square(1.0, (0.0, -1.499), tilt),
            ),
        ] {
            let on_a = collide_polygons((A, &a), (B, &b), 0.02, 1.0).unwrap();
            let on_b = collide_polygons((A, &a), (B, &b), 0.02, -1.0).unwrap();
            assert!(!on_a.reference_is_b && on_b.reference_is_b);
            assert_eq!(on_a.points().len(), 2);
            assert_eq!(on_b.points().len(), 2);
            assert_ne!(on_a.points()[0].id, on_a.points()[1].id);
            assert!((on_a.normal - on_b.normal).norm() < 2.0 * tilt);
            for p in on_a.points() {
                let q = on_b.points().iter().find(|q| q.id == p.id);
                let q = q.unwrap_or_else(|| panic!("{:?} lost its id: {on_b:?}", p.id));
                // Each end is the same corner seen from either face: positions and depths
                // differ by the tilt times a box's size.
                assert!((p.position - q.position).norm() < 2.0 * tilt, "{p:?} {q:?}");
                assert!((p.depth - q.depth).abs() < 2.0 * tilt, "{p:?} {q:?}");
            }
        }
    }

    #[test]
    fn feature_ids_are_stable_under_small_motion() {
        let plate = poly(
            &[(-5.0, -0.5), (5.0, -0.5), (5.0, 0.5), (-5.0, 0.5)],
            (0.0, 1.5),
            0.0,
        );
        let ids = |dy: f64| -> Vec<FeatureId> {
            let m = collide(&square(2.0, (0.3, dy), 0.0), &plate).unwrap();
            m.points().iter().map(|p| p.id).collect()
        };
        assert_eq!(ids(0.05), ids(0.08));
    }

    /// A regular polygon of `sides` and circumradius `radius`.
    fn regular(sides: usize, radius: f64, at: (f64, f64), angle: f64) -> WorldPolygon {
        let corners: Vec<(f64, f64)> = (0..sides)
            .map(|k| std::f64::consts::TAU * k as f64 / sides as f64)
            .map(|t| (radius * t.cos(), radius * t.sin()))
            .collect();
        poly(&corners, at, angle)
    }

    /// Each edge's direction as the clipping takes it, its normal turned back, is the
    /// normalised edge to the bit.
    #[test]
    fn an_edges_direction_is_its_normal_turned_back() {
        for (sides, angle) in [(3, 0.3), (4, 0.0), (4, 1.1), (5, 2.9), (7, 4.4)] {
            let p = regular(sides, 0.37, (1.3, -0.8), angle);
            for (i, u) in p.normals.iter().enumerate() {
                let next = p.vertices[(i + 1) % sides];
                let direction = (next - p.vertices[i]).normalize();
                assert_eq!(Vec2::new(-u.y, u.x), direction, "{sides} sides, edge {i}");
            }
        }
    }

    proptest::proptest! {
        #![proptest_config(proptest::test_runner::Config {
            cases: 2000,
            rng_seed: proptest::test_runner::RngSeed::Fixed(2026),
            failure_persistence: None,
            ..proptest::test_runner::Config::default()
        })]

        /// The search over a polygon of up to four vertices at once finds the edge and the
        /// separation that the vertex-by-vertex search finds, whatever the floor and the
        /// separation that is enough (boxes and triangles, any angle, touching, apart or
        /// overlapping).
        #[test]
        fn the_search_over_four_vertices_at_once_is_the_vertex_by_vertex_one(
            sides in (3usize..7, 3usize..5),
            radii in (0.2f64..1.5, 0.2f64..1.5),
            offset in (-2.5f64..2.5, -2.5f64..2.5),
            angles in (0.0f64..6.3, 0.0f64..6.3),
            floor in proptest::sample::select(vec![f64::NEG_INFINITY, -0.5, 0.0, 0.2]),
            enough in proptest::sample::select(vec![f64::INFINITY, 0.0, 0.05, 0.3]),
        ) {
            let p = regular(sides.0, radii.0, (0.0, 0.0), angles.0);
            let q = regular(sides.1, radii.1, offset, angles.1);
            proptest::prop_assert_eq!(
                separation_beyond(&p, &q, floor, enough),
                separation_beyond_vertex_by_vertex(&p, &q, floor, enough)
            );
        }

        /// B's edges are searched only above what could replace A's best edge (or part
        /// them): the outcome is the full search's, each polygon's best edge over all of
        /// them, chosen by the rule of `collide_polygons`.
        #[test]
        fn the_reference_edge_is_the_full_searchs(
            sides in (3usize..7, 3usize..7),
            radii in (0.2f64..1.5, 0.2f64..1.5),
            offset in (-2.5f64..2.5, -2.5f64..2.5),
            angles in (0.0f64..6.3, 0.0f64..6.3),
            margin in proptest::sample::select(vec![0.0, 0.05, 0.3]),
            tie_tolerance in proptest::sample::select(vec![1e-9, 0.02, 0.5]),
        ) {
            let a = regular(sides.0, radii.0, (0.0, 0.0), angles.0);
            let b = regular(sides.1, radii.1, offset, angles.1);
            let (edge_a, separation_a) = max_separation(&a, &b);
            let (edge_b, separation_b) = max_separation(&b, &a);
            let found = collide_polygons((A, &a), (B, &b), margin, tie_tolerance);
            if separation_a > margin || separation_b > margin {
                proptest::prop_assert!(found.is_none());
            } else {
                let m = found.expect("within the margin");
                let reference_is_b = separation_b > separation_a + tie_tolerance;
                let normal = if reference_is_b { b.normals[edge_b] } else { -a.normals[edge_a] };
                proptest::prop_assert_eq!(m.reference_is_b, reference_is_b);
                proptest::prop_assert_eq!(m.normal, normal);
            }
        }
    }
}
