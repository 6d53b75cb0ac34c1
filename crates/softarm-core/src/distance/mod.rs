//! Distance queries between the arcs of an arm and obstacles (planning paper eq. 10–18).
//!
//! One file per query pair, as in parry: [`arc_point`] (closed form), [`arc_curve`]
//! (exact and global, also used for segments), [`arc_cloud`] (parry BVH, exact),
//! [`arc_mesh`] (parry TriMesh through chords, conservative). [`obstacle`] dispatches.

pub mod arc_cloud;
pub mod arc_curve;
pub mod arc_mesh;
pub mod arc_point;
pub mod bodies;
pub mod obstacle;
pub mod polynomial;

pub use arc_cloud::PointCloud;
pub use arc_curve::{closest_arc_curve, closest_arc_curve_within, ArcCurveHit};
pub use arc_mesh::TriangleMesh;
pub use arc_point::{LocalArc, PlacedArc};
pub use bodies::{closest_body, BodyClosest};
pub use obstacle::{
    check_obstacles, check_points, closest, closest_to_arc, closest_to_arcs,
    closest_to_arcs_within, placed_arcs, Closest, Obstacle,
};
pub use polynomial::{PolynomialCurve, Segment};
