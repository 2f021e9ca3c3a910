//! Convex polygons: validation, convex hull and mass properties (thesis §2.2, §3.1).

use crate::math::{Vec2, cross};
use thiserror::Error;

/// Relative tolerance for "the same point", "zero area" and "collinear": a fraction of the
/// polygon's own size, so pixel-sized and metre-sized shapes are judged alike.
const RELATIVE_TOLERANCE: f64 = 1e-9;

/// Why a vertex list is not a usable convex polygon.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ShapeError {
    #[error("a polygon needs at least 3 vertices, this one has {count}")]
    TooFewVertices { count: usize },
    #[error("a polygon may have at most {limit} vertices, this one has {count}")]
    TooManyVertices { count: usize, limit: usize },
    #[error("vertex {index} has a coordinate that is not a finite number")]
    NonFiniteCoordinate { index: usize },
    #[error("the polygon spans {extent:e}: too large for its area to be computed")]
    TooLarge { extent: f64 },
    #[error("vertices {first} and {second} are the same point")]
    RepeatedPoint { first: usize, second: usize },
    /// Two vertices apart, but closer than `RELATIVE_TOLERANCE` of the polygon's size:
    /// a sliver the engine cannot tell from a line.
    #[error(
        "vertices {first} and {second} are only {distance:e} apart, less than a billionth of the polygon's size ({size:e}): too thin to simulate"
    )]
    TooThin {
        first: usize,
        second: usize,
        distance: f64,
        size: f64,
    },
    #[error("the polygon has (nearly) zero area")]
    ZeroArea,
    #[error("edges {first} and {second} cross: the polygon intersects itself")]
    SelfIntersecting { first: usize, second: usize },
    #[error("the polygon is not convex at vertex {vertex}")]
    NotConvex { vertex: usize },
}

/// A validated convex polygon with positive vertex order (signed area > 0: counter-clockwise
/// in y-up axes, clockwise on a y-down screen), collinear vertices removed.
#[derive(Debug, Clone, PartialEq)]
pub struct ConvexPolygon {
    vertices: Vec<Vec2>,
}

/// Area, centroid and polar second moment of a polygon of unit density.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MassProperties {
    pub area: f64,
    /// Centroid in the polygon's vertex frame.
    pub centroid: Vec2,
    /// Polar second moment of area about the centroid (I = density · this).
    pub second_moment: f64,
}

/// The most vertices a polygon may have: contact points are named by vertex indices in 15
/// bits (`collide::sat`), far beyond any drawn body.
pub(crate) const MAX_VERTICES: usize = 1 << 15;

impl ConvexPolygon {
    /// Validates `points` (either winding) and returns the polygon in positive order.
    pub fn new(points: &[Vec2]) -> Result<Self, ShapeError> {
        if points.len() < 3 {
            return Err(ShapeError::TooFewVertices {
                count: points.len(),
            });
        }
        if points.len() > MAX_VERTICES {
            return Err(ShapeError::TooManyVertices {
                count: points.len(),
                limit: MAX_VERTICES,
            });
        }
        if let Some(index) = points
            .iter()
            .position(|p| !p.x.is_finite() || !p.y.is_finite())
        {
            return Err(ShapeError::NonFiniteCoordinate { index });
        }
        let size = extent(points);
        // Area and moments are products of two (or four) coordinates: beyond this they overflow.
        if !(size * size * size * size).is_finite() {
            return Err(ShapeError::TooLarge { extent: size });
        }
        let same_point = RELATIVE_TOLERANCE * size;
        for i in 0..points.len() {
            for j in i + 1..points.len() {
                let distance = (points[i] - points[j]).norm();
                if distance == 0.0 {
                    return Err(ShapeError::RepeatedPoint {
                        first: i,
                        second: j,
                    });
                }
                if distance <= same_point {
                    return Err(ShapeError::TooThin {
                        first: i,
                        second: j,
                        distance,
                        size,
                    });
                }
            }
        }
        let area = signed_area(points);
        if area.abs() <= RELATIVE_TOLERANCE * size * size {
            return Err(ShapeError::ZeroArea);
        }
        if let Some((first, second)) = crossing_edges(points) {
            return Err(ShapeError::SelfIntersecting { first, second });
        }
        let mut ordered = points.to_vec();
        if area < 0.0 {
            ordered.reverse();
        }
        let n = ordered.len();
        let mut vertices = Vec::with_capacity(n);
        for i in 0..n {
            let prev = ordered[(i + n - 1) % n];
            let here = ordered[i];
            let next = ordered[(i + 1) % n];
            let (e0, e1) = (here - prev, next - here);
            let turn = cross(e0, e1);
            if turn < -RELATIVE_TOLERANCE * e0.norm() * e1.norm() {
                // Report the index the caller used, not the reordered one.
                let vertex = if area < 0.0 { n - 1 - i } else { i };
                return Err(ShapeError::NotConvex { vertex });
            }
            if turn > RELATIVE_TOLERANCE * e0.norm() * e1.norm() {
                vertices.push(here);
            }
        }
        // Only collinear vertices left: no area after all.
        if vertices.len() < 3 {
            return Err(ShapeError::ZeroArea);
        }
        Ok(Self { vertices })
    }

