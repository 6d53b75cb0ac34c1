//! Triangle meshes (parry3d [`TriMesh`]) and their distance to an arc, through chords.
//!
//! parry has no arc primitive, so the arc is replaced by `k` equal chords. Every arc point
//! lies within the sagitta `e = r (1 − cos(Θ / 2k))` of its chord (and every chord point
//! within `e` of the arc), so with `d_c` the smallest chord–mesh distance,
//! `d_c − e ≤ d(arc, mesh) ≤ d_c + e`. `k` is the smallest count with `e ≤ tolerance`, and
//! the reported distance is the conservative `max(d_c − e, 0)`. Each chord is queried with
//! `parry3d_f64::query::closest_points`, which descends the mesh's own BVH.

use parry3d_f64::math::Pose;
use parry3d_f64::query::{self, ClosestPoints, PointQuery};
use parry3d_f64::shape::{FeatureId, Segment as PSegment, TriMesh};

use super::arc_cloud::{from_parry, to_parry};
use super::arc_point::PlacedArc;
use crate::error::{check_parameter, Error, Result};
use crate::math::Vec3;

/// Smallest chord tolerance (m). Meeting a tolerance `e` on an arc of length `L` bent by
/// `Θ` takes about `√(L Θ / 8e)` chords: 630 for a 1 m arc bent by π at 1 µm, but 20,000
/// at 1 nm. Below a micron the chord count, not the geometry, would set the cost.
pub const MIN_TOLERANCE: f64 = 1e-6;
/// Largest chord tolerance (m).
pub const MAX_TOLERANCE: f64 = 1.0;
/// Most chords per arc. With the smallest tolerance this meets it for every arc with
/// `L Θ ≤ 8 · 1e-6 · 65536² ≈ 3.4e4 m·rad` (any arm); a longer or more bent arc gets the
/// sagitta of this many chords, still a conservative distance, reported in
/// [`MeshHit::error`].
pub const MAX_CHORDS: usize = 1 << 16;

/// A triangle mesh obstacle.
#[derive(Clone)]
pub struct TriangleMesh {
    mesh: TriMesh,
    tolerance: f64,
}

impl std::fmt::Debug for TriangleMesh {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TriangleMesh")
            .field("triangles", &self.mesh.indices().len())
            .field("tolerance", &self.tolerance)
            .finish()
    }
}

/// Hit of a mesh query: conservative distance, s, triangle index, arc and mesh points.
#[derive(Debug, Clone, Copy)]
pub struct MeshHit {
    /// `max(d_chord − e, 0)`.
    pub distance: f64,
    /// Fraction along the arc of the closest chord point.
    pub s: f64,
    /// Index of the closest triangle (`u` of the result).
    pub triangle: usize,
    /// Arc point at `s`.
    pub arc_point: Vec3,
    /// Closest mesh point.
    pub mesh_point: Vec3,
    /// The chord error bound `e` used (m): the tolerance or less, unless the arc needs more
    /// than [`MAX_CHORDS`] chords.
    pub error: f64,
}

impl TriangleMesh {
    /// A mesh from vertices and triangles; `tolerance` (m) bounds the chord error.
    ///
    /// # Errors
    /// [`Error::Shape`] for no triangle or an index out of range, as
    /// [`super::obstacle::check_points`] for a bad vertex, [`Error::Parameter`] for a
    /// tolerance outside [[`MIN_TOLERANCE`], [`MAX_TOLERANCE`]].
    pub fn new(vertices: &[Vec3], triangles: &[[u32; 3]], tolerance: f64) -> Result<Self> {
        if triangles.is_empty() {
            return Err(Error::shape("triangles", "at least one triangle", "none"));
        }
        check_parameter("tolerance", tolerance, MIN_TOLERANCE, MAX_TOLERANCE)?;
        super::obstacle::check_points("vertices", vertices)?;
        let n = vertices.len();
        if let Some(t) = triangles.iter().flatten().find(|&&i| i as usize >= n) {
            return Err(Error::shape(
                "triangles",
                format!("vertex indices below {n}"),
                format!("index {t}"),
            ));
        }
        let mesh = TriMesh::new(vertices.iter().map(to_parry).collect(), triangles.to_vec())
            .map_err(|e| Error::shape("triangles", "a valid triangle mesh", format!("{e:?}")))?;
        Ok(TriangleMesh { mesh, tolerance })
    }

    /// Chord tolerance (m).
    pub fn tolerance(&self) -> f64 {
        self.tolerance
    }

    /// The parry mesh.
    pub fn mesh(&self) -> &TriMesh {
        &self.mesh
    }

    /// Closest point to `x`: `(distance, point)`.
    pub fn closest_to_point(&self, x: &Vec3) -> (f64, Vec3) {
        let proj = self.mesh.project_local_point(to_parry(x), true);
        let p = from_parry(proj.point);
        ((p - x).norm(), p)
    }

    /// Distance between the chords of `arc` and the mesh (see the module docs).
    pub fn closest_to_arc(&self, arc: &PlacedArc) -> MeshHit {
        let mut k = 1usize;
        while arc.arc.chord_error(k) > self.tolerance && k < MAX_CHORDS {
            k *= 2;
        }
        let e = arc.arc.chord_error(k);
        let mut best = MeshHit {
            distance: f64::INFINITY,
            s: 0.0,
            triangle: 0,
            arc_point: arc.point(0.0),
            mesh_point: arc.point(0.0),
            error: e,
        };
        let mut d_best = f64::INFINITY;
        let id = Pose::IDENTITY;
        for i in 0..k {
            let (s0, s1) = (i as f64 / k as f64, (i + 1) as f64 / k as f64);
            let (a, b) = (arc.point(s0), arc.point(s1));
            let seg = PSegment::new(to_parry(&a), to_parry(&b));
            let found = query::closest_points(&id, &seg, &id, &self.mesh, d_best.min(1e300));
            let (pa, pb) = match found {
                Ok(ClosestPoints::WithinMargin(pa, pb)) => (from_parry(pa), from_parry(pb)),
                Ok(ClosestPoints::Intersecting) => {
                    // Touching: locate the contact through the chord's midpoint.
                    let mid = 0.5 * (a + b);
                    let (_, p) = self.closest_to_point(&mid);
                    (p, p)
                }
                _ => continue,
            };
            let d = (pa - pb).norm();
            if d < d_best {
                d_best = d;
                let ab = b - a;
                let t = if ab.norm_squared() > 0.0 {
                    ((pa - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let s = s0 + t * (s1 - s0);
                let ntri = self.mesh.indices().len().max(1) as u32;
                let tri = match self
                    .mesh
                    .project_local_point_and_get_feature(to_parry(&pb))
                    .1
                {
                    FeatureId::Face(f) => f % ntri,
                    _ => 0,
                };
                best = MeshHit {
                    distance: (d - e).max(0.0),
                    s,
                    triangle: tri as usize,
                    arc_point: arc.point(s),
                    mesh_point: pb,
                    error: e,
                };
            }
        }
        best
    }
}
