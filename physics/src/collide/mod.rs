//! Collision detection: bounds, the broad phase and the SAT narrow phase (thesis §3.1).

mod broad;
mod fixed_cells;
mod pair_set;
pub(crate) mod reuse;
pub(crate) mod sat;
pub(crate) mod toi;

pub(crate) use broad::BroadPhase;
pub(crate) use fixed_cells::FixedCells;
pub(crate) use pair_set::PairSet;
pub(crate) use sat::collide_polygons_into;

use crate::body::{Body, BodyHandle};
use crate::math::Vec2;

/// An axis-aligned bounding box.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Aabb {
    pub min: Vec2,
    pub max: Vec2,
}

impl Aabb {
    /// The four comparisons combined by `&`, without branches: in the broad phase's grid
    /// the answer goes either way from pair to pair, and branches cost more there.
    #[inline]
    pub fn overlaps(&self, other: &Aabb) -> bool {
        (self.min.x <= other.max.x)
            & (other.min.x <= self.max.x)
            & (self.min.y <= other.max.y)
            & (other.min.y <= self.max.y)
    }

    /// Whether `inner` lies inside this box.
    pub(crate) fn contains(&self, inner: &Aabb) -> bool {
        self.min.x <= inner.min.x
            && self.min.y <= inner.min.y
            && inner.max.x <= self.max.x
            && inner.max.y <= self.max.y
    }

    pub fn grown(&self, by: f64) -> Aabb {
        let d = Vec2::new(by, by);
        Aabb {
            min: self.min - d,
            max: self.max + d,
        }
    }
}

/// A body's polygon in world coordinates, cached once per step for the narrow phase.
#[derive(Debug, Clone, Default)]
pub struct WorldPolygon {
    pub vertices: Vec<Vec2>,
    /// Outward unit normal of the edge from vertex i to vertex i+1.
    pub normals: Vec<Vec2>,
}

impl WorldPolygon {
    /// Refills `self` from `body` without reallocating when the size is unchanged.
    pub(crate) fn update(&mut self, body: &Body) {
        self.set_vertices(body.world_vertices());
    }

    /// Refills `self` from world vertices in the positive order.
    pub fn set_vertices(&mut self, vertices: impl Iterator<Item = Vec2>) {
        self.set_outline(vertices);
        self.ensure_normals();
    }

    /// Refills the vertices only; `ensure_normals` adds the normals when a test needs
    /// them (a pile at rest reuses its manifolds and needs only the bounds).
    pub(crate) fn set_outline(&mut self, vertices: impl Iterator<Item = Vec2>) {
        self.vertices.clear();
        self.vertices.extend(vertices);
        self.normals.clear();
    }

    /// Computes the edge normals if `set_outline` left them out.
    pub(crate) fn ensure_normals(&mut self) {
        if !self.normals.is_empty() {
            return;
        }
        // Each vertex with the next, the last with the first (without a division per edge
        // to wrap the index: the smash computes ~30,000 polygons' normals a step).
        let next = self.vertices.iter().skip(1).chain(self.vertices.first());
        let edges = self.vertices.iter().zip(next).map(|(v, w)| w - v);
        // (e_y, −e_x)/|e| is outward for the positive vertex order (thesis §3.1).
        self.normals
            .extend(edges.map(|e| Vec2::new(e.y, -e.x) / e.norm()));
    }

    pub fn aabb(&self) -> Aabb {
        let mut min = self.vertices[0];
        let mut max = self.vertices[0];
        for v in &self.vertices[1..] {
            min = min.inf(v);
            max = max.sup(v);
        }
        Aabb { min, max }
    }
}

/// Identifies which features of the two polygons made a contact point, so that a solver can
/// match points across steps (warm starting) while the same edges stay in touch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
pub struct FeatureId(pub u32);

/// One contact point of a manifold.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ContactPoint {
    /// World position, halfway between the two surfaces.
    pub position: Vec2,
    /// Penetration depth: positive when overlapping, negative inside the contact margin.
    pub depth: f64,
    pub id: FeatureId,
}

/// The contact between two bodies: one normal and up to two points.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Manifold {
    pub body_a: BodyHandle,
    pub body_b: BodyHandle,
    /// Unit normal pointing from B towards A (thesis §2.4).
    pub normal: Vec2,
    points: [ContactPoint; 2],
    len: u8,
    /// Whether the reference edge (the one the points were clipped against) is B's.
    pub(crate) reference_is_b: bool,
}

impl Manifold {
    /// A manifold of the first `len` of `points`, found against `reference_is_b`'s edge:
    /// made whole from its points, never filled in afterwards (see
    /// `ManifoldCache::reuse_into`).
    pub(crate) fn with_points(
        (body_a, body_b): (BodyHandle, BodyHandle),
        normal: Vec2,
        (points, len): ([ContactPoint; 2], u8),
        reference_is_b: bool,
    ) -> Self {
        Self {
            body_a,
            body_b,
            normal,
            points,
            len,
            reference_is_b,
        }
    }

    pub fn points(&self) -> &[ContactPoint] {
        &self.points[..self.len as usize]
    }

    /// The deepest penetration of the manifold.
    pub(crate) fn depth(&self) -> f64 {
        self.points()
            .iter()
            .map(|p| p.depth)
            .fold(f64::NEG_INFINITY, f64::max)
    }
}