    /// An axis-aligned box of the given size centred on the origin.
    pub fn rectangle(width: f64, height: f64) -> Result<Self, ShapeError> {
        let (hw, hh) = (0.5 * width, 0.5 * height);
        Self::new(&[
            Vec2::new(-hw, -hh),
            Vec2::new(hw, -hh),
            Vec2::new(hw, hh),
            Vec2::new(-hw, hh),
        ])
    }

    /// A regular polygon with `sides` vertices on a circle of `radius` about the origin.
    pub fn regular(sides: usize, radius: f64) -> Result<Self, ShapeError> {
        let points: Vec<Vec2> = (0..sides)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / sides as f64;
                Vec2::new(radius * a.cos(), radius * a.sin())
            })
            .collect();
        Self::new(&points)
    }

    pub fn vertices(&self) -> &[Vec2] {
        &self.vertices
    }

    /// Exact polygon formulas of thesis §2.2, evaluated relative to the first vertex so that
    /// shapes far from their origin keep their precision.
    pub fn mass_properties(&self) -> MassProperties {
        let origin = self.vertices[0];
        let n = self.vertices.len();
        let (mut area2, mut first_moment, mut polar) = (0.0, Vec2::zeros(), 0.0);
        for i in 0..n {
            let v0 = self.vertices[i] - origin;
            let v1 = self.vertices[(i + 1) % n] - origin;
            let c = cross(v0, v1);
            area2 += c;
            first_moment += (v0 + v1) * c;
            polar += c * (v0.dot(&v0) + v0.dot(&v1) + v1.dot(&v1));
        }
        let area = 0.5 * area2;
        let centroid_rel = first_moment / (6.0 * area);
        let polar_about_origin = polar / 12.0;
        MassProperties {
            area,
            centroid: origin + centroid_rel,
            second_moment: polar_about_origin - area * centroid_rel.norm_squared(),
        }
    }

    /// Whether `point` lies inside or on the boundary.
    pub fn contains(&self, point: Vec2) -> bool {
        let n = self.vertices.len();
        (0..n).all(|i| {
            let a = self.vertices[i];
            let b = self.vertices[(i + 1) % n];
            cross(b - a, point - a) >= -RELATIVE_TOLERANCE * extent(&self.vertices).powi(2)
        })
    }
}

/// The convex hull of `points` in positive order, collinear points dropped (Andrew's
/// monotone chain). Fewer than 3 distinct non-collinear points give fewer than 3 vertices.
pub fn convex_hull(points: &[Vec2]) -> Vec<Vec2> {
    let mut sorted: Vec<Vec2> = points
        .iter()
        .copied()
        .filter(|p| p.x.is_finite() && p.y.is_finite())
        .collect();
    sorted.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    sorted.dedup();
    if sorted.len() < 3 {
        return sorted;
    }
    let mut hull: Vec<Vec2> = Vec::with_capacity(2 * sorted.len());
    for pass in [
        &sorted[..],
        &sorted.iter().rev().copied().collect::<Vec<_>>()[..],
    ] {
        let start = hull.len();
        for &p in pass {
            while hull.len() >= start + 2
                && cross(
                    hull[hull.len() - 1] - hull[hull.len() - 2],
                    p - hull[hull.len() - 1],
                ) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop(); // the last point starts the other chain
    }
    hull
}

/// Signed area: positive for the order the engine uses.
pub(crate) fn signed_area(points: &[Vec2]) -> f64 {
    let n = points.len();
    let origin = points[0];
    0.5 * (0..n)
        .map(|i| cross(points[i] - origin, points[(i + 1) % n] - origin))
        .sum::<f64>()
}

fn extent(points: &[Vec2]) -> f64 {
    let (mut min, mut max) = (points[0], points[0]);
    for p in points {
        min = min.inf(p);
        max = max.sup(p);
    }
    (max - min).max()
}

/// The first pair of non-adjacent edges that touch or cross, if any.
fn crossing_edges(points: &[Vec2]) -> Option<(usize, usize)> {
    let n = points.len();
    for i in 0..n {
        for j in i + 2..n {
            if i == 0 && j == n - 1 {
                continue; // adjacent through the closing edge
            }
            let (a0, a1) = (points[i], points[(i + 1) % n]);
            let (b0, b1) = (points[j], points[(j + 1) % n]);
            if segments_intersect(a0, a1, b0, b1) {
                return Some((i, j));
            }
        }
    }
    None
}

fn segments_intersect(a0: Vec2, a1: Vec2, b0: Vec2, b1: Vec2) -> bool {
    let d1 = cross(a1 - a0, b0 - a0);
    let d2 = cross(a1 - a0, b1 - a0);
    let d3 = cross(b1 - b0, a0 - b0);
    let d4 = cross(b1 - b0, a1 - b0);
    if d1 * d2 < 0.0 && d3 * d4 < 0.0 {
        return true;
    }
    let on_segment = |p: Vec2, q: Vec2, r: Vec2, d: f64| {
        d == 0.0
            && r.x >= p.x.min(q.x)
            && r.x <= p.x.max(q.x)
            && r.y >= p.y.min(q.y)
            && r.y <= p.y.max(q.y)
    };
    on_segment(a0, a1, b0, d1)
        || on_segment(a0, a1, b1, d2)
        || on_segment(b0, b1, a0, d3)
        || on_segment(b0, b1, a1, d4)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64) -> Vec2 {
        Vec2::new(x, y)
    }

    /// Rounding in the polygon sums is a few ulps of the largest term.
    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-12 * a.abs().max(b.abs()).max(1.0)
    }

    #[test]
    fn huge_coordinates_are_refused_not_overflowed() {
        let huge = [v(-1e300, -1e300), v(1e300, -1e300), v(0.0, 1e300)];
        assert!(matches!(
            ConvexPolygon::new(&huge),
            Err(ShapeError::TooLarge { .. })
        ));
    }

    /// Every triangle with corners from extreme values is either refused or has finite,
    /// positive mass properties (a fuzzed database once produced a polygon with no vertices).
    #[test]
    fn every_extreme_triangle_is_refused_or_sound() {
        let values = [0.0, 1.0, -1.0, 1e-320, 1e16, 1e150, -1e150, 1e300, -1e300];
        let n = values.len();
        for code in 0..n.pow(6) {
            let mut digits = (0..6).scan(code, |rest, _| {
                let d = *rest % n;
                *rest /= n;
                Some(values[d])
            });
            let mut next = || digits.next().unwrap();
            let points = [v(next(), next()), v(next(), next()), v(next(), next())];
            if let Ok(polygon) = ConvexPolygon::new(&points) {
                let mp = polygon.mass_properties();
                assert!(polygon.vertices().len() >= 3, "{points:?}");
                assert!(mp.area > 0.0 && mp.area.is_finite(), "{points:?}: {mp:?}");
                assert!(mp.second_moment > 0.0 && mp.second_moment.is_finite());
                assert!(mp.centroid.x.is_finite() && mp.centroid.y.is_finite());
            }
        }
    }

    #[test]
    fn spec_rectangle_has_spec_mass_properties() {
        // thesis §2.2 check: the 40×20 "obdelnik".
        let p =
            ConvexPolygon::new(&[v(20., -10.), v(20., 10.), v(-20., 10.), v(-20., -10.)]).unwrap();
        let mp = p.mass_properties();
        assert!(close(mp.area, 800.0));
        assert!(mp.centroid.norm() < 1e-12);
        assert!(close(
            mp.second_moment,
            800.0 * (40.0f64.powi(2) + 20.0f64.powi(2)) / 12.0
        ));
    }

    #[test]
    fn right_triangle_matches_closed_form() {
        // Legs a along x and b along y: centroid (a/3, b/3), I_c = A(a²+b²)/18.
        let (a, b) = (3.0, 4.0);
        let mp = ConvexPolygon::new(&[v(0., 0.), v(a, 0.), v(0., b)])
            .unwrap()
            .mass_properties();
        assert!(close(mp.area, a * b / 2.0));
        assert!((mp.centroid - v(a / 3.0, b / 3.0)).norm() < 1e-14);
        assert!(close(mp.second_moment, mp.area * (a * a + b * b) / 18.0));
    }

    #[test]
    fn regular_polygon_matches_closed_form() {
        // Regular n-gon of circumradius R: A = n R² sin(2π/n)/2, J = A R² (1 + 2cos²(π/n))/6.
        for n in [3usize, 5, 6, 8, 17] {
            let r = 2.5;
            let mp = ConvexPolygon::regular(n, r).unwrap().mass_properties();
            let t = std::f64::consts::PI / n as f64;
            let area = n as f64 * r * r * (2.0 * t).sin() / 2.0;
            assert!(close(mp.area, area), "n={n}");
            assert!(mp.centroid.norm() < 1e-12, "n={n}");
            let j = area * r * r * (1.0 + 2.0 * t.cos().powi(2)) / 6.0;
            assert!(
                close(mp.second_moment, j),
                "n={n}: {} vs {j}",
                mp.second_moment
            );
        }
    }

    #[test]
    fn off_centre_polygon_has_shifted_centroid_and_same_inertia() {
        let offset = v(1000.0, -250.0);
        let base = ConvexPolygon::regular(6, 3.0).unwrap();
        let moved: Vec<Vec2> = base.vertices().iter().map(|p| p + offset).collect();
        let mp = ConvexPolygon::new(&moved).unwrap().mass_properties();
        assert!((mp.centroid - offset).norm() < 1e-10);
        assert!(close(
            mp.second_moment,
            base.mass_properties().second_moment
        ));
    }

    #[test]
    fn clockwise_input_gives_the_same_polygon() {
        let ccw = [v(0., 0.), v(4., 0.), v(5., 3.), v(1., 2.)];
        let mut cw = ccw;
        cw.reverse();
        let a = ConvexPolygon::new(&ccw).unwrap();
        let b = ConvexPolygon::new(&cw).unwrap();
        assert_eq!(a.mass_properties().area, b.mass_properties().area);
        assert!(signed_area(b.vertices()) > 0.0);
        assert!(close(
            a.mass_properties().second_moment,
            b.mass_properties().second_moment
        ));
    }

    #[test]
    fn collinear_vertices_are_dropped() {
        let p =
            ConvexPolygon::new(&[v(0., 0.), v(1., 0.), v(2., 0.), v(2., 2.), v(0., 2.)]).unwrap();
        assert_eq!(p.vertices().len(), 4);
    }

    #[test]
    fn each_bad_polygon_has_its_own_error() {
        use ShapeError::*;
        assert_eq!(
            ConvexPolygon::new(&[v(0., 0.), v(1., 0.)]),
            Err(TooFewVertices { count: 2 })
        );
        let circle: Vec<Vec2> = (0..=MAX_VERTICES)
            .map(|i| {
                let a = std::f64::consts::TAU * i as f64 / (MAX_VERTICES + 1) as f64;
                v(a.cos(), a.sin())
            })
            .collect();
        assert_eq!(
            ConvexPolygon::new(&circle),
            Err(TooManyVertices {
                count: MAX_VERTICES + 1,
                limit: MAX_VERTICES
            })
        );
        assert_eq!(
            ConvexPolygon::new(&[v(0., 0.), v(f64::NAN, 0.), v(0., 1.)]),
            Err(NonFiniteCoordinate { index: 1 })
        );
        assert_eq!(
            ConvexPolygon::new(&[v(0., 0.), v(1., 0.), v(f64::INFINITY, 1.)]),
            Err(NonFiniteCoordinate { index: 2 })
        );
        assert_eq!(
            ConvexPolygon::new(&[v(0., 0.), v(1., 0.), v(1., 1.), v(1., 0.)]),
            Err(RepeatedPoint {
                first: 1,
                second: 3
            })
        );
        // A 1000 x 1e-6 plank: its short edges are a billionth of its size.
        let plank = [v(0., 0.), v(1000., 0.), v(1000., 1e-6), v(0., 1e-6)];
        let thin = ConvexPolygon::new(&plank).unwrap_err();
        assert!(
            matches!(
                thin,
                TooThin {
                    first: 0,
                    second: 3,
                    ..
                }
            ),
            "{thin:?}"
        );
        assert!(thin.to_string().contains("too thin"), "{thin}");
        assert_eq!(
            ConvexPolygon::new(&[v(0., 0.), v(1., 1.), v(2., 2.)]),
            Err(ZeroArea)
        );
        assert_eq!(
            ConvexPolygon::new(&[v(0., 0.), v(2., 2.), v(2., 0.), v(0., 3.)]),
            Err(SelfIntersecting {
                first: 0,
                second: 2
            })
        );
        assert_eq!(
            ConvexPolygon::new(&[v(0., 0.), v(4., 0.), v(2., 1.), v(4., 4.), v(0., 4.)]),
            Err(NotConvex { vertex: 2 })
        );
    }

    #[test]
    fn not_convex_reports_the_callers_index_for_clockwise_input() {
        let mut pts = vec![v(0., 0.), v(4., 0.), v(2., 1.), v(4., 4.), v(0., 4.)];
        pts.reverse(); // the dent is now at index 2 of the reversed list as well
        assert_eq!(
            ConvexPolygon::new(&pts),
            Err(ShapeError::NotConvex { vertex: 2 })
        );
    }

    #[test]
    fn hull_of_scattered_points() {
        let pts = [
            v(0., 0.),
            v(2., 0.),
            v(1., 1.),
            v(2., 2.),
            v(0., 2.),
            v(1., 0.),
            v(0.5, 1.5),
        ];
        let hull = convex_hull(&pts);
        assert_eq!(hull, vec![v(0., 0.), v(2., 0.), v(2., 2.), v(0., 2.)]);
        assert!(ConvexPolygon::new(&hull).is_ok());
    }
}
